// scanplan operator page: entry point. Polls the session, downloads and shows the map.
import './style.css';
import { ApiError, getBinary, getJson, getToken, initToken } from './api.js';
import { decodePointCloud, preloadDecoder } from './draco.js';
import { MapView } from './view.js';

const POLL_MS = 2000;
const MAP_TIMEOUT_MS = 120000;
const MAP_RETRY_MS = 10000; // after a failed map download/decode, wait this long before trying again

const $ = (id) => document.getElementById(id);
const ui = {
  state: $('conn-state'),
  scans: $('stat-scans'),
  points: $('stat-points'),
  message: $('status-message'),
  size: $('point-size'),
  sizeValue: $('point-size-value'),
  reset: $('reset-view'),
  view: $('view'),
};

const body = document.body;
const nf = new Intl.NumberFormat('en-US');

const state = {
  conn: 'connecting', // connecting | live | error
  scans: null, // scans in the last session answer
  points: null, // points in the last session answer
  mapScans: null, // the `scans` value the rendered map belongs to
  mapBusy: false,
  sessionError: null,
  mapError: null,
  mapRetryAt: 0,
};

function setText(el, text) {
  if (el && el.textContent !== text) el.textContent = text;
}

function render(view) {
  const err = state.sessionError || state.mapError;
  const conn = state.sessionError ? 'error' : state.conn;
  body.dataset.state = conn;
  body.dataset.scans = String(state.scans ?? 0);
  body.dataset.points = String(view ? view.pointCount : 0);
  setText(ui.state, conn);
  ui.state.className = `badge ${conn}`;
  setText(ui.scans, state.scans == null ? '–' : nf.format(state.scans));
  const shown = view ? view.pointCount : 0;
  let pts = state.points == null ? '–' : nf.format(state.points);
  if (view && state.points != null && shown !== state.points) pts += ` (${nf.format(shown)} shown)`;
  setText(ui.points, pts);
  let msg = '';
  if (err) msg = err.auth && !getToken() ? `${err.message}: open the page as /?token=YOUR_TOKEN` : err.message;
  else if (state.mapBusy) msg = 'loading map…';
  else if (conn === 'connecting') msg = 'connecting to the server…';
  else if (state.scans === 0) msg = 'waiting for the first scan';
  setText(ui.message, msg);
  ui.message.classList.toggle('error', !!err);
  body.dataset.error = err ? err.message : '';
}

function toError(e) {
  if (e instanceof ApiError || e instanceof Error) return e;
  return new Error(String(e));
}

let view = null;
try {
  view = new MapView(ui.view);
} catch (e) {
  console.error(e);
  state.conn = 'error';
  state.mapError = new Error('WebGL is not available in this browser: the map cannot be shown');
}

async function loadMap(scans) {
  state.mapBusy = true;
  render(view);
  try {
    const buf = await getBinary('/api/v1/map.drc', { timeoutMs: MAP_TIMEOUT_MS });
    const geometry = buf ? await decodePointCloud(buf) : null;
    if (view) view.setMap(geometry);
    else geometry?.dispose();
    state.mapScans = scans;
    state.mapError = null;
  } catch (e) {
    state.mapError = toError(e);
    state.mapRetryAt = Date.now() + MAP_RETRY_MS;
    if (state.mapError.auth) state.sessionError = state.mapError;
  } finally {
    state.mapBusy = false;
  }
  render(view);
}

async function poll() {
  try {
    const s = await getJson('/api/v1/session', { timeoutMs: 10000 });
    const scans = Number.isFinite(s?.scans) ? s.scans : 0;
    const points = Number.isFinite(s?.points) ? s.points : null;
    state.scans = scans;
    state.points = points;
    state.conn = 'live';
    state.sessionError = null;
    render(view);
    // Fetch the map when the number of scans changed, or retry after a failed download.
    const retryDue = !state.mapError || Date.now() >= state.mapRetryAt;
    if (view && !state.mapBusy && retryDue && (state.mapScans !== scans || state.mapError)) {
      await loadMap(scans);
    }
  } catch (e) {
    state.sessionError = toError(e);
    state.conn = 'error';
    render(view);
  }
  setTimeout(poll, POLL_MS);
}

// Controls
if (ui.size) {
  const applySize = () => {
    const v = Number(ui.size.value);
    view?.setPointSize(v);
    setText(ui.sizeValue, `${v}px`);
  };
  ui.size.addEventListener('input', applySize);
  applySize();
}
ui.reset?.addEventListener('click', () => view?.frame());
window.addEventListener('keydown', (ev) => {
  if (ev.target instanceof HTMLInputElement) return;
  if (ev.key === 'f' || ev.key === 'F') view?.frame();
});

initToken();
render(view);
if (view) preloadDecoder();
poll();

// For debugging from the console.
window.scanplan = { view, state };
