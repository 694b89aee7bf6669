// The three.js map view: one THREE.Points per scan chunk, orbit controls, z up.
//
// Level of detail: the decoder worker shuffles every chunk, so any prefix of its points is an even
// sample of it. When the points held exceed the budget, each chunk draws the same fraction of its
// points (a draw range: nothing is re-uploaded); while the camera moves the fraction drops further
// so orbiting stays fluid, and the full budget comes back when it stops.
//
// The budget also follows the measured drawing speed (points per millisecond, from the time until
// the next animation frame after a drawn one): a laptop without a working GPU driver draws a
// million points in about 0.6 s on Chromium's software renderer, so there a frame is capped to
// what it draws in 100 ms while the camera moves (10 frames a second) and in 400 ms at rest —
// the page, the candidates the operator waits for included, never freezes for seconds behind one
// frame. At rest the rest of the budget then fills in over the frame already drawn, a slice of
// every chunk per pass (about 150 ms of drawing each, a pause twice as long after it, starting two
// seconds after the view came to rest; the drawing buffer is kept), so the full detail comes back while
// the page stays responsive and the server keeps its share of the CPU. With a GPU the cap lies far above
// the budget and changes nothing.
//
// Colour modes (one shader, chosen by a uniform): the camera's colours, height (turbo ramp over
// the map's height range) or one colour per scan.
import {
  Box3,
  BufferAttribute,
  BufferGeometry,
  Color,
  Group,
  PerspectiveCamera,
  Points,
  Raycaster,
  Scene,
  ShaderMaterial,
  Sphere,
  Vector2,
  Vector3,
  WebGLRenderer,
} from 'three';
import { OrbitControls } from 'three/addons/controls/OrbitControls.js';
import { CSS2DRenderer } from 'three/addons/renderers/CSS2DRenderer.js';

export const BACKGROUND = 0x15181d;
export const COLOR_MODES = { rgb: 0, height: 1, scan: 2 };
const INTERACTIVE_SHARE = 0.35; // of the budget, while the camera moves
const MOVING_FRAME_MS = 100; // the longest frame while the camera moves: 10 frames a second
const REST_FRAME_MS = 400; // the longest frame at rest
const MIN_CAPPED_POINTS = 100_000; // a cap never thins the map below this
const VSYNC_MS = 34; // a frame back within two display refreshes did not limit the drawing
const FILL_FRAME_MS = 150; // one pass of the fill at rest
// The fill starts after this long at rest and then rests twice as long as each pass took: on a
// software renderer drawing is CPU time, and the server on the same laptop needs it for the next
// scan (a scan comes a minute or more after the last; the fill is done long before).
const FILL_DELAY_MS = 2000;
const FILL_PAUSE = 2; // × the pass's drawing time
const NO_COLOUR = [0.72, 0.77, 0.82];

const VERTEX = /* glsl */ `
  attribute vec3 rgb;
  uniform float uSize;
  uniform float uPixelRatio;
  uniform int uMode;
  uniform bool uHasRgb;
  uniform vec2 uZRange;
  uniform vec3 uScanColor;
  varying vec3 vColor;

  // Turbo colour map, polynomial approximation (Mikhailov, Google 2019); sRGB out.
  vec3 turbo(float x) {
    const vec4 kr4 = vec4(0.13572138, 4.61539260, -42.66032258, 132.13108234);
    const vec4 kg4 = vec4(0.09140261, 2.19418839, 4.84296658, -14.18503333);
    const vec4 kb4 = vec4(0.10667330, 12.64194608, -60.58204836, 110.36276771);
    const vec2 kr2 = vec2(-152.94239396, 59.28637943);
    const vec2 kg2 = vec2(4.27729857, 2.82956604);
    const vec2 kb2 = vec2(-89.90310912, 27.34824973);
    x = clamp(x, 0.0, 1.0);
    vec4 v4 = vec4(1.0, x, x * x, x * x * x);
    vec2 v2 = v4.zw * v4.z;
    return vec3(dot(v4, kr4) + dot(v2, kr2), dot(v4, kg4) + dot(v2, kg2), dot(v4, kb4) + dot(v2, kb2));
  }

  void main() {
    gl_Position = projectionMatrix * modelViewMatrix * vec4(position, 1.0);
    gl_PointSize = uSize * uPixelRatio;
    if (uMode == 1) {
      float span = max(uZRange.y - uZRange.x, 0.01);
      vColor = turbo((position.z - uZRange.x) / span);
    } else if (uMode == 2) {
      vColor = uScanColor;
    } else {
      vColor = uHasRgb ? rgb : vec3(${NO_COLOUR.join(', ')});
    }
  }
`;

// Colours are sRGB already (the camera's bytes): written as they are, no colour-space conversion.
const FRAGMENT = /* glsl */ `
  varying vec3 vColor;
  void main() {
    gl_FragColor = vec4(vColor, 1.0);
  }
`;

/** A distinct sRGB colour per scan id (golden-angle hues). */
export function scanColor(id) {
  const h = (id * 0.618033988749895) % 1;
  const s = 0.7;
  const l = 0.58;
  const f = (n) => {
    const k = (n + h * 12) % 12;
    const a = s * Math.min(l, 1 - l);
    return l - a * Math.max(-1, Math.min(k - 3, 9 - k, 1));
  };
  return [f(0), f(8), f(4)];
}

export class MapView {
  /** @param {HTMLElement} container */
  constructor(container) {
    this.container = container;
    this.renderer = new WebGLRenderer({ antialias: false, preserveDrawingBuffer: true, powerPreference: 'high-performance' });
    this.pixelRatio = Math.min(window.devicePixelRatio || 1, 2);
    this.renderer.setPixelRatio(this.pixelRatio);
    this.renderer.setClearColor(BACKGROUND, 1);
    container.appendChild(this.renderer.domElement);
    this.renderer.domElement.id = 'map-canvas';

    this.labels = new CSS2DRenderer();
    this.labels.domElement.className = 'labels';
    container.appendChild(this.labels.domElement);

    this.scene = new Scene();
    this.scene.background = new Color(BACKGROUND);
    this.overlay = new Group(); // markers, paths, measurements: drawn over the points
    this.overlay.name = 'overlay';
    this.scene.add(this.overlay);

    this.camera = new PerspectiveCamera(45, 1, 0.05, 5000);
    this.camera.up.set(0, 0, 1); // our data is z-up; must be set before OrbitControls is made
    this.camera.position.set(-20, -20, 15);
    this.camera.lookAt(0, 0, 0);

    this.controls = new OrbitControls(this.camera, this.renderer.domElement);
    this.controls.enableDamping = true;
    this.controls.dampingFactor = 0.15;
    this.controls.screenSpacePanning = true;
    this.controls.addEventListener('change', () => this.requestRender());
    this.controls.addEventListener('start', () => this._setInteracting(true));
    this.controls.addEventListener('end', () => {
      clearTimeout(this._idleTimer);
      this._idleTimer = setTimeout(() => this._setInteracting(false), 250);
    });

    this.chunks = new Map(); // scan id -> {points, material, count}
    this.bounds = new Box3();
    this.pointSize = 2;
    this.colorMode = 'rgb';
    this.budget = 4_000_000;
    this.interacting = false;
    this.framed = false;
    this.dirty = true;
    this.drawn = 0;
    this.pointsPerMs = null; // measured drawing speed; null until a frame has been timed
    this._timing = null; // {t0, drawn} of the frame drawn last, until the next animation frame
    this._fraction = 1; // the fraction of every chunk a frame draws (_applyLod)
    this.fill = null; // {done}: at rest, the fraction drawn so far by the fill passes
    this._extended = false; // the draw ranges reach past _fraction (what the fill drew)
    this.paused = false; // at rest nothing is drawn (pause): the server needs the CPU
    this.onClick = null; // (event, pick) for tools
    this.afterRender = null; // called after each drawn frame (the markers declutter their labels)
    this.onLodChange = null;

    this._installClick();
    this._resize = () => this.resize();
    window.addEventListener('resize', this._resize);
    if (typeof ResizeObserver === 'function') {
      this._ro = new ResizeObserver(this._resize);
      this._ro.observe(container);
    }
    this.resize();
    this.renderer.setAnimationLoop(() => this._frame());
  }

  /** Points held (all chunks). */
  get pointCount() {
    let n = 0;
    for (const c of this.chunks.values()) n += c.count;
    return n;
  }

  /** Points drawn after the level of detail. */
  get drawnCount() {
    return this.drawn;
  }

  get chunkCount() {
    return this.chunks.size;
  }

  requestRender() {
    this.dirty = true;
  }

  /** Draws only while the camera moves, until resume(); what changed meanwhile is drawn then. */
  pause() {
    this.paused = true;
  }

  resume() {
    this.paused = false;
  }

  resize() {
    const w = Math.max(1, this.container.clientWidth);
    const h = Math.max(1, this.container.clientHeight);
    this.renderer.setSize(w, h, true);
    this.labels.setSize(w, h);
    this.camera.aspect = w / h;
    this.camera.updateProjectionMatrix();
    this.requestRender();
  }

  _material(id, hasRgb) {
    return new ShaderMaterial({
      vertexShader: VERTEX,
      fragmentShader: FRAGMENT,
      uniforms: {
        uSize: { value: this.pointSize },
        uPixelRatio: { value: this.pixelRatio },
        uMode: { value: COLOR_MODES[this.colorMode] },
        uHasRgb: { value: hasRgb },
        uZRange: { value: new Vector2(0, 1) },
        uScanColor: { value: new Color().fromArray(scanColor(id)) },
      },
    });
  }

  /**
   * Adds one scan's points (from the decoder worker). A chunk for an id already shown replaces it.
   * @param {{id: number, count: number, positions: Float32Array, colors: Uint8Array|null, min: number[], max: number[]}} c
   */
  addChunk(c) {
    if (this.chunks.has(c.id)) this.removeChunk(c.id);
    if (!c.count) return;
    const geometry = new BufferGeometry();
    geometry.setAttribute('position', new BufferAttribute(c.positions, 3));
    if (c.colors) geometry.setAttribute('rgb', new BufferAttribute(c.colors, 3, true));
    const box = new Box3(new Vector3(...c.min), new Vector3(...c.max));
    geometry.boundingBox = box;
    geometry.boundingSphere = box.getBoundingSphere(new Sphere());
    const material = this._material(c.id, !!c.colors);
    const points = new Points(geometry, material);
    points.name = `scan ${c.id}`;
    points.userData.scan = c.id;
    this.scene.add(points);
    this.chunks.set(c.id, { points, material, count: c.count });
    this.bounds.union(box);
    this._updateUniforms();
    this._applyLod();
    if (!this.framed) {
      this.frame();
      this.framed = true;
    } else {
      this._fitClipPlanes();
    }
    this.requestRender();
  }

  removeChunk(id) {
    const c = this.chunks.get(id);
    if (!c) return;
    this.scene.remove(c.points);
    c.points.geometry.dispose();
    c.material.dispose();
    this.chunks.delete(id);
    this._recomputeBounds();
    this._applyLod();
    this.requestRender();
  }

  clear() {
    for (const id of [...this.chunks.keys()]) this.removeChunk(id);
    this.framed = false;
  }

  _recomputeBounds() {
    this.bounds.makeEmpty();
    for (const c of this.chunks.values()) this.bounds.union(c.points.geometry.boundingBox);
  }

  setPointSize(px) {
    this.pointSize = px;
    this._updateUniforms();
  }

  setColorMode(mode) {
    if (!(mode in COLOR_MODES)) return;
    this.colorMode = mode;
    this._updateUniforms();
  }

  setBudget(points) {
    this.budget = Math.max(10_000, points);
    this._applyLod();
  }

  _updateUniforms() {
    const z0 = Number.isFinite(this.bounds.min.z) ? this.bounds.min.z : 0;
    const z1 = Number.isFinite(this.bounds.max.z) ? this.bounds.max.z : 1;
    for (const c of this.chunks.values()) {
      const u = c.material.uniforms;
      u.uSize.value = this.pointSize;
      u.uMode.value = COLOR_MODES[this.colorMode];
      u.uZRange.value.set(z0, z1);
    }
    this.requestRender();
  }

  _setInteracting(on) {
    if (this.interacting === on) return;
    this.interacting = on;
    this._applyLod();
  }

  /** The share of every chunk that is drawn. */
  get lodFraction() {
    const total = this.pointCount;
    if (!total) return 1;
    let budget = this.interacting ? this.budget * INTERACTIVE_SHARE : this.budget;
    if (this.pointsPerMs) {
      const frameMs = this.interacting ? MOVING_FRAME_MS : REST_FRAME_MS;
      budget = Math.min(budget, Math.max(MIN_CAPPED_POINTS, this.pointsPerMs * frameMs));
    }
    return Math.min(1, budget / total);
  }

  /** The share of every chunk the budget alone allows at rest: what the fill completes. */
  get budgetFraction() {
    const total = this.pointCount;
    return total ? Math.min(1, this.budget / total) : 1;
  }

  /** The drawing speed from the frame just drawn; re-applies the LOD when it moved the cap. */
  _timeFrame(now) {
    const t = this._timing;
    this._timing = null;
    if (!t || t.drawn < (t.fill ? 1 : MIN_CAPPED_POINTS)) return;
    const ms = now - t.t0;
    // Back within two refreshes: the drawing did not limit the frame, the speed is at least this.
    const rate = t.drawn / Math.max(ms, VSYNC_MS);
    if (ms <= VSYNC_MS) this.pointsPerMs = Math.max(this.pointsPerMs ?? 0, rate);
    else this.pointsPerMs = this.pointsPerMs ? 0.6 * this.pointsPerMs + 0.4 * rate : rate;
    if (t.fill) return; // a fill pass sizes the next pass, it does not restart the drawing
    const f = this.lodFraction;
    if (Math.abs(f - this._fraction) > 0.15 * this._fraction) this._applyLod();
  }

  _applyLod() {
    this._fraction = this.lodFraction;
    this._setRanges(this._fraction);
    this.requestRender();
  }

  /** Every chunk drawn from its first point up to `f` of it. */
  _setRanges(f) {
    let drawn = 0;
    for (const c of this.chunks.values()) {
      const n = f >= 1 ? c.count : Math.max(1, Math.ceil(c.count * f));
      c.points.geometry.setDrawRange(0, n);
      drawn += n;
    }
    this._extended = f > this._fraction;
    if (drawn !== this.drawn) {
      this.drawn = drawn;
      this.onLodChange?.();
    }
  }

  /** One pass of the fill at rest: the next slice of every chunk, drawn over what is there. */
  _fillPass(now) {
    const total = this.pointCount;
    const target = this.budgetFraction;
    const from = this.fill.done;
    const step = ((this.pointsPerMs ?? 0) * FILL_FRAME_MS) / Math.max(1, total);
    const to = Math.min(target, from + Math.max(step, 0.01));
    let slice = 0;
    for (const c of this.chunks.values()) {
      const a = Math.ceil(c.count * from);
      const b = to >= 1 ? c.count : Math.ceil(c.count * to);
      c.points.geometry.setDrawRange(a, Math.max(0, b - a));
      slice += Math.max(0, b - a);
    }
    this.renderer.autoClear = false;
    this.renderer.render(this.scene, this.camera);
    this.renderer.autoClear = true;
    this._timing = { t0: now, drawn: slice, fill: true };
    // What is on screen now, for picking and the counts.
    this._setRanges(to);
    this.fill = to >= target ? null : { done: to, next: now + FILL_PAUSE * FILL_FRAME_MS };
  }

  /** Puts the whole map in view, looking from the south-west and above. */
  frame() {
    if (this.bounds.isEmpty()) return;
    const box = this.bounds;
    const center = box.getCenter(new Vector3());
    const dir = new Vector3(-0.5, -0.7, 0.9).normalize(); // from the target towards the camera
    const right = new Vector3().crossVectors(this.camera.up, dir).normalize();
    const upv = new Vector3().crossVectors(dir, right);
    const tanV = Math.tan(((this.camera.fov * Math.PI) / 180) / 2) / 1.06; // 6 % margin
    const tanH = tanV * this.camera.aspect;
    // Tightest camera position (fixed orientation) that sees all eight corners of the box:
    // per image axis, |corner·axis − P·axis| ≤ (P·dir − corner·dir)·tan, solved for P.
    let lh = -Infinity, rh = -Infinity, lv = -Infinity, rv = -Infinity;
    const c = new Vector3();
    for (let i = 0; i < 8; i++) {
      c.set(i & 1 ? box.max.x : box.min.x, i & 2 ? box.max.y : box.min.y, i & 4 ? box.max.z : box.min.z);
      const d = c.dot(dir), x = c.dot(right), y = c.dot(upv);
      lh = Math.max(lh, d + x / tanH);
      rh = Math.max(rh, d - x / tanH);
      lv = Math.max(lv, d + y / tanV);
      rv = Math.max(rv, d - y / tanV);
    }
    const px = ((lh - rh) * tanH) / 2;
    const py = ((lv - rv) * tanV) / 2;
    const pd = Math.max((lh + rh) / 2, (lv + rv) / 2, center.dot(dir) + 1);
    this.camera.position.set(0, 0, 0).addScaledVector(right, px).addScaledVector(upv, py).addScaledVector(dir, pd);
    this.controls.target.set(0, 0, 0).addScaledVector(right, px).addScaledVector(upv, py).addScaledVector(dir, center.dot(dir));
    this._fitClipPlanes();
    this.controls.update();
    this.requestRender();
  }

  /** Moves the orbit centre to (x, y, z), keeping the viewing direction and distance. */
  focus(x, y, z) {
    const offset = new Vector3().subVectors(this.camera.position, this.controls.target);
    this.controls.target.set(x, y, z);
    this.camera.position.copy(this.controls.target).add(offset);
    this.controls.update();
    this.requestRender();
  }

  _fitClipPlanes() {
    if (this.bounds.isEmpty()) return;
    const r = Math.max(this.bounds.getBoundingSphere(new Sphere()).radius, 0.5);
    this.camera.near = Math.max(0.01, r / 2000);
    this.camera.far = Math.max(100, r * 50);
    this.controls.maxDistance = r * 20;
    this.camera.updateProjectionMatrix();
  }

  /**
   * The map point under a pixel of the view (client coordinates), or null: of the drawn points
   * within a few pixels of the ray, the one nearest the cursor on the surface nearest the camera.
   */
  pick(clientX, clientY, radiusPx = 6) {
    if (!this.chunks.size) return null;
    const rect = this.renderer.domElement.getBoundingClientRect();
    const ndc = new Vector2(((clientX - rect.left) / rect.width) * 2 - 1, -((clientY - rect.top) / rect.height) * 2 + 1);
    const ray = new Raycaster();
    ray.setFromCamera(ndc, this.camera);
    // World size of a pixel at the orbit centre's distance: the tolerance around the ray.
    const dist = this.camera.position.distanceTo(this.controls.target);
    const perPx = (2 * dist * Math.tan(((this.camera.fov * Math.PI) / 180) / 2)) / Math.max(1, rect.height);
    ray.params.Points = { threshold: Math.max(0.02, radiusPx * perPx) };
    const hits = ray.intersectObjects([...this.chunks.values()].map((c) => c.points), false);
    if (!hits.length) return null;
    // The front surface: hits not much farther than the nearest one. Of those, the one nearest
    // the cursor (smallest angle off the ray), not merely the nearest to the camera: at a grazing
    // angle the tolerance cone covers metres of ground.
    const front = hits[0].distance;
    const depth = 0.5 + 0.02 * front;
    let best = hits[0];
    let bestAngle = Infinity;
    for (const h of hits) {
      if (h.distance > front + depth) break; // sorted by distance
      const angle = h.distanceToRay / Math.max(h.distance, 1e-6);
      if (angle < bestAngle) {
        best = h;
        bestAngle = angle;
      }
    }
    return { point: best.point.clone(), scan: best.object.userData.scan };
  }

  _installClick() {
    const el = this.renderer.domElement;
    let down = null;
    el.addEventListener('pointerdown', (e) => {
      down = { x: e.clientX, y: e.clientY, t: performance.now(), button: e.button };
    });
    el.addEventListener('pointerup', (e) => {
      if (!down || e.button !== 0 || down.button !== 0) return;
      const moved = Math.hypot(e.clientX - down.x, e.clientY - down.y);
      const quick = performance.now() - down.t < 600;
      down = null;
      if (moved <= (e.pointerType === 'mouse' ? 4 : 10) && quick && this.onClick) this.onClick(e);
    });
  }

  _frame() {
    const now = performance.now();
    this._timeFrame(now);
    const moving = this.controls.update();
    if (this.paused && !moving && !this.interacting) return;
    if (moving || this.dirty) {
      this.dirty = false;
      // A new frame starts from the capped share; what a fill drew is drawn again by a new fill.
      if (this._extended) this._setRanges(this._fraction);
      this.renderer.render(this.scene, this.camera);
      this.labels.render(this.scene, this.camera);
      this.afterRender?.();
      this._timing = { t0: now, drawn: this.drawn };
      this.fill = !moving && !this.interacting && this._fraction < this.budgetFraction ? { done: this._fraction, next: now + FILL_DELAY_MS } : null;
    } else if (this.fill && now >= this.fill.next) {
      this._fillPass(now);
    }
  }

  dispose() {
    this.renderer.setAnimationLoop(null);
    window.removeEventListener('resize', this._resize);
    this._ro?.disconnect();
    this.clear();
    this.controls.dispose();
    this.renderer.dispose();
  }
}
