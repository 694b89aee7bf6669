// The live event stream: GET /api/v1/events as a WebSocket (docs/api.md).
// Text frames are JSON events {type, at, ...}; binary frames are [u8 op][u32 id LE][u64 ns LE][payload],
// op 1 = one scan's points as Draco. A lost connection is retried with exponential backoff and jitter;
// the owner resynchronises over REST on every (re)open.

export const OP_MAP_CHUNK = 1;
const HEADER_BYTES = 13;
const BACKOFF_MS = [1000, 2000, 4000, 8000, 15000];

/**
 * Parses a binary frame. Returns null when it is too short to hold the header.
 * @param {ArrayBuffer} buf
 * @returns {{op: number, id: number, sentMs: number, payload: ArrayBuffer} | null}
 */
export function parseBinaryFrame(buf) {
  if (!(buf instanceof ArrayBuffer) || buf.byteLength < HEADER_BYTES) return null;
  const v = new DataView(buf);
  const op = v.getUint8(0);
  const id = v.getUint32(1, true);
  const ns = v.getBigUint64(5, true);
  return { op, id, sentMs: Number(ns / 1000000n), payload: buf.slice(HEADER_BYTES) };
}

export class EventStream {
  /**
   * @param {{url: () => string, onEvent: (e: object) => void, onChunk: (c: object) => void,
   *          onState: (state: string, info: object) => void}} handlers
   */
  constructor({ url, onEvent, onChunk, onState }) {
    this.url = url;
    this.onEvent = onEvent;
    this.onChunk = onChunk;
    this.onState = onState;
    this.ws = null;
    this.state = 'idle'; // idle | connecting | open | lost | stopped
    this.attempt = 0; // failed attempts since the last successful open
    this.retryAt = 0;
    this.timer = null;
    this.everOpened = false;
    this.lastCloseCode = 0;
    this.lastCloseReason = '';
  }

  start() {
    if (this.state === 'stopped') return;
    this._connect();
  }

  stop() {
    this.state = 'stopped';
    clearTimeout(this.timer);
    if (this.ws) {
      const ws = this.ws;
      this.ws = null;
      ws.onclose = ws.onerror = ws.onmessage = ws.onopen = null;
      try {
        ws.close(1000, 'page closed');
      } catch {
        /* already closed */
      }
    }
  }

  /** Drops the current connection as if the link failed; the usual backoff follows. */
  drop(reason = 'link check failed') {
    if (!this.ws || this.state === 'stopped') return;
    const ws = this.ws;
    this.ws = null;
    ws.onclose = ws.onerror = ws.onmessage = ws.onopen = null;
    try {
      ws.close(4000, reason.slice(0, 100));
    } catch {
      /* ignore */
    }
    this._lost(0, reason);
  }

  /** Skips the wait of the current backoff. */
  retryNow() {
    if (this.state !== 'lost') return;
    clearTimeout(this.timer);
    this._connect();
  }

  _setState(state, info = {}) {
    this.state = state;
    this.onState(state, { attempt: this.attempt, retryAt: this.retryAt, code: this.lastCloseCode, reason: this.lastCloseReason, ...info });
  }

  _connect() {
    clearTimeout(this.timer);
    let ws;
    try {
      ws = new WebSocket(this.url());
    } catch (e) {
      this._lost(0, String(e && e.message ? e.message : e));
      return;
    }
    ws.binaryType = 'arraybuffer';
    this.ws = ws;
    this._setState('connecting');
    ws.onopen = () => {
      if (this.ws !== ws) return;
      this.attempt = 0;
      this.retryAt = 0;
      const resumed = this.everOpened;
      this.everOpened = true;
      this._setState('open', { resumed });
    };
    ws.onmessage = (msg) => {
      if (this.ws !== ws) return;
      if (typeof msg.data === 'string') {
        let e;
        try {
          e = JSON.parse(msg.data);
        } catch {
          console.warn('events: a text frame that is not JSON was ignored');
          return;
        }
        if (e && typeof e === 'object' && typeof e.type === 'string') this.onEvent(e);
      } else {
        const frame = parseBinaryFrame(msg.data);
        if (frame) this.onChunk(frame);
      }
    };
    ws.onerror = () => {
      /* onclose follows with the details */
    };
    ws.onclose = (ev) => {
      if (this.ws !== ws) return;
      this.ws = null;
      this._lost(ev.code, ev.reason || '');
    };
  }

  _lost(code, reason) {
    if (this.state === 'stopped') return;
    this.lastCloseCode = code;
    this.lastCloseReason = reason;
    const base = BACKOFF_MS[Math.min(this.attempt, BACKOFF_MS.length - 1)];
    const delay = Math.round(base * (0.75 + Math.random() * 0.5));
    this.attempt += 1;
    this.retryAt = Date.now() + delay;
    clearTimeout(this.timer);
    this.timer = setTimeout(() => this._connect(), delay);
    this._setState('lost');
  }
}

/** The events URL for the page's origin: ws(s)://host/api/v1/events?token=T. */
export function eventsUrl(token, loc = window.location) {
  const proto = loc.protocol === 'https:' ? 'wss:' : 'ws:';
  return `${proto}//${loc.host}/api/v1/events?token=${encodeURIComponent(token)}`;
}
