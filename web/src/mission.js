// The mission's live state: each robot's own status (robot_status events and the session's robots),
// the scan under way as a progress bar (scan_progress: fraction), what became of the last scan
// (scan_received, match_done: score, RMSE and the correction applied, map_updated), and the
// operator's "scan here" (POST /api/v1/scan, confirmed first).
import { sendJson } from './api.js';
import { confirmAction } from './dialog.js';
import { robotColor } from './robot_colors.js';

const nf0 = new Intl.NumberFormat('en-US', { maximumFractionDigits: 0 });
const f2 = (v) => (Number.isFinite(v) ? v.toFixed(2) : '–');

const ROBOT_TEXT = {
  idle: 'idle',
  offline: 'offline',
  moving: 'driving',
  arrived: 'arrived',
  refused: 'refused the move',
  scanning: 'scanning',
  unknown: 'no status yet',
};

export class MissionPanel {
  /** @param {{robots: HTMLElement, progress: HTMLElement, bar: HTMLElement, progressText: HTMLElement, match: HTMLElement, scanHere: HTMLButtonElement, message: HTMLElement}} els */
  constructor(els, { onChanged }) {
    this.els = els;
    this.onChanged = onChanged;
    this.robots = {}; // id -> {state, message, pose, command_id}
    this.scan = null; // the newest scan news of any robot: {robot, state, fraction, message}
    this.scans = {}; // robot id -> its own scan's {state, fraction, message, command_id}
    this.stage = ''; // what happens to the newest scan after it was taken
    this.match = null;
    this.matches = new Map(); // scan id -> match_done event seen by this page
    this.corrections = new Map(); // scan id -> placed − estimated, from GET /api/v1/scans
    this.goalDistances = {};
    this.operator = false;
    this.bridges = 0;
    els.scanHere.addEventListener('click', () => this.scanHere());
    this.progress = null; // GET /api/v1/session's "mission"
    els.finish?.addEventListener('click', () => this.finishOrResume());
  }

  setRole(operator) {
    this.operator = operator;
    this.render();
  }

  /** From GET /api/v1/session. */
  setSession(s) {
    this.bridges = s.bridges ?? 0;
    this.progress = s.mission || null;
    for (const [id, r] of Object.entries(s.robots || {})) {
      this.robots[id] = {
        ...(this.robots[id] || {}),
        state: r.state,
        message: r.message,
        pose: r.pose,
        command_id: r.command_id,
        // Servers without bridge liveliness have no `connected`: take the robot as connected.
        connected: r.connected !== false,
        lostAt: r.lost_at || null,
        lostReason: r.lost_reason || '',
      };
      if (r.scan && r.scan.state !== 'idle') this.scans[id] = { ...r.scan };
      if (r.scan && r.scan.state === 'scanning') this.scan = { robot: id, ...r.scan };
      else if (!this.scan && r.scan && r.scan.state !== 'idle') this.scan = { robot: id, ...r.scan };
    }
    this.render();
  }

  onRobotStatus(e) {
    this.robots[e.robot] = { ...(this.robots[e.robot] || {}), state: e.state, message: e.message, pose: e.pose, command_id: e.command_id };
    this.render();
  }

  /** robot_lost: the robot's bridge stopped asserting its liveliness, or shut down. */
  onRobotLost(e) {
    this.robots[e.robot] = { ...(this.robots[e.robot] || {}), connected: false, lostAt: e.lost_at || e.at, lostReason: e.reason || '' };
    this.render();
  }

  onRobotBack(e) {
    this.robots[e.robot] = { ...(this.robots[e.robot] || {}), connected: true, lostAt: null, lostReason: '' };
    this.render();
  }

  /** scan_failed: the scan under way was lost with its bridge; nothing of it reaches the map. */
  onScanFailed(e) {
    this.scan = { robot: e.robot, state: 'failed', fraction: e.fraction ?? 0, message: e.reason || 'the scan failed', command_id: e.command_id };
    this.scans[e.robot] = { ...this.scan };
    this.stage = '';
    this.render();
  }

  onScanProgress(e) {
    this.scan = { robot: e.robot, state: e.state, fraction: e.fraction, message: e.message, command_id: e.command_id };
    this.scans[e.robot] = { ...this.scan };
    if (e.state === 'scanning') this.stage = '';
    if (e.state === 'done') this.stage = 'received by the robot; sending it to the server…';
    this.render();
  }

  onScanReceived(e) {
    this.stage = `scan ${e.scan} stored (${nf0.format(e.points)} points); matching it against the map…`;
    this.render();
  }

  onMatchDone(e) {
    this.match = e;
    this.matches.set(e.scan, e);
    this.stage = `scan ${e.scan} matched; building the map…`;
    this.render();
  }

  onMapUpdated(e) {
    this.stage = `scan ${e.scan} is in the map`;
    this.render();
  }

  /** Where matching placed each scan relative to its reported pose (GET /api/v1/scans). */
  setScans(scans) {
    this.corrections.clear();
    for (const s of scans) {
      const e = s.estimated;
      const p = s.placed;
      if (!e || !p) continue;
      const dyaw = ((((p.yaw_deg - e.yaw_deg) % 360) + 540) % 360) - 180;
      this.corrections.set(s.id, {
        shift: Math.hypot(p.x - e.x, p.y - e.y),
        dz: p.z - e.z,
        dyaw,
        waiting: s.in_map === false,
        outside: s.outside || '',
      });
    }
    this.render();
  }

  /** One line per scan: the match result when this page saw it, else the correction on record. */
  matchHistory() {
    const ids = [...new Set([...this.corrections.keys(), ...this.matches.keys()])].sort((a, b) => a - b);
    return ids.map((id) => {
      const m = this.matches.get(id);
      const c = this.corrections.get(id);
      if (c?.waiting) {
        // The server says why (GET /api/v1/scans `outside`).
        return c.outside
          ? `scan ${id}: waiting outside the map (not drawn): ${c.outside}`
          : `scan ${id}: waiting outside the map until a match ties it in (not drawn)`;
      }
      if (m) {
        const d = m.correction || {};
        return `scan ${id}: score ${f2(m.score)}, RMSE ${f2(m.rmse)} m, shift ${f2(Math.hypot(d.x || 0, d.y || 0))} m / ${f2(d.yaw_deg)}°, ${m.applied ? 'applied' : 'not applied'}`;
      }
      if (id === ids[0] && c.shift === 0 && c.dyaw === 0) return `scan ${id}: the reference`;
      return `scan ${id}: placed ${f2(c.shift)} m / ${f2(c.dyaw)}° from its reported pose`;
    });
  }

  /** Distance left to the goal of a move under way (or null). */
  /** Metres left to each driving robot's goal, by robot id. */
  setGoalDistances(byRobot) {
    this.goalDistances = byRobot;
    this.render();
  }

  /** Robots whose bridge is lost: [{id, lostAt, lostReason}]. */
  lostRobots() {
    return Object.entries(this.robots)
      .filter(([, r]) => r.connected === false)
      .map(([id, r]) => ({ id, lostAt: r.lostAt, lostReason: r.lostReason }));
  }

  robotPose(id) {
    return this.robots[id]?.pose || null;
  }

  render() {
    const { robots, bar, progressText, progress, match, scanHere, message } = this.els;
    robots.replaceChildren();
    const ids = Object.keys(this.robots);
    if (!ids.length) {
      const d = document.createElement('div');
      d.className = 'muted';
      d.textContent = this.bridges ? 'robot connected, no status yet' : 'no robot connected';
      robots.append(d);
    }
    for (const id of ids) {
      const r = this.robots[id];
      const line = document.createElement('div');
      line.className = 'robot-line';
      const name = document.createElement('b');
      name.textContent = id;
      name.className = 'robot-name';
      name.style.setProperty('--robot', robotColor(id));
      const chip = document.createElement('span');
      const lost = r.connected === false;
      chip.className = lost ? 'chip robot-lost' : `chip robot-${r.state}`;
      chip.textContent = lost ? 'LOST' : ROBOT_TEXT[r.state] ?? r.state;
      line.append(name, chip);
      line.classList.toggle('lost', lost);
      let extra = r.message || '';
      if (lost) {
        const since = r.lostAt ? new Date(r.lostAt) : null;
        const when = since && !Number.isNaN(since.getTime()) ? ` since ${since.toLocaleTimeString('en-GB', { hour12: false })}` : '';
        extra = `no contact${when}${r.lostReason ? `: ${r.lostReason}` : ''}`;
        line.title = extra;
      }
      const toGo = this.goalDistances?.[id];
      if (r.state === 'moving' && toGo != null) extra = `${toGo.toFixed(1)} m to go${extra ? ` · ${extra}` : ''}`;
      // With several robots each shows its own scan: one robot's progress never stands for
      // another's.
      const own = this.scans[id];
      if (ids.length > 1 && own && own.state === 'scanning') {
        const p = Math.round(Math.max(0, Math.min(1, Number(own.fraction) || 0)) * 100);
        const meter = document.createElement('span');
        meter.className = 'robot-progress';
        meter.dataset.robot = id;
        meter.dataset.fraction = String(p / 100);
        meter.title = `${id} scanning ${p} %`;
        const fill = document.createElement('i');
        fill.style.width = `${p}%`;
        meter.append(fill);
        line.append(meter);
        extra = `scanning ${p} %${extra ? ` · ${extra}` : ''}`;
      }
      if (extra) {
        const m = document.createElement('span');
        m.className = 'muted';
        m.textContent = extra;
        line.append(m);
      }
      robots.append(line);
    }

    const s = this.scan;
    const frac = s ? Math.max(0, Math.min(1, Number(s.fraction) || 0)) : 0;
    bar.style.width = `${(frac * 100).toFixed(1)}%`;
    progress.dataset.state = s ? s.state : 'idle';
    progress.dataset.fraction = frac.toFixed(3);
    progress.classList.toggle('failed', !!s && s.state === 'failed');
    let text = 'no scan yet';
    if (s && s.state === 'scanning') text = `scanning ${Math.round(frac * 100)} %`;
    else if (s && s.state === 'done') text = this.stage || `scan done${s.message ? `: ${s.message}` : ''}`;
    else if (s && s.state === 'failed') text = `scan failed: ${s.message || 'no reason given'}`;
    else if (this.stage) text = this.stage;
    progressText.textContent = text;

    if (this.match) {
      const m = this.match;
      const c = m.correction || {};
      const shift = Math.hypot(c.x || 0, c.y || 0);
      const verdict = m.applied ? 'correction applied' : `not applied${m.message ? `: ${m.message}` : ''}`;
      match.textContent = `scan ${m.scan} matched (${m.method}): score ${f2(m.score)}, RMSE ${f2(m.rmse)} m, ` +
        `shift ${f2(shift)} m / ${f2(c.yaw_deg)}° — ${verdict}`;
      match.classList.toggle('warn', !m.applied);
    } else {
      const history = this.matchHistory();
      match.textContent = history.length > 1 ? `last match on record: ${history[history.length - 1]}` : 'the first scan is the reference; later ones are matched against the map';
      match.classList.remove('warn');
    }
    match.title = this.matchHistory().join('\n');
    this.renderProgress();
    scanHere.hidden = !this.operator;
    // "Scan here" asks every robot: not while any of them is scanning.
    scanHere.disabled = !this.bridges || Object.values(this.scans).some((x) => x.state === 'scanning');
    message.hidden = !message.textContent;
  }

  /** Coverage of the area, what the next scan adds, scans left; complete or finished. */
  renderProgress() {
    const { progressLine, finish } = this.els;
    if (!progressLine) return;
    const p = this.progress;
    progressLine.dataset.state = p?.state || '';
    if (!p) {
      progressLine.textContent = '';
    } else if (p.state === 'finished') {
      const at = new Date(p.finished_at);
      const when = Number.isNaN(at.getTime()) ? '' : ` at ${at.toLocaleTimeString('en-GB', { hour12: false })}`;
      progressLine.textContent = `mission finished by ${p.finished_by}${when} · ${p.coverage_pct.toFixed(0)} % of the area scanned`;
    } else if (p.state === 'complete') {
      progressLine.textContent = `mission complete: ${p.coverage_pct.toFixed(0)} % of the area scanned; no reachable point adds more than ${nf0.format(p.threshold_m2)} m² (best ${nf0.format(p.best_left_m2 ?? p.best_gain_m2)} m²) — finish it, or enlarge the area`;
    } else {
      const left = p.scans_left != null ? ` · ≈ ${p.scans_left} more scan${p.scans_left === 1 ? '' : 's'}` : '';
      const next = p.best_gain_m2 > 0 ? ` · next scan adds ≈ ${nf0.format(p.best_gain_m2)} m²` : '';
      progressLine.textContent = `${p.coverage_pct.toFixed(0)} % of the area scanned${next}${left}`;
    }
    if (finish) {
      finish.hidden = !this.operator || !p;
      finish.textContent = p?.state === 'finished' ? 'Resume' : 'Finish…';
    }
  }

  async finishOrResume() {
    const resume = this.progress?.state === 'finished';
    let answer = null;
    if (!resume) {
      answer = await confirmAction({
        title: 'Finish the mission?',
        body: 'Recorded with who and when; the robots stay where they are and the map stays. It can be resumed.',
        confirm: 'Finish mission',
        reason: true,
      });
      if (!answer) return;
    }
    const { message } = this.els;
    try {
      const body = {};
      if (answer?.by) body.by = answer.by;
      if (answer?.reason) body.reason = answer.reason;
      this.progress = await sendJson(`/api/v1/mission/${resume ? 'resume' : 'finish'}`, Object.keys(body).length ? body : undefined);
      message.textContent = resume ? 'mission resumed' : 'mission finished';
      message.classList.remove('error');
    } catch (e) {
      message.textContent = `${resume ? 'resume' : 'finish'} failed: ${e.detail || e.message}`;
      message.classList.add('error');
    }
    this.render();
    this.onChanged();
  }

  async scanHere() {
    const ok = await confirmAction({
      title: 'Scan here?',
      body: 'Every connected robot takes a scan where it stands now (about a minute).',
      confirm: 'Scan',
    });
    if (!ok) return;
    const { message } = this.els;
    try {
      const r = await sendJson('/api/v1/scan', undefined);
      message.textContent = `scan requested (command ${r?.command_id ?? '?'})`;
      message.classList.remove('error');
    } catch (e) {
      message.textContent = `scan request failed: ${e.detail || e.message}`;
      message.classList.add('error');
    }
    this.render();
    this.onChanged();
  }
}
