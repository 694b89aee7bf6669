// The operator's area on the top view (issue 18, part 1): the target area the planner covers and
// the no-go zones no candidate or drive may enter, drawn as polygons and saved with
// PUT /api/v1/params {target, no_go, by}. Outside editing the saved shapes are only drawn. While
// editing, a click adds a corner to the shape being drawn (clicking its first corner, or the
// last one again, closes it), a corner of a finished shape can be dragged, and nothing reaches
// the server until Save; Cancel forgets the draft. The server checks the shapes again (corners,
// size) and its refusal is shown as it words it.
import { getJson, sendJson } from './api.js';
import { operatorName } from './dialog.js';

const CLOSE_PX = 12; // a click this close to the first corner closes the shape
const HANDLE_PX = 10; // a corner this close to the pointer can be dragged
const nf1 = new Intl.NumberFormat('en-US', { maximumFractionDigits: 1 });
const clone = (poly) => poly.map(([x, y]) => [x, y]);

/** Signed area (m²) of a polygon, counter-clockwise positive. */
export function polygonArea(poly) {
  let a = 0;
  for (let i = 0; i < poly.length; i++) {
    const [x0, y0] = poly[i];
    const [x1, y1] = poly[(i + 1) % poly.length];
    a += x0 * y1 - x1 * y0;
  }
  return a / 2;
}

function segmentsCross(a, b, c, d) {
  const orient = (p, q, r) => Math.sign((q[0] - p[0]) * (r[1] - p[1]) - (q[1] - p[1]) * (r[0] - p[0]));
  return orient(a, b, c) * orient(a, b, d) < 0 && orient(c, d, a) * orient(c, d, b) < 0;
}

/** Why `poly` cannot be an area or a zone, or '' when it can. */
export function polygonProblem(poly) {
  if (poly.length < 3) return 'a shape needs at least 3 corners';
  const n = poly.length;
  for (let i = 0; i < n; i++) {
    for (let j = i + 2; j < n; j++) {
      if (i === 0 && j === n - 1) continue; // neighbours through the closing edge
      if (segmentsCross(poly[i], poly[(i + 1) % n], poly[j], poly[(j + 1) % n])) return 'its outline crosses itself';
    }
  }
  if (Math.abs(polygonArea(poly)) < 1) return 'it encloses less than 1 m²';
  return '';
}

export class AreaEditor {
  /**
   * @param {{edit: HTMLButtonElement, bar: HTMLElement, drawArea: HTMLButtonElement, addZone: HTMLButtonElement,
   *          undo: HTMLButtonElement, close: HTMLButtonElement, reset: HTMLButtonElement, save: HTMLButtonElement,
   *          cancel: HTMLButtonElement, zones: HTMLElement, msg: HTMLElement}} els
   * @param {{topView: import('./top_view.js').TopView, onEditing: (on: boolean) => void}} handlers
   */
  constructor(els, { topView, onEditing }) {
    this.els = els;
    this.topView = topView;
    this.onEditing = onEditing;
    this.saved = { target: null, no_go: [] };
    this.draft = null; // {target, no_go} while editing
    this.drawing = null; // {kind: 'area'|'zone', corners: [[x, y], …]} a shape being drawn
    this.operator = false;
    this.busy = false;
    els.edit.addEventListener('click', () => (this.draft ? this.cancel() : this.start()));
    els.drawArea.addEventListener('click', () => this.beginShape('area'));
    els.addZone.addEventListener('click', () => this.beginShape('zone'));
    els.undo.addEventListener('click', () => this.undo());
    els.close.addEventListener('click', () => this.closeShape());
    els.reset.addEventListener('click', () => this.resetArea());
    els.save.addEventListener('click', () => this.save());
    els.cancel.addEventListener('click', () => this.cancel());
    topView.setAreaEditor(this);
    this.render();
  }

  get editing() {
    return !!this.draft;
  }

  setRole(operator) {
    this.operator = operator;
    if (!operator && this.draft) this.cancel();
    this.render();
  }

  async load() {
    try {
      const p = await getJson('/api/v1/params', { timeoutMs: 15000 });
      this.saved = { target: p.target ?? null, no_go: p.no_go ?? [] };
      this.render();
    } catch (e) {
      if (!e.network) console.warn('params:', e);
    }
  }

  start() {
    if (!this.operator) return;
    this.draft = { target: this.saved.target ? clone(this.saved.target) : null, no_go: this.saved.no_go.map(clone) };
    this.drawing = null;
    this.say('Draw the area the robots should cover, or a no-go zone; drag a corner to move it.');
    this.onEditing(true);
    this.render();
  }

  cancel() {
    this.draft = null;
    this.drawing = null;
    this.say('');
    this.onEditing(false);
    this.render();
  }

  beginShape(kind) {
    if (!this.draft) return;
    this.drawing = { kind, corners: [] };
    this.say(`Click the corners of the ${kind === 'area' ? 'area' : 'no-go zone'} on the map; click the first corner (or Close shape) to finish.`);
    this.render();
  }

  /** Forgets the shape being drawn (Esc). */
  dropShape() {
    this.drawing = null;
    this.render();
  }

  undo() {
    if (this.drawing?.corners.length) this.drawing.corners.pop();
    else this.drawing = null;
    this.render();
  }

  closeShape() {
    const d = this.drawing;
    if (!d || !this.draft) return;
    const why = polygonProblem(d.corners);
    if (why) {
      this.say(`This shape cannot be used: ${why}.`, true);
      return;
    }
    if (d.kind === 'area') this.draft.target = clone(d.corners);
    else this.draft.no_go.push(clone(d.corners));
    this.drawing = null;
    this.say(`${d.kind === 'area' ? 'Area' : 'No-go zone'} of ${nf1.format(Math.abs(polygonArea(d.corners)))} m² drawn: Save to plan with it.`);
    this.render();
  }

  resetArea() {
    if (!this.draft) return;
    this.draft.target = null;
    this.drawing = null;
    this.say('The default area (200 m around the first scan) once saved.');
    this.render();
  }

  removeZone(i) {
    if (!this.draft) return;
    this.draft.no_go.splice(i, 1);
    this.render();
  }

  async save() {
    if (!this.draft || this.busy) return;
    if (this.drawing?.corners.length) {
      this.say('Close or undo the shape being drawn first.', true);
      return;
    }
    for (const [i, z] of [this.draft.target, ...this.draft.no_go].entries()) {
      const why = z ? polygonProblem(z) : '';
      if (why) {
        this.say(`${i === 0 ? 'The area' : `No-go zone ${i}`} cannot be used: ${why}.`, true);
        return;
      }
    }
    this.busy = true;
    this.say('saving: the server re-plans…');
    this.render();
    try {
      const by = operatorName();
      const p = await sendJson('/api/v1/params', { target: this.draft.target, no_go: this.draft.no_go, ...(by ? { by } : {}) }, { method: 'PUT', timeoutMs: 60000 });
      this.saved = { target: p.target ?? null, no_go: p.no_go ?? [] };
      this.busy = false;
      this.draft = null;
      this.drawing = null;
      const zones = this.saved.no_go.length;
      const areaText = this.saved.target ? `an area of ${nf1.format(Math.abs(polygonArea(this.saved.target)))} m²` : 'the default area';
      this.say(`Saved: ${areaText}${zones ? `, ${zones} no-go zone${zones > 1 ? 's' : ''}` : ''}; new candidates follow.`);
      this.onEditing(false);
    } catch (e) {
      this.busy = false;
      this.say(`not saved: ${e.detail || e.message}`, true);
    }
    this.render();
  }

  say(text, error = false) {
    this.els.msg.textContent = text;
    this.els.msg.classList.toggle('error', error);
  }

  // ---------------------------------------------------------------- called by the top view
  /** What the top view draws: the saved shapes, or the draft and the shape being drawn. */
  shapes() {
    const src = this.draft ?? this.saved;
    return { target: src.target, noGo: src.no_go, drawing: this.drawing, editing: !!this.draft };
  }

  /** A click at map position p while editing; true when it was used. */
  click(p) {
    if (!this.draft) return false;
    if (!this.drawing) {
      this.say('Pick "Draw area" or "Add no-go zone" first, or drag a corner.', true);
      return true;
    }
    const c = this.drawing.corners;
    const near = (q) => q && Math.hypot((q[0] - p.x) * this.topView.scale, (q[1] - p.y) * this.topView.scale) <= CLOSE_PX;
    if (c.length >= 3 && (near(c[0]) || near(c[c.length - 1]))) {
      this.closeShape();
      return true;
    }
    c.push([p.x, p.y]);
    this.render();
    return true;
  }

  /** The corner of a finished draft shape under screen point (px, py): a handle to drag. */
  handleAt(px, py) {
    if (!this.draft) return null;
    const shapes = [this.draft.target, ...this.draft.no_go];
    for (let s = 0; s < shapes.length; s++) {
      const poly = shapes[s];
      if (!poly) continue;
      for (let i = 0; i < poly.length; i++) {
        const q = this.topView.screenOf(poly[i][0], poly[i][1]);
        if (Math.hypot(q.x - px, q.y - py) <= HANDLE_PX) return { poly, i };
      }
    }
    return null;
  }

  moveHandle(h, p) {
    h.poly[h.i] = [p.x, p.y];
    this.topView.redraw();
  }

  render() {
    const e = this.els;
    const editing = !!this.draft;
    e.edit.hidden = !this.operator;
    e.edit.setAttribute('aria-pressed', String(editing));
    e.bar.hidden = !editing && !e.msg.textContent;
    for (const b of [e.drawArea, e.addZone, e.undo, e.close, e.reset, e.save, e.cancel]) b.hidden = !editing;
    e.drawArea.setAttribute('aria-pressed', String(this.drawing?.kind === 'area'));
    e.addZone.setAttribute('aria-pressed', String(this.drawing?.kind === 'zone'));
    e.undo.disabled = !this.drawing;
    e.close.disabled = !this.drawing || this.drawing.corners.length < 3;
    e.reset.disabled = !editing || !this.draft.target;
    e.save.disabled = this.busy;
    e.zones.replaceChildren();
    if (editing) {
      this.draft.no_go.forEach((z, i) => {
        const b = document.createElement('button');
        b.type = 'button';
        b.className = 'zone-chip';
        b.textContent = `no-go ${i + 1} · ${nf1.format(Math.abs(polygonArea(z)))} m² ✕`;
        b.title = 'remove this no-go zone (once saved)';
        b.addEventListener('click', () => this.removeZone(i));
        e.zones.append(b);
      });
    }
    document.body.dataset.areaEditing = String(editing);
    this.topView.redraw();
  }
}
