// Scans the operator took out of the map (DELETE /api/v1/scans/{id}) and the way to put one back
// (POST /api/v1/scans/{id}/restore): a list in the mission panel. A scan is taken out from one of
// its points clicked in the 3-D view. The server records who and why, rebuilds the map without
// the scan and says so (`map_rebuilt`); the scan's file stays in the session.
import { sendJson } from './api.js';
import { confirmAction } from './dialog.js';

function timeOf(at) {
  const d = new Date(at);
  return Number.isNaN(d.getTime()) ? at || '' : d.toLocaleTimeString('en-GB', { hour12: false });
}

export class ExcludedScans {
  /** @param {{list: HTMLElement, onChange: () => void}} opts */
  constructor({ list, onChange }) {
    this.list = list;
    this.onChange = onChange;
    this.scans = [];
    this.operator = false;
    this.error = '';
  }

  setRole(operator) {
    this.operator = operator;
    this.render();
  }

  /** The `excluded` list of GET /api/v1/scans. */
  set(scans) {
    this.scans = scans || [];
    this.render();
  }

  async exclude(id) {
    const answer = await confirmAction({
      title: `Take scan ${id} out of the map?`,
      body: 'Its points leave the map, and the regions and the plans are made again without it. ' +
        'The scan stays in the session and can be put back.',
      confirm: 'Take out',
      danger: true,
      reason: true,
    });
    if (!answer) return;
    await this._send(`/api/v1/scans/${id}`, answer, 'DELETE');
  }

  async restore(id) {
    const answer = await confirmAction({
      title: `Put scan ${id} back into the map?`,
      body: 'The map, the regions and the plans are made again with it.',
      confirm: 'Put back',
    });
    if (!answer) return;
    await this._send(`/api/v1/scans/${id}/restore`, answer, 'POST');
  }

  async _send(path, { by, reason }, method) {
    const body = {};
    if (by) body.by = by;
    if (reason) body.reason = reason;
    try {
      await sendJson(path, body, { method });
      this.error = '';
    } catch (e) {
      this.error = e.detail || e.message || String(e);
    }
    this.render();
    this.onChange();
  }

  render() {
    const { list } = this;
    list.replaceChildren();
    list.hidden = !this.scans.length && !this.error;
    if (this.error) {
      const err = document.createElement('div');
      err.className = 'error';
      err.textContent = this.error;
      list.append(err);
    }
    if (!this.scans.length) return;
    const head = document.createElement('div');
    head.className = 'excluded-head';
    head.textContent = `Out of the map: ${this.scans.length} scan${this.scans.length > 1 ? 's' : ''}`;
    list.append(head);
    for (const s of this.scans) {
      const row = document.createElement('div');
      row.className = 'excluded-scan';
      row.dataset.scan = String(s.id);
      const text = document.createElement('span');
      const x = s.excluded || {};
      text.textContent = `scan ${s.id} (${s.robot}), out since ${timeOf(x.at)} by ${x.by || 'operator'}` +
        (x.reason ? `: ${x.reason}` : '');
      row.append(text);
      if (this.operator) {
        const back = document.createElement('button');
        back.type = 'button';
        back.textContent = 'Put back';
        back.addEventListener('click', () => this.restore(s.id));
        row.append(back);
      }
      list.append(row);
    }
  }
}
