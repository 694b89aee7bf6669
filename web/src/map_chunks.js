// The map as per-scan chunks: which scans the page holds, what it still needs, and the decoder
// worker (map_chunks_worker.js). Chunks come from the WebSocket (one binary frame per new scan)
// or, for scans the page missed (first load, a lost connection, chunks the server dropped for a
// slow link), from GET /api/v1/map.drc?since=A&until=B: the points of the scans A < id <= B, so a
// page never downloads a scan twice unless the pose graph moved it. Each chunk held is keyed by
// the scan's placed pose in the listing it was fetched after: a listing with another pose (a
// correction the page missed while disconnected, or one that came while the chunk was on its way)
// fetches it again.
import { ApiError, getBinaryWithHeaders } from './api.js';

const MAP_TIMEOUT_MS = 120000;

export class MapChunks {
  /**
   * @param {{onChunk: (c: {id: number, count: number, positions: Float32Array,
   *   colors: Uint8Array|null, min: number[], max: number[]}) => void,
   *   onChange: () => void, onRemove?: (id: number) => void}} handlers
   */
  constructor({ onChunk, onChange, onRemove = () => {} }) {
    this.onChunk = onChunk;
    this.onChange = onChange;
    this.onRemove = onRemove;
    this.held = new Map(); // scan id in the view -> its placed pose's key (null: came as it joined)
    this.pending = new Set(); // being fetched or decoded
    this.stale = new Set(); // pending, but the scan moved since: fetched again once in
    this.wanted = null; // the scans of the latest sync
    this.behind = false; // the map changed on the server since the latest sync
    this.failed = new Map(); // scan id -> message
    this.syncing = false;
    this.resyncWanted = null;
    this.error = null;
    this.stats = { wsChunks: 0, restChunks: 0, bytes: 0 };
    this.worker = null;
    this.jobs = new Map(); // key -> {resolve, reject}
    this.nextKey = 1;
    this.gate = null; // while paused: {promise, open}; decoding waits for it
  }

  /** Chunks that arrive wait to be decoded until resume() (they are counted as pending). */
  pause() {
    if (this.gate) return;
    let open;
    const promise = new Promise((resolve) => (open = resolve));
    this.gate = { promise, open };
  }

  resume() {
    const gate = this.gate;
    this.gate = null;
    gate?.open();
  }

  _worker() {
    if (!this.worker) {
      this.worker = new Worker(new URL('map_chunks_worker.js', document.baseURI));
      this.worker.onmessage = (e) => {
        const m = e.data;
        const job = this.jobs.get(m.key);
        if (!job) return;
        this.jobs.delete(m.key);
        if (m.type === 'decoded') job.resolve(m);
        else job.reject(new Error(`map decoding failed: ${m.message}`));
      };
      this.worker.onerror = (e) => {
        // A worker that cannot start fails every job; the next chunk makes a new one.
        const msg = e.message || 'the decoder worker failed to start';
        for (const job of this.jobs.values()) job.reject(new Error(`map decoding failed: ${msg}`));
        this.jobs.clear();
        this.worker.terminate();
        this.worker = null;
      };
    }
    return this.worker;
  }

  _decode(buffer, id) {
    const key = `${id}:${this.nextKey++}`;
    return new Promise((resolve, reject) => {
      this.jobs.set(key, { resolve, reject });
      try {
        this._worker().postMessage({ type: 'decode', key, buffer }, [buffer]);
      } catch (e) {
        this.jobs.delete(key);
        reject(e);
      }
    });
  }

  get pendingCount() {
    return this.pending.size;
  }

  /** True when every scan of the latest sync is held where the server has it now. */
  get current() {
    if (!this.wanted || this.behind || this.syncing || this.pending.size || this.failed.size) return false;
    return this.held.size === this.wanted.length && this.wanted.every((s) => this.held.get(s.id) === s.key);
  }

  /** The map changed on the server (an event said so): not current until the next sync. */
  outdated() {
    this.behind = true;
    this.onChange();
  }

  /** Forgets every chunk (a different session on the server). */
  reset() {
    this.held.clear();
    this.stale.clear();
    this.failed.clear();
    this.error = null;
    this.onChange();
  }

  async _take(id, buffer, source, key = null) {
    this.pending.add(id);
    this.onChange();
    try {
      while (this.gate) await this.gate.promise;
      const d = await this._decode(buffer, id);
      this.pending.delete(id);
      // Drawn all the same (nearer than nothing), and fetched again where it now is.
      const stale = this.stale.delete(id);
      if (!stale) this.held.set(id, key);
      const want = this.wanted?.find((s) => s.id === id);
      if (stale || (want && key !== null && want.key !== key)) queueMicrotask(() => this._sync(this.wanted, false));
      this.failed.delete(id);
      this.onChunk({ id, count: d.count, positions: d.positions, colors: d.colors, min: d.min, max: d.max, source });
    } catch (e) {
      this.pending.delete(id);
      this.failed.set(id, e.message);
      this.error = e;
    }
    this.onChange();
  }

  /**
   * The pose graph moved these scans (`map_corrected`): the chunks drawn stay until the next
   * sync brings each one where it now is (replacing it in the view).
   */
  forget(ids) {
    this.behind = true;
    for (const id of ids) {
      this.held.delete(id);
      this.failed.delete(id);
      if (this.pending.has(id)) this.stale.add(id);
    }
    this.onChange();
  }

  /** A binary frame from the WebSocket (op 1). */
  addFrame(frame) {
    const { id, payload } = frame;
    if (this.held.has(id) || this.pending.has(id) || !payload.byteLength) return;
    this.stats.wsChunks += 1;
    this.stats.bytes += payload.byteLength;
    this._take(id, payload, 'ws');
  }

  /**
   * Fetches the chunks of `scans` (the session's scans in the map, ascending ids, each
   * {id, placed}) that the page does not hold where the server has them, one scan at a time,
   * oldest first, and drops those it holds that are no longer in the map (a scan the operator
   * took out, or one the graph set outside). Calls made while one runs are merged.
   */
  sync(scans) {
    return this._sync(scans.map((s) => ({ id: s.id, key: JSON.stringify(s.placed ?? null) })));
  }

  // `listed`: the list is the server's latest (not one the page held already).
  async _sync(list, listed = true) {
    this.wanted = list;
    if (listed) this.behind = false;
    const wanted = new Map(list.map((s) => [s.id, s.key]));
    for (const [id, key] of [...this.held]) {
      if (!wanted.has(id)) {
        this.held.delete(id);
        this.onRemove(id);
      } else if (key === null) {
        // Came over the WebSocket as the scan joined; a move since came as map_corrected.
        this.held.set(id, wanted.get(id));
      }
    }
    if (this.syncing) {
      this.resyncWanted = list;
      return;
    }
    this.syncing = true;
    this.onChange();
    try {
      let next = list;
      while (next) {
        this.resyncWanted = null;
        await this._fetchMissing(next);
        next = this.resyncWanted;
      }
      this.error = null;
    } catch (e) {
      this.error = e instanceof ApiError || e instanceof Error ? e : new Error(String(e));
    } finally {
      this.syncing = false;
      this.onChange();
    }
  }

  async _fetchMissing(scans) {
    const sorted = [...scans].sort((a, b) => a.id - b.id);
    const decodes = [];
    const current = (s) => this.held.get(s.id) === s.key || this.pending.has(s.id);
    for (let k = 0; k < sorted.length; k++) {
      const { id, key } = sorted[k];
      if (current(sorted[k])) continue;
      // since = the scan before it (ids may have gaps), so exactly this scan comes back.
      const since = k > 0 ? sorted[k - 1].id : 0;
      const res = await getBinaryWithHeaders(`/api/v1/map.drc?since=${since}&until=${id}`, { timeoutMs: MAP_TIMEOUT_MS });
      // The WebSocket was quicker (a chunk that came as the scan joined is where it is listed).
      if (current(sorted[k]) || this.held.get(id) === null) continue;
      if (!res.body) {
        this.held.set(id, key); // no points in it
        continue;
      }
      this.stats.restChunks += 1;
      this.stats.bytes += res.body.byteLength;
      decodes.push(this._take(id, res.body, 'rest', key));
    }
    await Promise.all(decodes);
  }

  get lastHeld() {
    let m = 0;
    for (const id of this.held) if (id > m) m = id;
    return m;
  }
}
