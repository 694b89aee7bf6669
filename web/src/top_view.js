// Top view: a region layer of the server (GET /api/v1/layers/{regions,elevation,movable}.png, placed
// in the map by its X-Scanplan-Layer-Bounds header) with the scan points, candidates and their travel
// paths, the robot and annotations drawn over it. Wheel zooms about the cursor, dragging pans; a
// click selects the candidate under it, or else reports the map position (to propose a goal there).
import { ANNOTATION_COLORS, SELECTED_COLOR, STATE_COLORS } from './markers.js';

const HIT_PX = 11;
const hex = (c) => `#${c.toString(16).padStart(6, '0')}`;

export class TopView {
  /**
   * @param {HTMLCanvasElement} canvas
   * @param {{onSelect: (id: number) => void, onMapClick: (x: number, y: number) => void,
   *          onHover: (p: {x: number, y: number} | null) => void}} handlers
   */
  constructor(canvas, { onSelect, onMapClick, onHover }) {
    this.canvas = canvas;
    this.ctx = canvas.getContext('2d');
    this.onSelect = onSelect;
    this.onMapClick = onMapClick;
    this.onHover = onHover;
    this.image = null; // ImageBitmap
    this.bounds = null; // {minX, minY, maxX, maxY} of the image in the map
    this.scans = [];
    this.candidates = [];
    this.selected = null;
    this.robots = [];
    this.annotations = [];
    this.pending = null; // {x, y}: a point the operator clicked, before proposing it
    this.dataBounds = null;
    this.scale = 4; // CSS px per metre
    this.cx = 0;
    this.cy = 0;
    this.userMoved = false;
    this.needsDraw = true;
    this._installInput();
    this._ro = new ResizeObserver(() => this._resize());
    this._ro.observe(canvas);
    this._resize();
    const loop = () => {
      if (this.needsDraw) this._draw();
      this._raf = requestAnimationFrame(loop);
    };
    this._raf = requestAnimationFrame(loop);
  }

  _resize() {
    const dpr = Math.min(window.devicePixelRatio || 1, 2);
    const w = Math.max(1, this.canvas.clientWidth);
    const h = Math.max(1, this.canvas.clientHeight);
    this.canvas.width = Math.round(w * dpr);
    this.canvas.height = Math.round(h * dpr);
    this.dpr = dpr;
    if (!this.userMoved) this.fit();
    this.redraw();
  }

  redraw() {
    this.needsDraw = true;
  }

  get width() {
    return this.canvas.clientWidth;
  }

  get height() {
    return this.canvas.clientHeight;
  }

  /** CSS pixel (relative to the canvas) of a map position. */
  screenOf(x, y) {
    return { x: this.width / 2 + (x - this.cx) * this.scale, y: this.height / 2 - (y - this.cy) * this.scale };
  }

  mapOf(px, py) {
    return { x: this.cx + (px - this.width / 2) / this.scale, y: this.cy - (py - this.height / 2) / this.scale };
  }

  /**
   * A new layer image. The old bitmap is released.
   * @param {ImageBitmap|null} image
   * @param {{minX, minY, maxX, maxY}|null} bounds
   */
  setLayer(image, bounds) {
    if (this.image && this.image !== image) this.image.close?.();
    this.image = image;
    this.bounds = bounds;
    if (!this.userMoved) this.fit();
    this.redraw();
  }

  /** Where the map has data (x-y bounds of the points): what fit() frames. */
  setDataBounds(b) {
    this.dataBounds = b;
    if (!this.userMoved) this.fit();
    this.redraw();
  }

  setScans(scans) {
    this.scans = scans;
    this.redraw();
  }

  setCandidates(list, selected) {
    this.candidates = list;
    this.selected = selected;
    if (!this.userMoved) this.fit();
    this.redraw();
  }

  /** @param {Array<{id: string, pose: object}>} robots */
  setRobots(robots) {
    this.robots = robots;
    this.redraw();
  }

  setAnnotations(list) {
    this.annotations = list;
    this.redraw();
  }

  setPending(p) {
    this.pending = p;
    this.redraw();
  }

  /** Frames the data (or the whole layer) with a margin. */
  fit() {
    let b = this.dataBounds ? { ...this.dataBounds } : null;
    for (const c of this.candidates) {
      if (c.state === 'superseded') continue;
      if (!b) b = { minX: c.x, minY: c.y, maxX: c.x, maxY: c.y };
      b.minX = Math.min(b.minX, c.x);
      b.minY = Math.min(b.minY, c.y);
      b.maxX = Math.max(b.maxX, c.x);
      b.maxY = Math.max(b.maxY, c.y);
    }
    if (!b && this.bounds) b = this.bounds;
    if (!b) return;
    const pad = 0.08;
    const w = Math.max(5, b.maxX - b.minX);
    const h = Math.max(5, b.maxY - b.minY);
    this.cx = (b.minX + b.maxX) / 2;
    this.cy = (b.minY + b.maxY) / 2;
    this.scale = Math.min(this.width / (w * (1 + 2 * pad)), this.height / (h * (1 + 2 * pad)));
    this.redraw();
  }

  resetView() {
    this.userMoved = false;
    this.fit();
  }

  _installInput() {
    const c = this.canvas;
    let drag = null;
    c.addEventListener('wheel', (e) => {
      e.preventDefault();
      const r = c.getBoundingClientRect();
      const px = e.clientX - r.left;
      const py = e.clientY - r.top;
      const before = this.mapOf(px, py);
      const k = Math.exp(-e.deltaY * 0.0015);
      this.scale = Math.min(80, Math.max(0.2, this.scale * k));
      const after = this.mapOf(px, py);
      this.cx += before.x - after.x;
      this.cy += before.y - after.y;
      this.userMoved = true;
      this.redraw();
    }, { passive: false });
    c.addEventListener('pointerdown', (e) => {
      if (e.button !== 0) return;
      c.setPointerCapture(e.pointerId);
      drag = { x: e.clientX, y: e.clientY, cx: this.cx, cy: this.cy, moved: false };
    });
    c.addEventListener('pointermove', (e) => {
      const r = c.getBoundingClientRect();
      this.onHover?.(this.mapOf(e.clientX - r.left, e.clientY - r.top));
      if (!drag) return;
      const dx = e.clientX - drag.x;
      const dy = e.clientY - drag.y;
      if (!drag.moved && Math.hypot(dx, dy) < 4) return;
      drag.moved = true;
      this.cx = drag.cx - dx / this.scale;
      this.cy = drag.cy + dy / this.scale;
      this.userMoved = true;
      this.redraw();
    });
    c.addEventListener('pointerleave', () => this.onHover?.(null));
    c.addEventListener('pointerup', (e) => {
      if (!drag) return;
      const wasDrag = drag.moved;
      drag = null;
      if (wasDrag) return;
      const r = c.getBoundingClientRect();
      const px = e.clientX - r.left;
      const py = e.clientY - r.top;
      const hit = this.candidateAt(px, py);
      if (hit) this.onSelect(hit.id);
      else {
        const p = this.mapOf(px, py);
        this.onMapClick(p.x, p.y);
      }
    });
  }

  /** The candidate drawn nearest (px, py), within a few pixels. */
  candidateAt(px, py) {
    let best = null;
    let bestD = HIT_PX;
    for (const cand of this.candidates) {
      if (cand.state === 'superseded') continue;
      const s = this.screenOf(cand.x, cand.y);
      const d = Math.hypot(s.x - px, s.y - py);
      if (d <= bestD) {
        best = cand;
        bestD = d;
      }
    }
    return best;
  }

  _draw() {
    this.needsDraw = false;
    const ctx = this.ctx;
    const w = this.width;
    const h = this.height;
    ctx.setTransform(this.dpr, 0, 0, this.dpr, 0, 0);
    ctx.fillStyle = '#141414';
    ctx.fillRect(0, 0, w, h);
    if (this.image && this.bounds) {
      const a = this.screenOf(this.bounds.minX, this.bounds.maxY);
      const b = this.screenOf(this.bounds.maxX, this.bounds.minY);
      ctx.imageSmoothingEnabled = this.scale * (this.bounds.maxX - this.bounds.minX) < this.image.width;
      ctx.drawImage(this.image, a.x, a.y, b.x - a.x, b.y - a.y);
    }
    this._drawScale(ctx, h);

    // Travel paths: the selected candidate's bold, a moving one green, the others faint.
    for (const cand of this.candidates) {
      if (!cand.path || cand.path.length < 2 || cand.state === 'superseded') continue;
      const selected = cand.id === this.selected;
      const moving = cand.state === 'moving';
      if (!selected && !moving && cand.state !== 'proposed') continue;
      ctx.beginPath();
      cand.path.forEach(([x, y], i) => {
        const s = this.screenOf(x, y);
        if (i === 0) ctx.moveTo(s.x, s.y);
        else ctx.lineTo(s.x, s.y);
      });
      ctx.setLineDash(selected || moving ? [] : [4, 4]);
      ctx.lineWidth = selected || moving ? 3 : 1.2;
      ctx.strokeStyle = moving ? hex(STATE_COLORS.moving) : selected ? hex(SELECTED_COLOR) : 'rgba(255,255,255,0.55)';
      ctx.stroke();
    }
    ctx.setLineDash([]);

    ctx.font = '600 11px system-ui, sans-serif';
    ctx.textBaseline = 'middle';
    for (const s of this.scans) {
      const p = this.screenOf(s.placed.x, s.placed.y);
      ctx.beginPath();
      ctx.arc(p.x, p.y, 4, 0, Math.PI * 2);
      ctx.fillStyle = '#ffffff';
      ctx.fill();
      ctx.lineWidth = 1.5;
      ctx.strokeStyle = '#1f2937';
      ctx.stroke();
    }

    // Candidates: rank in a circle (custom ones a diamond), coloured by state.
    const order = [...this.candidates].sort((a, b) => (a.id === this.selected) - (b.id === this.selected));
    for (const cand of order) {
      if (cand.state === 'superseded') continue;
      const p = this.screenOf(cand.x, cand.y);
      const selected = cand.id === this.selected;
      const color = selected ? SELECTED_COLOR : STATE_COLORS[cand.state] ?? STATE_COLORS.proposed;
      const r = selected ? 10 : 8;
      ctx.beginPath();
      if (cand.custom) {
        ctx.moveTo(p.x, p.y - r - 1);
        ctx.lineTo(p.x + r + 1, p.y);
        ctx.lineTo(p.x, p.y + r + 1);
        ctx.lineTo(p.x - r - 1, p.y);
        ctx.closePath();
      } else {
        ctx.arc(p.x, p.y, r, 0, Math.PI * 2);
      }
      ctx.fillStyle = hex(color);
      ctx.fill();
      ctx.lineWidth = selected ? 2.5 : 1.5;
      ctx.strokeStyle = '#0d1117';
      ctx.stroke();
      ctx.fillStyle = '#0d1117';
      ctx.textAlign = 'center';
      ctx.fillText(cand.custom ? 'C' : String(cand.rank), p.x, p.y + 0.5);
    }

    for (const a of this.annotations) {
      const p = this.screenOf(a.x, a.y);
      ctx.fillStyle = hex(ANNOTATION_COLORS[a.kind] ?? ANNOTATION_COLORS.note);
      ctx.fillRect(p.x - 4, p.y - 4, 8, 8);
      ctx.lineWidth = 1;
      ctx.strokeStyle = '#0d1117';
      ctx.strokeRect(p.x - 4, p.y - 4, 8, 8);
    }

    const named = this.robots.length > 1;
    for (const [k, { id, pose }] of this.robots.entries()) {
      if (!pose || !Number.isFinite(pose.x)) continue;
      const p = this.screenOf(pose.x, pose.y);
      const yaw = ((pose.yaw_deg || 0) * Math.PI) / 180;
      ctx.save();
      ctx.translate(p.x, p.y);
      ctx.rotate(-yaw);
      ctx.beginPath();
      ctx.moveTo(11, 0);
      ctx.lineTo(-7, 7);
      ctx.lineTo(-3, 0);
      ctx.lineTo(-7, -7);
      ctx.closePath();
      ctx.fillStyle = '#ff7b29';
      ctx.fill();
      ctx.lineWidth = 1.5;
      ctx.strokeStyle = '#0d1117';
      ctx.stroke();
      ctx.restore();
      if (named) {
        ctx.font = '11px system-ui, sans-serif';
        ctx.textAlign = 'left';
        ctx.textBaseline = 'middle';
        ctx.lineWidth = 3;
        ctx.strokeStyle = '#0d1117';
        // Alternately above and below, so robots side by side keep readable names.
        const dy = k % 2 ? 13 : -13;
        ctx.strokeText(id, p.x + 8, p.y + dy);
        ctx.fillStyle = '#ffb27a';
        ctx.fillText(id, p.x + 8, p.y + dy);
      }
    }

    if (this.pending) {
      const p = this.screenOf(this.pending.x, this.pending.y);
      ctx.strokeStyle = hex(SELECTED_COLOR);
      ctx.lineWidth = 2;
      ctx.beginPath();
      ctx.moveTo(p.x - 9, p.y);
      ctx.lineTo(p.x + 9, p.y);
      ctx.moveTo(p.x, p.y - 9);
      ctx.lineTo(p.x, p.y + 9);
      ctx.stroke();
      ctx.beginPath();
      ctx.arc(p.x, p.y, 6, 0, Math.PI * 2);
      ctx.stroke();
    }
  }

  _drawScale(ctx, h) {
    // A scale bar of a round length about 80 px long.
    const target = 80 / this.scale;
    const pow = 10 ** Math.floor(Math.log10(target));
    const len = [1, 2, 5, 10].map((k) => k * pow).find((v) => v >= target * 0.6) ?? pow * 10;
    const px = len * this.scale;
    const x0 = 8;
    const y0 = h - 10;
    ctx.fillStyle = 'rgba(13, 17, 23, 0.75)';
    ctx.fillRect(x0 - 4, y0 - 14, px + 44, 18);
    ctx.strokeStyle = '#e6edf3';
    ctx.lineWidth = 2;
    ctx.beginPath();
    ctx.moveTo(x0, y0 - 4);
    ctx.lineTo(x0, y0);
    ctx.lineTo(x0 + px, y0);
    ctx.lineTo(x0 + px, y0 - 4);
    ctx.stroke();
    ctx.fillStyle = '#e6edf3';
    ctx.font = '11px system-ui, sans-serif';
    ctx.textAlign = 'left';
    ctx.textBaseline = 'bottom';
    ctx.fillText(`${len} m`, x0 + px + 4, y0 + 1);
  }

  dispose() {
    cancelAnimationFrame(this._raf);
    this._ro.disconnect();
    this.image?.close?.();
  }
}

/** Parses X-Scanplan-Layer-Bounds: "minX,minY,maxX,maxY" (metres). */
export function parseLayerBounds(header) {
  if (!header) return null;
  const v = header.split(',').map(Number);
  if (v.length !== 4 || !v.every(Number.isFinite) || v[2] <= v[0] || v[3] <= v[1]) return null;
  return { minX: v[0], minY: v[1], maxX: v[2], maxY: v[3] };
}
