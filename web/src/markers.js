// What is drawn over the points in the 3-D view: scan positions, the planner's candidates (rank and
// F), the robot, the approved path and annotations. Drawn without depth test so buildings never hide
// them; labels are HTML (CSS2DRenderer), decluttered after each render: where two overlap on
// screen the more important one stays (the selected candidate, robots, annotations, then the
// candidates by rank, then scans), so labels never pile up into an unreadable heap. Shared
// geometries and materials are made once and disposed with the markers; groups are rebuilt when
// their data changes.
import {
  BoxGeometry,
  BufferGeometry,
  ConeGeometry,
  CylinderGeometry,
  Group,
  Line,
  LineBasicMaterial,
  Mesh,
  MeshBasicMaterial,
  SphereGeometry,
  Vector3,
} from 'three';
import { CSS2DObject } from 'three/addons/renderers/CSS2DRenderer.js';
import { robotColor, robotColorInt } from './robot_colors.js';
import { scanColor } from './view.js';

export const STATE_COLORS = {
  proposed: 0xf0b429,
  moving: 0x3fb950,
  reached: 0x3fb950,
  rejected: 0x6e7681,
  refused: 0xf85149,
  interrupted: 0xff7b29,
  cancelled: 0x6e7681,
  superseded: 0x6e7681,
};
export const SELECTED_COLOR = 0x39c5f3;
export const ANNOTATION_COLORS = { victim: 0xff4d6d, hazard: 0xff9f1c, blocked: 0xb388ff, note: 0x4dabf7 };
const OVERLAY_ORDER = 10;
// Which label stays where two overlap (higher wins).
const PRIORITY = { selected: 100, robot: 90, annotation: 80, custom: 60, candidate: 50, scan: 10 };

function label(text, className, priority) {
  const el = document.createElement('div');
  el.className = `marker-label ${className}`;
  el.textContent = text;
  el.dataset.priority = String(priority);
  return new CSS2DObject(el);
}

function overlay(obj) {
  obj.renderOrder = OVERLAY_ORDER;
  obj.traverse((o) => {
    o.renderOrder = OVERLAY_ORDER;
  });
  return obj;
}

export class Markers {
  /** @param {import('./view.js').MapView} view */
  constructor(view) {
    this.view = view;
    this.root = new Group();
    this.root.name = 'markers';
    view.overlay.add(this.root);
    this.groups = {};
    for (const name of ['scans', 'candidates', 'path', 'robot', 'annotations']) {
      const g = new Group();
      g.name = name;
      this.root.add(g);
      this.groups[name] = g;
    }
    this.geo = {
      disc: new CylinderGeometry(0.45, 0.45, 0.12, 24).rotateX(Math.PI / 2),
      pin: new CylinderGeometry(0.06, 0.06, 2.4, 8).rotateX(Math.PI / 2).translate(0, 0, 1.2),
      head: new SphereGeometry(0.38, 16, 12).translate(0, 0, 2.5),
      body: new BoxGeometry(0.9, 0.6, 0.45).translate(0, 0, 0.35),
      nose: new ConeGeometry(0.22, 0.5, 12).rotateZ(-Math.PI / 2).translate(0.65, 0, 0.35),
      dot: new SphereGeometry(0.3, 12, 10),
    };
    this.materials = new Map(); // colour -> material
    this.lineMaterials = [];
    this.shown = {}; // group name -> what it was last built from (see _same)
    view.afterRender = () => this.declutter();
  }

  // Whether group `name` already shows `data`: robot poses and paths are set again on every
  // status and poll, and each rebuild re-draws the whole point cloud, a large part of a second
  // on a laptop without a GPU. Nothing changed, nothing is drawn.
  _same(name, data) {
    const key = JSON.stringify(data);
    if (this.shown[name] === key) return true;
    this.shown[name] = key;
    return false;
  }

  /** Hides each label that overlaps a more important one on screen (see PRIORITY). */
  declutter() {
    const items = [];
    for (const el of this.view.labels.domElement.querySelectorAll('.marker-label')) {
      if (el.style.display === 'none') continue; // behind the camera
      items.push({ el, priority: Number(el.dataset.priority) || 0 });
    }
    items.sort((a, b) => b.priority - a.priority);
    const kept = [];
    for (const { el } of items) {
      const r = el.getBoundingClientRect();
      const covered = kept.some((k) => r.left < k.right && r.right > k.left && r.top < k.bottom && r.bottom > k.top);
      el.classList.toggle('cluttered', covered);
      if (!covered) kept.push(r);
    }
  }

  _mat(color) {
    let m = this.materials.get(color);
    if (!m) {
      m = new MeshBasicMaterial({ color, depthTest: false, transparent: true, opacity: 0.95 });
      this.materials.set(color, m);
    }
    return m;
  }

  _clear(name) {
    const g = this.groups[name];
    for (const child of [...g.children]) {
      // A label's element leaves the page only when the label itself is removed from its parent,
      // not when an ancestor is: remove nested labels one by one.
      const labels = [];
      child.traverse((o) => {
        if (o.isCSS2DObject && o !== child) labels.push(o);
      });
      for (const l of labels) l.parent.remove(l);
      g.remove(child);
      // Path lines have geometries of their own (the other groups share this.geo).
      if (name === 'path') child.geometry?.dispose();
    }
  }

  /** @param {Array<{id: number, placed: {x: number, y: number, z: number}}>} scans */
  setScans(scans) {
    if (this._same('scans', scans.map((s) => [s.id, s.placed.x, s.placed.y, s.placed.z]))) return;
    this._clear('scans');
    for (const s of scans) {
      const [r, g, b] = scanColor(s.id);
      const color = (Math.round(r * 255) << 16) | (Math.round(g * 255) << 8) | Math.round(b * 255);
      const m = overlay(new Mesh(this.geo.disc, this._mat(color)));
      m.position.set(s.placed.x, s.placed.y, s.placed.z + 0.06);
      const l = label(`S${s.id}`, 'scan-label', PRIORITY.scan);
      l.position.set(0, 0, 0.4);
      m.add(l);
      this.groups.scans.add(m);
    }
    this.view.requestRender();
  }

  /** Candidates of the current plans; `selected` is a candidate id or null. */
  setCandidates(list, selected) {
    const colors = list.map((c) => robotColor(c.robot));
    if (this._same('candidates', [list.map((c) => [c.id, c.state, c.rank, c.x, c.y, c.z, c.gain_unscanned_m2, c.gain_low_res_m2]), selected, colors])) return;
    this._clear('candidates');
    // With several robots each label says whose plan it is from.
    const several = new Set(list.map((c) => c.robot)).size > 1;
    for (const c of list) {
      if (c.state === 'superseded') continue;
      const color = c.id === selected ? SELECTED_COLOR : STATE_COLORS[c.state] ?? STATE_COLORS.proposed;
      const g = new Group();
      g.position.set(c.x, c.y, c.z);
      g.add(overlay(new Mesh(this.geo.pin, this._mat(color))));
      g.add(overlay(new Mesh(this.geo.head, this._mat(color))));
      const name = `${several ? `${c.robot} ` : ''}${c.custom ? 'custom' : `#${c.rank}`}`;
      const priority = c.id === selected ? PRIORITY.selected : c.custom ? PRIORITY.custom : PRIORITY.candidate - Math.min(c.rank || 0, 40);
      const l = label(`${name} · ≈ ${Math.round((c.gain_unscanned_m2 || 0) + (c.gain_low_res_m2 || 0)).toLocaleString('en-US')} m²`, `cand-label state-${c.state}${c.id === selected ? ' selected' : ''}`, priority);
      if (several && c.robot) l.element.style.borderLeft = `4px solid ${robotColor(c.robot)}`;
      l.position.set(0, 0, 3.1);
      g.add(l);
      g.userData.candidate = c.id;
      this.groups.candidates.add(g);
    }
    this.view.requestRender();
  }

  /**
   * The drives of approved moves, one per robot: 2-D path points lifted between the robot's height
   * and the goal's.
   * @param {Array<{path: Array<[number, number]>, z0: number, z1: number}>} drives
   */
  setPaths(drives) {
    if (this._same('path', drives)) return;
    this._clear('path');
    if (!this.lineMaterials.length) {
      this.lineMaterials.push(new LineBasicMaterial({ color: STATE_COLORS.moving, depthTest: false, transparent: true }));
    }
    for (const { path, z0 = 0, z1 = 0 } of drives) {
      if (!path || path.length < 2) continue;
      const pts = path.map(([x, y], i) => new Vector3(x, y, z0 + ((z1 - z0) * i) / (path.length - 1) + 0.2));
      this.groups.path.add(overlay(new Line(new BufferGeometry().setFromPoints(pts), this.lineMaterials[0])));
    }
    this.view.requestRender();
  }

  /** @param {Array<{id: string, pose: {x: number, y: number, z: number, yaw_deg: number}}>} robots */
  setRobots(robots) {
    if (this._same('robot', robots.map(({ id, pose }) => [id, robotColor(id), pose]))) return;
    this._clear('robot');
    for (const { id, pose } of robots) {
      if (!pose || !Number.isFinite(pose.x)) continue;
      const g = new Group();
      const color = robotColorInt(id);
      g.add(overlay(new Mesh(this.geo.body, this._mat(color))));
      g.add(overlay(new Mesh(this.geo.nose, this._mat(color))));
      const l = label(id, 'robot-label', PRIORITY.robot);
      l.element.style.borderColor = robotColor(id);
      l.position.set(0, 0, 1.1);
      g.add(l);
      g.position.set(pose.x, pose.y, pose.z || 0);
      g.rotation.z = ((pose.yaw_deg || 0) * Math.PI) / 180;
      this.groups.robot.add(g);
    }
    this.view.requestRender();
  }

  /** @param {Array<{id, kind, x, y, z, text}>} list */
  setAnnotations(list) {
    if (this._same('annotations', list.map((a) => [a.id, a.kind, a.x, a.y, a.z, a.text]))) return;
    this._clear('annotations');
    for (const a of list) {
      const color = ANNOTATION_COLORS[a.kind] ?? ANNOTATION_COLORS.note;
      const m = overlay(new Mesh(this.geo.dot, this._mat(color)));
      m.position.set(a.x, a.y, a.z);
      const text = a.text ? `${a.kind}: ${a.text}` : a.kind;
      const l = label(text.length > 40 ? `${text.slice(0, 39)}…` : text, `annot-label kind-${a.kind}`, PRIORITY.annotation);
      l.position.set(0, 0, 0.6);
      m.add(l);
      this.groups.annotations.add(m);
    }
    this.view.requestRender();
  }

  dispose() {
    if (this.view.afterRender) this.view.afterRender = null;
    this.shown = {};
    for (const name of Object.keys(this.groups)) this._clear(name);
    this.view.overlay.remove(this.root);
    for (const g of Object.values(this.geo)) g.dispose();
    for (const m of this.materials.values()) m.dispose();
    for (const m of this.lineMaterials) m.dispose();
    this.materials.clear();
  }
}
