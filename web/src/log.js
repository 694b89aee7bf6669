// The log of decisions: who approved, rejected, stopped or proposed what and when, and what the
// robot did about it (GET /api/v1/decisions, then `mission` events). Newest first.

const MAX = 300;
const f1 = (v) => (Number.isFinite(v) ? v.toFixed(1) : '?');

function describe(e) {
  const who = e.candidate != null ? `#${e.candidate}` : '';
  switch (e.kind) {
    case 'approve':
      return `approved ${who}: ${e.robot} to (${f1(e.x)}, ${f1(e.y)})`;
    case 'reject':
      return `rejected ${who}${e.reason ? `: ${e.reason}` : ''}`;
    case 'cancel':
      return `stopped the move to ${who}`;
    case 'arrived':
      return `${e.robot} arrived at ${who}`;
    case 'refused':
      return `${e.robot} refused ${who}${e.message ? `: ${e.message}` : ''}`;
    case 'scan_requested':
      return `scan requested from ${e.robot}${e.after ? ` (after ${e.after})` : ''}`;
    case 'interrupted':
      return `move to ${who} interrupted: ${e.message || `${e.robot} lost`}`;
    case 'robot_lost':
      return `${e.robot} LOST${e.reason ? `: ${e.reason}` : ''}`;
    case 'robot_back':
      return `${e.robot} is back`;
    case 'scan_failed':
      return `scan by ${e.robot} failed${e.reason ? `: ${e.reason}` : ''}`;
    case 'scan_excluded':
      return `took scan ${e.scan} out of the map${e.reason ? `: ${e.reason}` : ''}`;
    case 'scan_restored':
      return `put scan ${e.scan} back into the map`;
    case 'goal':
      return `proposed custom point ${who} at (${f1(e.x)}, ${f1(e.y)}), F ${Math.round(e.f ?? 0)}`;
    default:
      return e.kind;
  }
}

function timeOf(at) {
  const d = new Date(at);
  if (Number.isNaN(d.getTime())) return at || '';
  return d.toLocaleTimeString('en-GB', { hour12: false });
}

export class DecisionLog {
  /** @param {HTMLElement} list */
  constructor(list) {
    this.list = list;
    this.entries = [];
  }

  /** Replaces the log with the server's record. */
  setAll(entries) {
    this.entries = entries.slice(-MAX);
    this.render();
  }

  /** A `mission` event. */
  add(e) {
    this.entries.push(e);
    if (this.entries.length > MAX) this.entries.splice(0, this.entries.length - MAX);
    this.render();
  }

  render() {
    const ul = this.list;
    ul.replaceChildren();
    ul.dataset.count = String(this.entries.length);
    if (!this.entries.length) {
      const li = document.createElement('li');
      li.className = 'muted';
      li.textContent = 'no decisions yet';
      ul.append(li);
      return;
    }
    for (let i = this.entries.length - 1; i >= 0; i--) {
      const e = this.entries[i];
      const li = document.createElement('li');
      li.className = `log-${e.kind}`;
      const t = document.createElement('time');
      t.textContent = timeOf(e.at);
      if (e.at) t.dateTime = e.at;
      const what = document.createElement('span');
      what.className = 'what';
      what.textContent = describe(e);
      li.append(t, what);
      if (e.by) {
        const by = document.createElement('span');
        by.className = 'by';
        by.textContent = e.by;
        li.append(by);
      }
      ul.append(li);
    }
  }
}
