// The planner's suggestions (GET /api/v1/candidates: one plan per robot) as ranked lists, the
// selected one's details (F, gains, drive), and the operator's decisions on it: approve, reject,
// cancel a move, each after a confirmation (POST /api/v1/candidates/{id}/approve|reject|cancel).
// Viewers see no buttons.
import { sendJson } from './api.js';
import { confirmAction } from './dialog.js';
import { robotColor } from './robot_colors.js';

const nf0 = new Intl.NumberFormat('en-US', { maximumFractionDigits: 0 });
// The planner's forecast of matching a scan at the candidate (docs/planner.md): whether the
// scan will land on enough of the trusted map, and whether what it sees there fixes the pose.
function matchDoubtful(c) {
  return !!c.registrability && c.registrability.factor < 1;
}
function matchForecast(c) {
  const r = c.registrability;
  if (!r) return '';
  const share = `${nf0.format(100 * r.overlap_share)} %`;
  if (r.factor >= 1) return `${share} of the scan on the trusted map; it should match`;
  if (r.overlap_share < 0.3) return `only ${share} of the scan on the trusted map: the match may fail`;
  return `${share} on the trusted map, but few walls across: the match may slide (a corridor, one facade)`;
}
// signDisplay 'negative': no "-0.0" for a height just below zero.
const nf1 = new Intl.NumberFormat('en-US', { maximumFractionDigits: 1, minimumFractionDigits: 1, signDisplay: 'negative' });

const STATE_TEXT = {
  proposed: 'proposed',
  moving: 'driving there',
  reached: 'reached',
  rejected: 'rejected',
  refused: 'refused by the robot',
  interrupted: 'interrupted: robot lost',
  cancelled: 'cancelled',
  superseded: 'superseded',
};

function el(tag, className, text) {
  const e = document.createElement(tag);
  if (className) e.className = className;
  if (text !== undefined) e.textContent = text;
  return e;
}

export function candidateName(c) {
  return c.custom ? `custom point #${c.id}` : `candidate ${c.rank} (#${c.id})`;
}

/** What a scan there would add: never-scanned ground it sees plus coarse ground it completes (m²). */
export function newGround(c) {
  return (c.gain_unscanned_m2 || 0) + (c.gain_low_res_m2 || 0);
}

const POLICY_TEXT = {
  paper: 'hill climbing (paper)',
  exhaustive: 'best point (exhaustive)',
  travel: 'best point for the drive',
  'nearest-frontier': 'nearest frontier',
  random: 'random',
};

/** How a plan was made, in words: the search, and what coarse ground counts for (α, Eq. 1). */
function howPlanned(p) {
  return `${POLICY_TEXT[p.policy] ?? p.policy}, coarse ground counts ×${p.alpha}`;
}

export class CandidatesPanel {
  /**
   * @param {{list: HTMLElement, detail: HTMLElement, summary: HTMLElement}} els
   * @param {{onSelect: (id: number|null) => void, onChanged: () => void}} handlers
   */
  constructor(els, { onSelect, onChanged }) {
    this.els = els;
    this.onSelect = onSelect;
    this.onChanged = onChanged;
    this.plan = null;
    this.plans = [];
    this.list = [];
    this.selected = null;
    this.operator = false;
    this.busy = false;
    this.message = '';
    this.messageIsError = false;
  }

  setRole(operator) {
    this.operator = operator;
    this.render();
  }

  /** @param {{plan: object|null, plans: object[], candidates: object[]}} answer */
  setData(answer) {
    this.plan = answer.plan;
    this.plans = answer.plans || (answer.plan ? [answer.plan] : []);
    this.list = (answer.candidates || []).filter((c) => c.state !== 'superseded');
    if (this.selected != null && !this.list.some((c) => c.id === this.selected)) {
      this.selected = null;
      this.message = ''; // it was about a candidate of an older plan
    }
    // "On its way" holds while the move does: a refusal or an arrival says otherwise.
    const now = this.list.find((c) => c.id === this.selected);
    if (this.messageState && now && now.state !== this.messageState) this._stateChanged(now);
    if (this.selected == null) {
      // Keep the eye on what matters: a move under way, else the best proposal.
      const moving = this.list.find((c) => c.state === 'moving' || c.state === 'interrupted');
      const best = this.list.find((c) => c.state === 'proposed');
      this.selected = (moving || best)?.id ?? null;
    }
    this.render();
  }

  select(id) {
    this.selected = id;
    this.message = '';
    this.messageState = null;
    this.render();
    this.onSelect(id);
  }

  get current() {
    return this.list.find((c) => c.id === this.selected) || null;
  }

  /** Every robot's approved move under way. */
  get movingAll() {
    return this.list.filter((c) => c.state === 'moving');
  }

  /** The move `robot` is carrying out, if any. */
  movingOf(robot) {
    return this.list.find((c) => c.state === 'moving' && c.robot === robot) || null;
  }

  get several() {
    return this.plans.length > 1;
  }

  /** The selected candidate left the state the message was about: say what it is now. */
  _stateChanged(now) {
    this.messageState = null;
    this.message = now.state === 'refused'
      ? `refused by ${now.robot || this.plan?.robot || 'the robot'}${now.note ? `: ${now.note}` : ''}`
      : '';
    this.messageIsError = now.state === 'refused';
  }

  _say(text, isError = false) {
    this.message = text;
    this.messageIsError = isError;
    this.render();
  }

  render() {
    const { list, detail, summary } = this.els;
    if (this.several) {
      const p = this.plan;
      summary.textContent = `${this.plans.length} robots, one plan each, no two sent to one spot · ${howPlanned(p)} · ` +
        this.plans.map((q) => `${q.robot}: plan ${q.id}`).join(', ');
    } else if (this.plan) {
      const p = this.plan;
      summary.textContent = `plan ${p.id} after scan ${p.based_on_scan} · ${howPlanned(p)} · ${nf0.format(p.plan_ms)} ms`;
    } else {
      summary.textContent = 'no plan yet: the planner runs after each scan';
    }

    list.replaceChildren();
    if (!this.list.length) {
      list.append(el('div', 'empty', this.plan ? 'the planner found no scan point worth making' : 'no candidates yet'));
    }
    for (const c of this.list) {
      const row = el('button', `cand-row state-${c.state}${c.id === this.selected ? ' selected' : ''}${this.several ? ' with-robot' : ''}`);
      row.type = 'button';
      row.dataset.id = String(c.id);
      row.dataset.state = c.state;
      if (c.robot) row.dataset.robot = c.robot;
      if (this.several) {
        const chip = el('span', 'robot-chip', c.robot);
        chip.style.color = robotColor(c.robot);
        row.append(chip);
      }
      row.append(
        el('span', `rank${c.custom ? ' custom' : ''}`, c.custom ? 'C' : String(c.rank)),
        el('span', 'f', `≈ ${nf0.format(newGround(c))} m²`),
        el('span', 'gain', `${matchDoubtful(c) ? '⚠ ' : ''}new ground · F ${nf0.format(c.f)}`),
        el('span', 'travel', `${nf1.format(c.travel_m)} m`),
        el('span', 'chip', STATE_TEXT[c.state] ?? c.state),
      );
      row.title = `${candidateName(c)}${c.robot ? ` for ${c.robot}` : ''} at (${nf1.format(c.x)} m, ${nf1.format(c.y)} m): ≈ ${nf0.format(newGround(c))} m² new ground, ${nf1.format(c.travel_m)} m drive${matchDoubtful(c) ? ' — the scan may not match the map' : ''}`;
      row.addEventListener('click', () => this.select(c.id));
      list.append(row);
    }

    // Nothing left to send the robot to: every point was refused (or rejected). The server
    // leaves refused points out of the next plans until the map there changes.
    const closed = (c) => c.state === 'refused' || c.state === 'rejected';
    if (this.list.length && this.list.every(closed) && this.list.some((c) => c.state === 'refused')) {
      const robots = [...new Set(this.list.filter((c) => c.state === 'refused').map((c) => c.robot || this.plan?.robot || 'the robot'))];
      list.prepend(el('div', 'all-refused',
        `${robots.join(', ')} refused every suggested point. Click a spot on the top view to propose your own, ` +
        'or ask for a scan where the robot stands; refused points are not suggested again until the map there changes.'));
    }

    detail.replaceChildren();
    const c = this.current;
    if (!c) {
      detail.append(el('div', 'hint', this.list.length ? 'select a candidate in the list or on the top view' : ''));
    } else {
      const title = el('div', 'detail-title', `${candidateName(c)}${this.several ? ` for ${c.robot}` : ''} — ${STATE_TEXT[c.state] ?? c.state}`);
      const grid = el('dl', 'facts');
      const fact = (k, v) => grid.append(el('dt', '', k), el('dd', '', v));
      fact('new ground', `≈ ${nf0.format(newGround(c))} m²`);
      fact('drive', `${nf1.format(c.travel_m)} m`);
      fact('never scanned', `${nf0.format(c.gain_unscanned_m2)} m²`);
      fact('now coarse', `${nf0.format(c.gain_low_res_m2)} m²`);
      fact('position', `${nf1.format(c.x)}, ${nf1.format(c.y)}, ${nf1.format(c.z)} m`);
      // The planner's score (paper Eq. 1): never-scanned ground plus α times the coarse ground.
      fact('score F', `${nf0.format(c.f)} m²`);
      if (c.overlap_m2 > 0) fact('overlap', `${nf0.format(c.overlap_m2)} m² of the map in view`);
      const forecast = matchForecast(c);
      if (forecast) fact('matching', forecast);
      if (c.note) fact('note', c.note);
      for (const dd of grid.querySelectorAll('dd:nth-of-type(n+5)')) dd.classList.add('wide');
      detail.append(title, grid);
      if (this.operator) {
        const actions = el('div', 'actions');
        // An interrupted move (its robot's bridge was lost) may be approved again.
        if (c.state === 'proposed' || c.state === 'interrupted') {
          const approve = el('button', 'primary', 'Approve move…');
          approve.id = 'approve';
          approve.type = 'button';
          // Each robot's move is approved on its own; only this candidate's robot must be free.
          const busyRobot = this.movingOf(c.robot);
          approve.disabled = this.busy || !!busyRobot;
          if (busyRobot) approve.title = `${c.robot || 'the robot'} is still driving to another point`;
          approve.addEventListener('click', () => this.approve(c));
          const reject = el('button', '', 'Reject…');
          reject.id = 'reject';
          reject.type = 'button';
          reject.disabled = this.busy;
          reject.addEventListener('click', () => this.reject(c));
          actions.append(approve, reject);
        } else if (c.state === 'moving') {
          const cancel = el('button', 'danger', 'Stop the move…');
          cancel.id = 'cancel-move';
          cancel.type = 'button';
          cancel.disabled = this.busy;
          cancel.addEventListener('click', () => this.cancel(c));
          actions.append(cancel);
        }
        if (actions.childElementCount) detail.append(actions);
      }
    }
    if (this.message) detail.append(el('div', this.messageIsError ? 'msg error' : 'msg', this.message));
  }

  async _decide(c, action, body) {
    this.busy = true;
    // A robot may refuse (or the move end) before the approval's reply is back: the new state
    // then reaches setData first, and says so in place of "sending…".
    const sentFrom = action === 'approve' ? c.state : null;
    this.messageState = sentFrom;
    this._say(`${action}: sending…`);
    try {
      await sendJson(`/api/v1/candidates/${c.id}/${action}`, body);
      this.busy = false;
      const done = { approve: 'approved: the robot is on its way', reject: 'rejected', cancel: 'move stopped' }[action];
      const now = this.current;
      if (sentFrom && now?.id === c.id && now.state !== sentFrom && now.state !== 'moving') {
        this.render(); // already answered: the refusal or the end of the move stays in view
      } else {
        this.messageState = action === 'approve' ? 'moving' : null;
        this._say(done);
      }
      this.onChanged();
    } catch (e) {
      this.busy = false;
      this._say(`${action} failed: ${e.detail || e.message}`, true);
      this.onChanged();
    }
  }

  async approve(c) {
    const robot = c.robot || this.plan?.robot || 'the robot';
    const ok = await confirmAction({
      title: `Approve ${candidateName(c)}?`,
      body: `${robot} will drive ${nf1.format(c.travel_m)} m to (${nf1.format(c.x)} m, ${nf1.format(c.y)} m) and scan there: about ${nf0.format(newGround(c))} m² of new ground (${nf0.format(c.gain_unscanned_m2)} m² never scanned, ${nf0.format(c.gain_low_res_m2)} m² now only coarse; F ${nf0.format(c.f)}).`,
      confirm: 'Approve and drive',
    });
    if (!ok) return;
    await this._decide(c, 'approve', ok.by ? { by: ok.by } : {});
  }

  async reject(c) {
    const ok = await confirmAction({
      title: `Reject ${candidateName(c)}?`,
      body: 'The robot will not be sent there. The rejection is recorded with your name and reason.',
      confirm: 'Reject',
      danger: true,
      reason: true,
    });
    if (!ok) return;
    const body = {};
    if (ok.by) body.by = ok.by;
    if (ok.reason) body.reason = ok.reason;
    await this._decide(c, 'reject', body);
  }

  async cancel(c) {
    const ok = await confirmAction({
      title: 'Stop the move?',
      body: `The robot stops where it is now instead of driving to ${candidateName(c)}. No scan is taken.`,
      confirm: 'Stop the robot',
      danger: true,
    });
    if (!ok) return;
    await this._decide(c, 'cancel', ok.by ? { by: ok.by } : {});
  }
}
