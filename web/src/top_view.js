// Top view: a region layer of the server (GET /api/v1/layers/{regions,elevation,movable}.png, placed
// in the map by its X-Scanplan-Layer-Bounds header) with the scan points, candidates and their travel
// paths, the robots, annotations, the target area and the no-go zones drawn over it. Wheel or a
// two-finger pinch zooms, dragging pans; a click (or tap) selects the candidate under it, or else
// reports the map position (to propose a goal there). While the area is edited, clicks and corner
// drags go to the area editor.
import { ANNOTATION_COLORS, SELECTED_COLOR, STATE_COLORS } from './markers.js';
import { robotColor } from './robot_colors.js';

const coarse = () => window.matchMedia?.('(pointer: coarse)').matches;
const hitPx = () => (coarse() ? 22 : 11); // a finger needs a larger target than a mouse
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
    this.area = null; // the AreaEditor: the shapes to draw, and clicks while editing
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

  /** @param {import('./area_editor.js').AreaEditor} editor */
  setAreaEditor(editor) {
    this.area = editor;
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
    const pointers = new Map(); // pointerId -> {x, y} (client px): two of them pinch
    let drag = null;
    let pinch = null;
    const local = (e) => {
      const r = c.getBoundingClientRect();
      return { px: e.clientX - r.left, py: e.clientY - r.top };
    };
    const zoomAbout = (px, py, k) => {
      const before = this.mapOf(px, py);
      this.scale = Math.min(80, Math.max(0.2, this.scale * k));
      const after = this.mapOf(px, py);
      this.cx += before.x - after.x;
      this.cy += before.y - after.y;
      this.userMoved = true;
      this.redraw();
    };
    const startPinch = () => {
      const [a, b] = [...pointers.values()];
      pinch = { d: Math.max(1, Math.hypot(a.x - b.x, a.y - b.y)), mx: (a.x + b.x) / 2, my: (a.y + b.y) / 2 };
      drag = null; // a second finger turns a tap or drag into a pinch
    };
    c.addEventListener('wheel', (e) => {
      e.preventDefault();
      const { px, py } = local(e);
      zoomAbout(px, py, Math.exp(-e.deltaY * 0.0015));
    }, { passive: false });
    c.addEventListener('pointerdown', (e) => {
      if (e.pointerType === 'mouse' && e.button !== 0) return;
      c.setPointerCapture(e.pointerId);
      pointers.set(e.pointerId, { x: e.clientX, y: e.clientY });
      if (pointers.size === 2) {
        startPinch();
        return;
      }
      if (pointers.size > 2) return;
      const { px, py } = local(e);
      const handle = this.area?.handleAt(px, py) ?? null;
      drag = { x: e.clientX, y: e.clientY, cx: this.cx, cy: this.cy, moved: false, handle };
    });
    c.addEventListener('pointermove', (e) => {
      const { px, py } = local(e);
      if (e.pointerType === 'mouse') this.onHover?.(this.mapOf(px, py));
      if (pointers.has(e.pointerId)) pointers.set(e.pointerId, { x: e.clientX, y: e.clientY });
      if (pinch && pointers.size === 2) {
        const [a, b] = [...pointers.values()];
        const d = Math.max(1, Math.hypot(a.x - b.x, a.y - b.y));
        const mx = (a.x + b.x) / 2;
        const my = (a.y + b.y) / 2;
        // Pan with the fingers' midpoint, zoom about it by the change of their distance.
        this.cx -= (mx - pinch.mx) / this.scale;
        this.cy += (my - pinch.my) / this.scale;
        const r = c.getBoundingClientRect();
        zoomAbout(mx - r.left, my - r.top, d / pinch.d);
        pinch = { d, mx, my };
        return;
      }
      if (!drag) return;
      const dx = e.clientX - drag.x;
      const dy = e.clientY - drag.y;
      if (!drag.moved && Math.hypot(dx, dy) < (e.pointerType === 'mouse' ? 4 : 8)) return;
      drag.moved = true;
      if (drag.handle) {
        this.area.moveHandle(drag.handle, this.mapOf(px, py));
        return;
      }
      this.cx = drag.cx - dx / this.scale;
      this.cy = drag.cy + dy / this.scale;
      this.userMoved = true;
      this.redraw();
    });
    c.addEventListener('pointerleave', (e) => {
      if (e.pointerType === 'mouse') this.onHover?.(null);
    });
    const release = (e) => {
      pointers.delete(e.pointerId);
      if (pointers.size < 2) pinch = null;
    };
    c.addEventListener('pointercancel', (e) => {
      release(e);
      drag = null;
    });
    c.addEventListener('pointerup', (e) => {
      release(e);
      if (!drag) return;
      const wasDrag = drag.moved;
      drag = null;
      if (wasDrag) return;
      const { px, py } = local(e);
      const p = this.mapOf(px, py);
      // A tap shows where it was, as the mouse's hover does.
      if (e.pointerType !== 'mouse') this.onHover?.(p);
      if (this.area?.click(p)) return;
      const hit = this.candidateAt(px, py);
      if (hit) this.onSelect(hit.id);
      else this.onMapClick(p.x, p.y);
    });
  }

  /** The candidate drawn nearest (px, py), within a few pixels. */
  candidateAt(px, py) {
    let best = null;
    let bestD = hitPx();
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
    this._drawArea(ctx);
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
    const several = new Set(this.candidates.map((c) => c.robot)).size > 1;
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
      if (several && cand.robot) {
        // Whose candidate: a ring in its robot's colour.
        ctx.beginPath();
        ctx.arc(p.x, p.y, r + 3, 0, Math.PI * 2);
        ctx.lineWidth = 2.5;
        ctx.strokeStyle = robotColor(cand.robot);
        ctx.stroke();
      }
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
      ctx.fillStyle = robotColor(id);
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
        ctx.fillStyle = robotColor(id);
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

  _polygonPath(ctx, poly, close = true) {
    ctx.beginPath();
    poly.forEach(([x, y], i) => {
      const s = this.screenOf(x, y);
      if (i === 0) ctx.moveTo(s.x, s.y);
      else ctx.lineTo(s.x, s.y);
    });
    if (close) ctx.closePath();
  }

  // The target area (cyan outline; the default square dashed grey), the no-go zones (red, hatched)
  // and, while editing, every corner as a handle and the shape being drawn.
  _drawArea(ctx) {
    const shapes = this.area?.shapes();
    if (!shapes) return;
    const { target, noGo, drawing, editing } = shapes;
    ctx.save();
    if (target) {
      this._polygonPath(ctx, target);
      ctx.setLineDash([]);
      ctx.lineWidth = 2;
      ctx.strokeStyle = '#39c5f3';
      ctx.stroke();
    } else if (this.bounds && editing) {
      const { minX, minY, maxX, maxY } = this.bounds;
      this._polygonPath(ctx, [[minX, minY], [maxX, minY], [maxX, maxY], [minX, maxY]]);
      ctx.setLineDash([6, 5]);
      ctx.lineWidth = 1.5;
      ctx.strokeStyle = 'rgba(230,237,243,0.6)';
      ctx.stroke();
    }
    if (!this._hatch) {
      const tile = document.createElement('canvas');
      tile.width = tile.height = 8;
      const t = tile.getContext('2d');
      t.strokeStyle = 'rgba(248,81,73,0.55)';
      t.lineWidth = 1.5;
      t.beginPath();
      t.moveTo(0, 8);
      t.lineTo(8, 0);
      t.stroke();
      this._hatch = ctx.createPattern(tile, 'repeat');
    }
    ctx.setLineDash([]);
    for (const zone of noGo) {
      this._polygonPath(ctx, zone);
      ctx.fillStyle = 'rgba(248,81,73,0.18)';
      ctx.fill();
      ctx.fillStyle = this._hatch;
      ctx.fill();
      ctx.lineWidth = 2;
      ctx.strokeStyle = '#f85149';
      ctx.stroke();
    }
    if (editing) {
      for (const poly of [target, ...noGo]) {
        if (!poly) continue;
        for (const [x, y] of poly) {
          const s = this.screenOf(x, y);
          ctx.fillStyle = '#e6edf3';
          ctx.fillRect(s.x - 4, s.y - 4, 8, 8);
          ctx.strokeStyle = '#0d1117';
          ctx.lineWidth = 1;
          ctx.strokeRect(s.x - 4, s.y - 4, 8, 8);
        }
      }
    }
    if (drawing && drawing.corners.length) {
      this._polygonPath(ctx, drawing.corners, false);
      ctx.setLineDash([5, 4]);
      ctx.lineWidth = 2;
      ctx.strokeStyle = drawing.kind === 'area' ? '#39c5f3' : '#f85149';
      ctx.stroke();
      ctx.setLineDash([]);
      drawing.corners.forEach(([x, y], i) => {
        const s = this.screenOf(x, y);
        ctx.beginPath();
        ctx.arc(s.x, s.y, i === 0 ? 6 : 4, 0, Math.PI * 2);
        ctx.fillStyle = i === 0 ? '#e6edf3' : ctx.strokeStyle;
        ctx.fill();
      });
    }
    ctx.restore();
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
