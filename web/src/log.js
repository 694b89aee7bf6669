// The log of decisions: who approved, rejected, stopped or proposed what and when, and what the
// robot did about it (GET /api/v1/decisions, then `mission` events). Newest first.

const MAX = 300;
const f1 = (v) => (Number.isFinite(v) ? v.toFixed(1) : '?');

// [3, 4, 5, 9] -> "3–5, 9"
function runs(ids) {
  const v = [...ids].sort((a, b) => a - b);
  const out = [];
  for (let i = 0; i < v.length; ) {
    let j = i;
    while (j + 1 < v.length && v[j + 1] === v[j] + 1) j++;
    out.push(j > i ? `${v[i]}\u2013${v[j]}` : `${v[i]}`);
    i = j + 1;
  }
  return out.join(', ');
}

function scans(ids) {
  return `${ids.length === 1 ? 'scan' : 'scans'} ${runs(ids)}`;
}

// "map corrected: scans 3–9 moved up to 12 cm"
function mapCorrected(e) {
  const parts = [];
  if (e.scans?.length) {
    parts.push(`${scans(e.scans)} moved up to ${Math.round(100 * (e.max_moved_m ?? 0))} cm / ${f1(e.max_turned_deg)}°`);
  }
  if (e.joined?.length) parts.push(`${scans(e.joined)} tied into the map`);
  if (e.left?.length) parts.push(`${scans(e.left)} set outside the map until a match agrees`);
  return `map corrected: ${parts.join('; ')}`;
}

function paramsChanged(e) {
  const p = e.params ?? {};
  const zones = p.no_go?.length ?? 0;
  const area = p.target ? `area of ${p.target.length} corners` : 'default area';
  return `${e.by ?? 'operator'} set the mission's parameters: ${area}, ${zones} no-go zone${zones === 1 ? '' : 's'}, coarse ground counts ×${p.alpha}`;
}

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
    case 'map_corrected':
      return mapCorrected(e);
    case 'goal':
      return `proposed custom point ${who} at (${f1(e.x)}, ${f1(e.y)}), F ${Math.round(e.f ?? 0)}`;
    case 'params':
      return paramsChanged(e);
    case 'finish':
      return `${e.by ?? 'operator'} finished the mission${e.reason ? `: ${e.reason}` : ''}`;
    case 'resume':
      return `${e.by ?? 'operator'} resumed the mission`;
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
