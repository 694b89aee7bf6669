// Measure tool: the distance between two points picked on the map in the 3-D view (the drawn point
// nearest the camera under the cursor). A third click starts a new measurement; Esc clears it.
import { BufferGeometry, Group, Line, LineBasicMaterial, Mesh, MeshBasicMaterial, SphereGeometry, Vector3 } from 'three';
import { CSS2DObject } from 'three/addons/renderers/CSS2DRenderer.js';

const COLOR = 0xffe066;

export function formatDistance(a, b) {
  const d = a.distanceTo(b);
  const h = Math.hypot(b.x - a.x, b.y - a.y);
  const v = b.z - a.z;
  return { d, h, v, text: `${d.toFixed(2)} m (horizontal ${h.toFixed(2)} m, height ${v >= 0 ? '+' : '−'}${Math.abs(v).toFixed(2)} m)` };
}

export class MeasureTool {
  /**
   * @param {import('./view.js').MapView} view
   * @param {(text: string) => void} onStatus  what to tell the operator
   */
  constructor(view, onStatus) {
    this.view = view;
    this.onStatus = onStatus;
    this.group = new Group();
    this.group.name = 'measure';
    view.overlay.add(this.group);
    this.dotGeo = new SphereGeometry(0.12, 12, 8);
    this.dotMat = new MeshBasicMaterial({ color: COLOR, depthTest: false, transparent: true });
    this.lineMat = new LineBasicMaterial({ color: COLOR, depthTest: false, transparent: true });
    this.points = [];
    this.line = null;
    this.result = null; // the last measurement {d, h, v, text}
  }

  /** A click in the view while the tool is active. */
  handleClick(event) {
    const hit = this.view.pick(event.clientX, event.clientY);
    if (!hit) {
      this.onStatus('measure: no map point under the cursor; click on the points');
      return;
    }
    if (this.points.length >= 2) this.clear();
    this.points.push(hit.point);
    const dot = new Mesh(this.dotGeo, this.dotMat);
    dot.renderOrder = 11;
    dot.position.copy(hit.point);
    this.group.add(dot);
    if (this.points.length === 1) {
      this.onStatus(`measure: from (${fmt(hit.point)}); now click the second point`);
    } else {
      const [a, b] = this.points;
      this.result = formatDistance(a, b);
      this.line = new Line(new BufferGeometry().setFromPoints([a, b]), this.lineMat);
      this.line.renderOrder = 11;
      this.group.add(this.line);
      const el = document.createElement('div');
      el.className = 'marker-label measure-label';
      el.textContent = `${this.result.d.toFixed(2)} m`;
      const l = new CSS2DObject(el);
      l.position.copy(new Vector3().addVectors(a, b).multiplyScalar(0.5));
      this.group.add(l);
      this.onStatus(`measure: ${this.result.text}`);
    }
    this.view.requestRender();
  }

  clear() {
    for (const child of [...this.group.children]) this.group.remove(child);
    if (this.line) this.line.geometry.dispose();
    this.line = null;
    this.points = [];
    this.result = null;
    this.view.requestRender();
  }

  dispose() {
    this.clear();
    this.view.overlay.remove(this.group);
    this.dotGeo.dispose();
    this.dotMat.dispose();
    this.lineMat.dispose();
  }
}

function fmt(p) {
  return `${p.x.toFixed(1)}, ${p.y.toFixed(1)}, ${p.z.toFixed(1)}`;
}
