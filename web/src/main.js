// scanplan operator page: entry point. Wires the REST snapshot (session, scans, candidates, layers,
// decisions, annotations) and the live event stream (WebSocket: events and per-scan map chunks)
// to the panels. On every (re)connection it resynchronises over REST and fetches only the scans it
// does not hold.
import './style.css';
import { AnnotationsPanel } from './annotations.js';
import { AreaEditor } from './area_editor.js';
import { apiFetch, getJson, getToken, initToken } from './api.js';
import { CandidatesPanel } from './candidates.js';
import { CoverageChart } from './chart.js';
import { ExcludedScans } from './excluded_scans.js';
import { EventStream, OP_MAP_CHUNK, eventsUrl } from './events.js';
import { ExportMenu } from './exports.js';
import { GoalPicker } from './goals.js';
import { DecisionLog } from './log.js';
import { MapChunks } from './map_chunks.js';
import { Markers } from './markers.js';
import { ScanInFlight } from './scan_in_flight.js';
import { MeasureTool } from './measure.js';
import { setRobotIds } from './robot_colors.js';
import { MissionPanel } from './mission.js';
import { TopView, parseLayerBounds } from './top_view.js';
import { MapView } from './view.js';

const POLL_MS = 10000; // the session, as a link check and for robot poses between events
const LAYER_LEGENDS = {
  regions: [['#fad6b4', 'C completed'], ['#ecd040', 'M low-res, movable'], ['#466ec8', 'M not movable'], ['#404040', 'U unscanned']],
  elevation: [['linear-gradient(90deg,#30123b,#28bbec,#a2fc3c,#fb8022,#7a0403)', 'low → high (top surface)']],
  movable: [['#5abe5a', 'movable'], ['#969696', 'data, not movable'], ['#404040', 'no data']],
};

const $ = (id) => document.getElementById(id);
const body = document.body;
const nf = new Intl.NumberFormat('en-US');

const state = {
  ws: 'connecting',
  wsInfo: {},
  role: '',
  session: null,
  sessionDir: null,
  scans: [],
  error: null, // an error of the session or auth, shown in the top bar
  pollFailures: 0,
  layer: 'regions',
  layerRange: null, // [lo, hi] m of the elevation layer's colours
  tool: null, // null | measure | annotate
  resumedAt: 0,
  resumeScans: 0,
  heldAtLoss: 0,
};

// ---------------------------------------------------------------- views and panels
let view = null;
try {
  view = new MapView($('view'));
} catch (e) {
  console.error(e);
  state.error = new Error('WebGL is not available in this browser: the 3-D map cannot be shown');
}
const markers = view ? new Markers(view) : null;
const measure = view ? new MeasureTool(view, (t) => setViewStatus(t)) : null;

const chunks = new MapChunks({
  onChunk: (c) => {
    if (view) view.addChunk(c);
    render();
  },
  onRemove: (id) => {
    if (view) view.removeChunk(id);
    render();
  },
  onChange: () => render(),
});
// The candidates the operator waits for come first: while the server works on a scan the view
// draws only when the camera moves and new chunks wait to be decoded (scan_in_flight.js).
const inFlight = new ScanInFlight({
  onBusy: () => {
    view?.pause();
    chunks.pause();
  },
  onIdle: () => {
    view?.resume();
    chunks.resume();
  },
});
new ExportMenu($('export-select'), $('export-msg'));

const excluded = new ExcludedScans({
  list: $('excluded-scans'),
  onChange: () => soon(() => {
    refreshSession();
    refreshScans();
  }),
});

const topView = new TopView($('top-canvas'), {
  onSelect: (id) => candidates.select(id),
  onMapClick: (x, y) => goals.set({ x, y }),
  onHover: (p) => {
    $('top-coords').textContent = p ? `x ${p.x.toFixed(1)} m  y ${p.y.toFixed(1)} m` : '';
  },
});

const area = new AreaEditor(
  {
    edit: $('area-edit'),
    bar: $('area-bar'),
    drawArea: $('area-draw'),
    addZone: $('area-zone'),
    undo: $('area-undo'),
    close: $('area-close'),
    reset: $('area-reset'),
    save: $('area-save'),
    cancel: $('area-cancel'),
    zones: $('area-zones'),
    msg: $('area-msg'),
  },
  {
    topView,
    // Clicks on the top view draw corners now, not scan points.
    onEditing: (on) => on && goals.set(null),
  },
);

const candidates = new CandidatesPanel(
  { list: $('cand-list'), detail: $('cand-detail'), summary: $('cand-summary') },
  { onSelect: () => showCandidates(), onChanged: () => refreshCandidates() },
);

const goals = new GoalPicker(
  { bar: $('goal-bar'), where: $('goal-where'), propose: $('goal-propose'), clear: $('goal-clear'), msg: $('goal-msg') },
  {
    onPending: (p) => topView.setPending(p),
    // With several robots the point is for the robot of the selected candidate.
    robotFor: () => (candidates.several ? candidates.current?.robot ?? candidates.plan?.robot ?? null : null),
    onProposed: async (c) => {
      await refreshCandidates();
      candidates.select(c.id);
      selectTab('cands');
    },
  },
);

const mission = new MissionPanel(
  {
    robots: $('robots'),
    progressLine: $('mission-progress'),
    finish: $('finish-mission'),
    progress: $('scan-progress'),
    bar: $('scan-progress-bar'),
    progressText: $('scan-progress-text'),
    match: $('match-result'),
    scanHere: $('scan-here'),
    message: $('mission-msg'),
  },
  { onChanged: () => refreshSession() },
);

const chart = new CoverageChart($('chart'), $('chart-readout'));
const log = new DecisionLog($('log'));

const annotations = new AnnotationsPanel(
  { list: $('annot-list'), status: $('annot-status'), form: $('annot-form'), count: $('annot-count') },
  {
    onChange: (list) => {
      markers?.setAnnotations(list);
      topView.setAnnotations(list);
      updateTools();
    },
    onFocus: (a) => view?.focus(a.x, a.y, a.z),
  },
);

const events = new EventStream({
  url: () => eventsUrl(getToken()),
  onEvent: (e) => onEvent(e),
  onChunk: (frame) => {
    if (frame.op === OP_MAP_CHUNK) chunks.addFrame(frame);
  },
  onState: (s, info) => onStreamState(s, info),
});

// ---------------------------------------------------------------- rendering of the page frame
function setText(el, text) {
  if (el && el.textContent !== text) el.textContent = text;
}

function setViewStatus(text) {
  setText($('view-status'), text);
}

function render() {
  const err = state.error;
  const conn = err ? 'error' : state.ws === 'open' ? 'live' : 'connecting';
  body.dataset.state = conn;
  body.dataset.ws = state.ws;
  body.dataset.scans = String(state.session?.scans ?? 0);
  body.dataset.points = String(view ? view.pointCount : 0);
  body.dataset.drawn = String(view ? view.drawnCount : 0);
  body.dataset.chunks = String(view ? view.chunkCount : 0);
  // Every scan in the map drawn where the server has it now (after a correction: fetched again).
  body.dataset.mapCurrent = String(chunks.current);
  body.dataset.role = state.role;
  body.dataset.error = err ? err.message : '';
  setText($('conn-state'), conn);
  $('conn-state').className = `badge ${conn}`;
  setText($('role-badge'), state.role ? (state.role === 'operator' ? 'operator' : 'viewer: read only') : '');
  $('role-badge').className = `role ${state.role}`;
  setText($('stat-scans'), state.session ? nf.format(state.session.scans) : '–');
  const held = view ? view.pointCount : 0;
  let pts = state.session ? nf.format(state.session.points) : '–';
  if (view && held && view.drawnCount < held) pts += ` (${nf.format(view.drawnCount)} drawn)`;
  setText($('stat-points'), pts);

  let msg = '';
  const lost = mission.lostRobots();
  if (err) msg = err.auth && !getToken() ? `${err.message}: open the page as /?token=YOUR_TOKEN` : err.message;
  else if (lost.length) msg = `${lost.map((r) => r.id).join(', ')} LOST: no contact with the robot (see Mission)`;
  else if (chunks.error) msg = chunks.error.message;
  else if (chunks.pendingCount || chunks.syncing) {
    const total = state.scans.length || state.session?.scans || 0;
    msg = `loading map: ${chunks.held.size} of ${total} scans…`;
  } else if (!state.session) msg = 'connecting to the server…';
  else if (state.session && state.session.scans === 0) {
    msg = state.session.bridges ? 'waiting for the first scan' : 'waiting for the first scan: no robot is connected';
  }
  setText($('status-message'), msg);
  $('status-message').classList.toggle('error', !!err || !!chunks.error || lost.length > 0);
  body.dataset.lost = lost.map((r) => r.id).join(',');
  renderBanner();
}

function renderBanner() {
  const banner = $('banner');
  const text = $('banner-text');
  const retry = $('banner-retry');
  const lost = state.ws === 'lost' || (state.ws === 'connecting' && state.wsInfo.attempt > 0);
  if (lost) {
    const secs = Math.max(0, Math.ceil(((state.wsInfo.retryAt || 0) - Date.now()) / 1000));
    const when = state.ws === 'connecting' ? 'reconnecting now…' : `reconnecting in ${secs} s (attempt ${state.wsInfo.attempt})`;
    text.textContent = `Connection to the server lost — ${when}. The map on screen is kept; only new scans will be downloaded.`;
    banner.className = 'lost';
    banner.hidden = false;
    retry.hidden = state.ws !== 'lost';
    body.dataset.banner = 'lost';
  } else if (state.resumedAt && Date.now() - state.resumedAt < 5000) {
    const n = state.resumeScans;
    text.textContent = `Reconnected — ${n ? `fetched ${n} new scan${n > 1 ? 's' : ''}` : 'nothing was missed'}.`;
    banner.className = 'ok';
    banner.hidden = false;
    retry.hidden = true;
    body.dataset.banner = 'resumed';
  } else {
    banner.hidden = true;
    body.dataset.banner = '';
  }
}
setInterval(renderBanner, 1000);
$('banner-retry').addEventListener('click', () => events.retryNow());

function applyRole(role) {
  if (state.role === role) return;
  state.role = role;
  const operator = role === 'operator';
  candidates.setRole(operator);
  goals.setRole(operator);
  area.setRole(operator);
  mission.setRole(operator);
  annotations.setRole(operator);
  excluded.setRole(operator);
  if (!operator) $('exclude-scan').hidden = true;
  updateTools();
}

function updateTools() {
  const annotate = $('tool-annotate');
  const operator = state.role === 'operator';
  annotate.hidden = !operator;
  annotate.disabled = !annotations.available;
  annotate.title = annotations.available
    ? 'mark a victim, hazard, blockage or note at a point of the map'
    : annotations.reason || 'annotations are not available';
  if (!annotations.available && state.tool === 'annotate') setTool(null);
}

// ---------------------------------------------------------------- REST snapshot
function toError(e) {
  return e instanceof Error ? e : new Error(String(e));
}

async function refreshSession() {
  try {
    const s = await getJson('/api/v1/session', { timeoutMs: 10000 });
    if (state.sessionDir && s.session_dir !== state.sessionDir) {
      // Another session on this address: nothing held belongs to it.
      view?.clear();
      chunks.reset();
      chart.clear();
    }
    state.sessionDir = s.session_dir;
    state.session = s;
    state.error = null;
    state.pollFailures = 0;
    applyRole(s.role === 'operator' ? 'operator' : 'viewer');
    mission.setSession(s);
    updateRobot();
    if (s.bounds) {
      topView.setDataBounds({ minX: s.bounds.min[0], minY: s.bounds.min[1], maxX: s.bounds.max[0], maxY: s.bounds.max[1] });
    }
  } catch (e) {
    const err = toError(e);
    if (err.network) {
      state.pollFailures += 1;
      // Two failed polls while the socket looks open: the link is gone, the socket just doesn't know.
      if (state.pollFailures >= 2 && state.ws === 'open') events.drop('the server stopped answering');
    } else {
      state.error = err;
    }
  }
  render();
}

async function refreshScans() {
  try {
    const answer = await getJson('/api/v1/scans', { timeoutMs: 15000 });
    state.scans = answer.scans || [];
    excluded.set(answer.excluded);
    for (const s of state.scans) if (s.areas) chart.set(s.id, s.areas);
    markers?.setScans(state.scans);
    topView.setScans(state.scans);
    mission.setScans(state.scans);
    render();
    // A scan waiting for a match that ties it in may be metres off: not drawn until it joins.
    if (view) await chunks.sync(state.scans.filter((s) => s.in_map !== false));
  } catch (e) {
    if (!toError(e).network) console.warn('scans:', e);
  }
  render();
}

async function refreshCandidates() {
  try {
    const answer = await getJson('/api/v1/candidates', { timeoutMs: 15000 });
    candidates.setData(answer);
    showCandidates();
  } catch (e) {
    if (!toError(e).network) console.warn('candidates:', e);
  }
}

function showCandidates() {
  const list = candidates.list;
  markers?.setCandidates(list, candidates.selected);
  topView.setCandidates(list, candidates.selected);
  body.dataset.candidates = String(list.length);
  updateRobot();
}

let layerBusy = false;
let layerAgain = false;
async function refreshLayer() {
  if (layerBusy) {
    layerAgain = true;
    return;
  }
  layerBusy = true;
  try {
    do {
      layerAgain = false;
      const name = state.layer;
      const res = await apiFetch(`/api/v1/layers/${name}.png`, { timeoutMs: 30000 });
      try {
        if (res.status === 204) {
          topView.setLayer(null, null);
          continue;
        }
        const bounds = parseLayerBounds(res.headers.get('X-Scanplan-Layer-Bounds'));
        const range = (res.headers.get('X-Scanplan-Layer-Range') || '').split(',').map(Number);
        if (name === state.layer) state.layerRange = range.length === 2 && range.every(Number.isFinite) ? range : null;
        const blob = await res.blob();
        const image = await createImageBitmap(blob);
        if (name === state.layer) topView.setLayer(image, bounds);
        else image.close();
      } finally {
        res.done();
      }
    } while (layerAgain);
  } catch (e) {
    if (!toError(e).network) console.warn('layer:', e);
  } finally {
    layerBusy = false;
  }
  renderLegend();
}

function renderLegend() {
  const legend = $('top-legend');
  legend.replaceChildren();
  for (let [color, label] of LAYER_LEGENDS[state.layer] || []) {
    // The elevation colours in metres: the lowest and highest top surface of the area.
    if (state.layer === 'elevation' && state.layerRange) {
      const [lo, hi] = state.layerRange;
      const m = (v) => `${(Math.abs(v) < 0.05 ? 0 : v).toFixed(1)} m`;
      label = `${m(lo)} → ${m(hi)} (top surface)`;
    }
    const item = document.createElement('span');
    const sw = document.createElement('i');
    sw.className = color.startsWith('linear') ? 'sw wide' : 'sw';
    sw.style.background = color;
    item.append(sw, document.createTextNode(label));
    legend.append(item);
  }
}

async function refreshDecisions() {
  try {
    const answer = await getJson('/api/v1/decisions?limit=200', { timeoutMs: 15000 });
    log.setAll(answer.decisions || []);
  } catch (e) {
    if (!toError(e).network) console.warn('decisions:', e);
  }
}

/** Everything over REST; after a reconnection only the scans the page lacks are downloaded. */
async function resync() {
  await refreshSession();
  if (state.error?.auth) return;
  await Promise.all([refreshScans(), refreshCandidates(), refreshLayer(), refreshDecisions(), annotations.load(), area.load()]);
}

// ---------------------------------------------------------------- robot, path
function updateRobot() {
  const robots = state.session?.robots || {};
  const ids = Object.keys({ ...robots, ...mission.robots }).sort();
  if (setRobotIds([...ids, ...candidates.list.map((c) => c.robot)])) {
    // A robot joined: colours follow the sorted ids, so every panel draws again.
    candidates.render();
    mission.render();
    markers?.setCandidates(candidates.list, candidates.selected);
  }
  const placed = ids.map((id) => ({ id, pose: mission.robotPose(id) }));
  markers?.setRobots(placed);
  topView.setRobots(placed);
  // Each driving robot's path from where it is, and what is left of the drive.
  const drives = [];
  const toGo = {};
  for (const moving of candidates.movingAll) {
    const pose = mission.robotPose(moving.robot);
    if (!pose) continue;
    drives.push({ path: moving.path, z0: pose.z ?? moving.z, z1: moving.z });
    toGo[moving.robot] = Math.hypot(moving.x - pose.x, moving.y - pose.y);
  }
  markers?.setPaths(drives);
  mission.setGoalDistances(toGo);
}

// ---------------------------------------------------------------- live events
let scansTimer = null;
function soon(fn, ms = 300) {
  // Several events of one scan arrive together: one REST refresh for all of them.
  clearTimeout(scansTimer);
  scansTimer = setTimeout(fn, ms);
}

// The latest refresh of the candidates a plan_done asked for: the view draws again only once the
// operator can see them (after their next frame).
let candidatesShown = Promise.resolve();
function afterCandidates(fn) {
  candidatesShown.finally(() => requestAnimationFrame(() => setTimeout(fn, 0)));
}

function onEvent(e) {
  switch (e.type) {
    case 'scan_progress':
      mission.onScanProgress(e);
      break;
    case 'robot_status':
      mission.onRobotStatus(e);
      updateRobot();
      break;
    case 'scan_received':
      inFlight.received(e.scan);
      mission.onScanReceived(e);
      break;
    case 'match_done':
      mission.onMatchDone(e);
      break;
    case 'scan_excluded':
    case 'scan_restored':
      log.add({ ...e, kind: e.type });
      break;
    case 'map_corrected':
    case 'map_rebuilt':
      if (e.type === 'map_corrected') {
        log.add({ ...e, kind: 'map_corrected' });
        // Fetched again where they now are (refreshScans syncs the chunks).
        chunks.forget([...(e.scans || []), ...(e.joined || [])]);
      } else {
        chunks.outdated();
      }
      soon(() => {
        refreshSession();
        refreshScans();
        refreshLayer();
        refreshCandidates();
      });
      break;
    case 'map_updated':
      afterCandidates(() => inFlight.settled(e.scan));
      chunks.outdated();
      mission.onMapUpdated(e);
      chart.set(e.scan, e);
      soon(() => {
        refreshSession();
        refreshScans();
        refreshLayer();
      });
      break;
    case 'plan_done':
      candidatesShown = refreshCandidates();
      afterCandidates(() => inFlight.settled(e.based_on_scan));
      refreshLayer();
      // The mission's progress line (the best candidate's gain, the estimate) follows the plan.
      refreshSession();
      break;
    case 'mission':
      log.add(e);
      refreshCandidates();
      if (e.kind === 'params') area.load();
      break;
    case 'annotation':
      annotations.onEvent(e);
      break;
    case 'annotation_deleted':
      annotations.onDeleted(e);
      break;
    case 'robot_lost':
      mission.onRobotLost(e);
      render();
      log.add({ ...e, kind: 'robot_lost' });
      refreshCandidates();
      break;
    case 'robot_back':
      mission.onRobotBack(e);
      render();
      log.add({ ...e, kind: 'robot_back' });
      refreshCandidates();
      break;
    case 'scan_failed':
      mission.onScanFailed(e);
      log.add({ ...e, kind: 'scan_failed' });
      break;
    case 'binary_dropped':
      // The server dropped chunks for a slow link: fetch those scans over REST.
      refreshScans();
      break;
    default:
      break;
  }
}

let firstSnapshot = null; // the REST snapshot taken without waiting for the socket any longer
function onStreamState(s, info) {
  const was = state.ws;
  state.ws = s;
  state.wsInfo = info;
  if (s === 'open') {
    clearTimeout(firstSnapshot);
    const resumed = info.resumed;
    const before = chunks.held.size;
    resync().then(() => {
      if (resumed) {
        state.resumedAt = Date.now();
        state.resumeScans = Math.max(0, chunks.held.size - before);
        render();
      }
    });
  } else if (s === 'lost' && was === 'open') {
    state.heldAtLoss = chunks.held.size;
  }
  if (s !== 'open') inFlight.clear();
  render();
}

// ---------------------------------------------------------------- 3-D tools and controls
function setTool(tool) {
  state.tool = state.tool === tool ? null : tool;
  $('tool-measure').setAttribute('aria-pressed', String(state.tool === 'measure'));
  $('tool-annotate').setAttribute('aria-pressed', String(state.tool === 'annotate'));
  $('view').classList.toggle('picking', !!state.tool);
  if (state.tool !== 'annotate') annotations.closeForm();
  if (state.tool === 'measure') setViewStatus('measure: click the first point on the map');
  else if (state.tool === 'annotate') setViewStatus('annotate: click the point of the map to mark');
  else setViewStatus('');
}

$('exclude-scan').addEventListener('click', (e) => {
  const id = Number(e.currentTarget.dataset.scan);
  e.currentTarget.hidden = true;
  if (Number.isInteger(id) && id > 0) excluded.exclude(id);
});

if (view) {
  view.onClick = (e) => {
    if (state.tool === 'measure') {
      measure.handleClick(e);
    } else if (state.tool === 'annotate') {
      const hit = view.pick(e.clientX, e.clientY);
      if (!hit) setViewStatus('annotate: no map point under the cursor; click on the points');
      else annotations.openForm(hit.point, { x: e.clientX, y: e.clientY });
    } else {
      const hit = view.pick(e.clientX, e.clientY);
      const out = $('exclude-scan');
      out.hidden = !hit || state.role !== 'operator';
      if (hit) {
        const p = hit.point;
        out.dataset.scan = String(hit.scan);
        out.textContent = `Take scan ${hit.scan} out of the map…`;
        setViewStatus(`point (${p.x.toFixed(2)}, ${p.y.toFixed(2)}, ${p.z.toFixed(2)}) of scan ${hit.scan}`);
      }
    }
  };
  view.onLodChange = () => render();
}

$('tool-measure').addEventListener('click', () => setTool('measure'));
$('tool-annotate').addEventListener('click', () => setTool('annotate'));
$('reset-view').addEventListener('click', () => view?.frame());
$('color-mode').addEventListener('change', (e) => view?.setColorMode(e.target.value));
$('budget').addEventListener('change', (e) => view?.setBudget(Number(e.target.value)));
const applySize = () => {
  const v = Number($('point-size').value);
  view?.setPointSize(v);
  setText($('point-size-value'), `${v}px`);
};
$('point-size').addEventListener('input', applySize);
applySize();

$('layer-select').addEventListener('change', (e) => {
  state.layer = e.target.value;
  state.layerRange = null;
  renderLegend();
  refreshLayer();
});
$('top-fit').addEventListener('click', () => topView.resetView());

function selectTab(name) {
  for (const b of document.querySelectorAll('.tabs [data-tab]')) b.setAttribute('aria-selected', String(b.dataset.tab === name));
  $('tab-cands').hidden = name !== 'cands';
  $('tab-annots').hidden = name !== 'annots';
}
for (const b of document.querySelectorAll('.tabs [data-tab]')) b.addEventListener('click', () => selectTab(b.dataset.tab));

window.addEventListener('keydown', (ev) => {
  if (ev.target instanceof HTMLInputElement || ev.target instanceof HTMLSelectElement || $('confirm').open) return;
  if (ev.key === 'f' || ev.key === 'F') view?.frame();
  if (ev.key === 'm' || ev.key === 'M') setTool('measure');
  if (ev.key === 'Escape') {
    measure?.clear();
    annotations.closeForm();
    goals.set(null);
    if (area.drawing) area.dropShape();
    if (state.tool) setTool(state.tool);
  }
});

// ---------------------------------------------------------------- start
initToken();
render();
renderLegend();
if (state.error) {
  render();
} else {
  // The snapshot follows the socket's opening, so no event falls between the two; a socket that
  // cannot open (a proxy, a dead link) must not keep the map away, though.
  events.start();
  firstSnapshot = setTimeout(resync, 3000);
}
setInterval(refreshSession, POLL_MS);

// For the console and for tests.
window.scanplan = { view, state, chunks, events, topView, candidates, annotations, measure, chart, log, mission, area };
