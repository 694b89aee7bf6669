// Coverage over the scans: per scan the scanned area as stacked bars, scan-completed C and
// low-resolution M (m², left axis, the paper's Fig. 4/5 colours), and the unscanned share U of the
// target region as a line (%, right axis). Data: `areas` of GET /api/v1/scans (the areas right
// after each scan joined the map) and map_updated events.

const COLORS = { C: '#fad6b4', M: '#ecd040', U: '#9aa4b2', grid: '#2c323c', text: '#8a94a3' };
const nf0 = new Intl.NumberFormat('en-US', { maximumFractionDigits: 0 });

export class CoverageChart {
  /** @param {HTMLCanvasElement} canvas @param {HTMLElement} readout */
  constructor(canvas, readout) {
    this.canvas = canvas;
    this.readout = readout;
    this.points = new Map(); // scan id -> {completed_m2, low_resolution_m2, unscanned_m2, movable_m2}
    this._ro = new ResizeObserver(() => this.draw());
    this._ro.observe(canvas);
  }

  /** Areas after scan `id` (either source); the newest value wins. */
  set(id, areas) {
    if (!areas || !Number.isFinite(areas.completed_m2)) return;
    this.points.set(id, areas);
    this.draw();
  }

  clear() {
    this.points.clear();
    this.draw();
  }

  get count() {
    return this.points.size;
  }

  draw() {
    const c = this.canvas;
    const dpr = Math.min(window.devicePixelRatio || 1, 2);
    const w = Math.max(1, c.clientWidth);
    const h = Math.max(1, c.clientHeight);
    if (c.width !== Math.round(w * dpr) || c.height !== Math.round(h * dpr)) {
      c.width = Math.round(w * dpr);
      c.height = Math.round(h * dpr);
    }
    const ctx = c.getContext('2d');
    ctx.setTransform(dpr, 0, 0, dpr, 0, 0);
    ctx.clearRect(0, 0, w, h);
    const ids = [...this.points.keys()].sort((a, b) => a - b);
    c.dataset.points = String(ids.length);
    ctx.font = '10px system-ui, sans-serif';
    if (!ids.length) {
      ctx.fillStyle = COLORS.text;
      ctx.textAlign = 'center';
      ctx.textBaseline = 'middle';
      ctx.fillText('coverage appears after the first scan', w / 2, h / 2);
      this.readout.textContent = '';
      return;
    }
    const L = 40, R = 30, T = 14, B = 16;
    const pw = w - L - R;
    const ph = h - T - B;
    const data = ids.map((id) => this.points.get(id));
    const maxScanned = Math.max(1, ...data.map((a) => a.completed_m2 + a.low_resolution_m2));
    const step = niceStep(maxScanned / 3);
    const top = Math.ceil(maxScanned / step) * step;

    // Grid and the left axis (m² scanned).
    ctx.strokeStyle = COLORS.grid;
    ctx.fillStyle = COLORS.text;
    ctx.lineWidth = 1;
    ctx.textAlign = 'right';
    ctx.textBaseline = 'middle';
    for (let v = 0; v <= top + 1e-9; v += step) {
      const y = T + ph - (v / top) * ph;
      ctx.beginPath();
      ctx.moveTo(L, Math.round(y) + 0.5);
      ctx.lineTo(L + pw, Math.round(y) + 0.5);
      ctx.stroke();
      ctx.fillText(compact(v), L - 4, y);
    }
    ctx.textAlign = 'left';
    for (const p of [0, 50, 100]) ctx.fillText(`${p}%`, L + pw + 4, T + ph - (p / 100) * ph);
    // The axes' units: scanned area (m²) left, unscanned share right, scans along the bottom.
    ctx.textBaseline = 'top';
    ctx.fillText('m² scanned', 2, 0);
    ctx.textAlign = 'right';
    ctx.fillText('U %', w - 2, 0);
    ctx.textBaseline = 'top';
    ctx.fillText('scan', L - 4, T + ph + 3);

    // Bars: C below, M on top.
    const slot = pw / ids.length;
    const bw = Math.max(2, Math.min(28, slot * 0.7));
    ctx.textAlign = 'center';
    ctx.textBaseline = 'top';
    const labelEvery = Math.ceil(ids.length / Math.max(1, Math.floor(pw / 22)));
    data.forEach((a, i) => {
      const x = L + slot * (i + 0.5);
      const hc = (a.completed_m2 / top) * ph;
      const hm = (a.low_resolution_m2 / top) * ph;
      ctx.fillStyle = COLORS.C;
      ctx.fillRect(x - bw / 2, T + ph - hc, bw, hc);
      ctx.fillStyle = COLORS.M;
      ctx.fillRect(x - bw / 2, T + ph - hc - hm, bw, hm);
      if (i % labelEvery === 0 || i === ids.length - 1) {
        ctx.fillStyle = COLORS.text;
        ctx.fillText(String(ids[i]), x, T + ph + 3);
      }
    });

    // U as a share of the target region (right axis).
    ctx.strokeStyle = COLORS.U;
    ctx.fillStyle = COLORS.U;
    ctx.lineWidth = 1.5;
    ctx.beginPath();
    data.forEach((a, i) => {
      const total = a.completed_m2 + a.low_resolution_m2 + a.unscanned_m2;
      const share = total > 0 ? a.unscanned_m2 / total : 0;
      const x = L + slot * (i + 0.5);
      const y = T + ph - share * ph;
      if (i === 0) ctx.moveTo(x, y);
      else ctx.lineTo(x, y);
    });
    ctx.stroke();
    data.forEach((a, i) => {
      const total = a.completed_m2 + a.low_resolution_m2 + a.unscanned_m2;
      const share = total > 0 ? a.unscanned_m2 / total : 0;
      ctx.beginPath();
      ctx.arc(L + slot * (i + 0.5), T + ph - share * ph, 2.5, 0, Math.PI * 2);
      ctx.fill();
    });

    const last = data[data.length - 1];
    const total = last.completed_m2 + last.low_resolution_m2 + last.unscanned_m2;
    const pct = total > 0 ? ((100 * last.completed_m2) / total).toFixed(1) : '0';
    this.readout.textContent = `after scan ${ids[ids.length - 1]}: scanned ${nf0.format(last.completed_m2 + last.low_resolution_m2)} m² ` +
      `(C ${nf0.format(last.completed_m2)}, M ${nf0.format(last.low_resolution_m2)}), U ${nf0.format(last.unscanned_m2)} m², ` +
      `C ${pct} % of the target, movable ${nf0.format(last.movable_m2)} m²`;
  }
}

function niceStep(raw) {
  const pow = 10 ** Math.floor(Math.log10(Math.max(raw, 1e-9)));
  for (const k of [1, 2, 2.5, 5, 10]) if (k * pow >= raw) return k * pow;
  return 10 * pow;
}

function compact(v) {
  if (v >= 1e6) return `${+(v / 1e6).toFixed(1)}M`;
  if (v >= 1e3) return `${+(v / 1e3).toFixed(1)}k`;
  return String(Math.round(v));
}
