// Whether the server is working on a scan: from its arrival (scan_received) to the first plan
// made from it or a later scan (plan_done), or its last word (map_updated). Meanwhile the page
// leaves the CPU to the server: on a laptop without a working GPU driver the 3-D view draws on the
// CPU (Chromium's software renderer, on every core) and the chunks are decoded on it, and both
// took the cores the server's matcher and planner needed for the candidates the operator waits
// for — the planner's stage ran 435 ms against 310 ms with the view not drawing (issue 19,
// docs/benchmarks.md). The view and the decoder hold off while a scan is in flight; the camera,
// when the operator moves it, is still drawn.
//
// A hold lasts at most maxMs from its first scan, whatever arrives meanwhile: with several robots
// scanning, scans overlap, and a hold that waited for a moment with none in flight kept new
// chunks out of the view for 7–12 s.
export class ScanInFlight {
  /**
   * onBusy / onIdle: called when a hold starts (a scan arrives) and when it ends.
   * maxMs: the longest a hold lasts (a server busy rebuilding, a plan that never came, scans of
   * several robots one after another).
   */
  constructor({ onBusy, onIdle, maxMs = 2000 }) {
    this.onBusy = onBusy;
    this.onIdle = onIdle;
    this.maxMs = maxMs;
    this.scans = new Set(); // ids of the scans in flight
    this.timer = null; // ends the hold after maxMs
  }

  get busy() {
    return this.scans.size > 0;
  }

  /** The server took scan `id` and is matching it. */
  received(id) {
    if (!Number.isFinite(id) || this.scans.has(id)) return;
    this.scans.add(id);
    if (this.scans.size > 1) return;
    this.timer = setTimeout(() => this.clear(), this.maxMs);
    this.onBusy();
  }

  /** A plan based on scan `id`, or its map_updated: it and every scan before it are done. */
  settled(id) {
    if (!Number.isFinite(id) || !this.busy) return;
    for (const s of [...this.scans]) if (s <= id) this.scans.delete(s);
    if (!this.busy) this._end();
  }

  /** Nothing holds the page any more (the hold's time is up, or the connection was lost). */
  clear() {
    if (!this.busy) return;
    this.scans.clear();
    this._end();
  }

  _end() {
    clearTimeout(this.timer);
    this.timer = null;
    this.onIdle();
  }
}
