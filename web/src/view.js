// The three.js map view: one Points object for the merged map, orbit controls, z up.
import {
  Color,
  PerspectiveCamera,
  Points,
  PointsMaterial,
  Scene,
  Vector3,
  WebGLRenderer,
} from 'three';
import { OrbitControls } from 'three/addons/controls/OrbitControls.js';

export const BACKGROUND = 0x15181d;

// sRGB (0..1, k/255 steps) -> linear lookup; colours in the map are 8-bit sRGB.
const SRGB_TO_LINEAR = new Float32Array(256);
for (let i = 0; i < 256; i++) {
  const c = i / 255;
  SRGB_TO_LINEAR[i] = c <= 0.04045 ? c / 12.92 : Math.pow((c + 0.055) / 1.055, 2.4);
}

/**
 * Turns decoded Draco colours into three's linear working space in place.
 * Accepts 0..1 floats (uint8 normalized attribute) and, defensively, 0..255 floats
 * (an attribute that was not marked normalized).
 */
export function colorsToLinear(array) {
  let max = 0;
  for (let i = 0; i < array.length; i++) if (array[i] > max) max = array[i];
  const scale = max > 1.001 ? 1 : 255;
  for (let i = 0; i < array.length; i++) {
    let k = Math.round(array[i] * scale);
    k = k < 0 ? 0 : k > 255 ? 255 : k;
    array[i] = SRGB_TO_LINEAR[k];
  }
}

export class MapView {
  /** @param {HTMLElement} container */
  constructor(container) {
    this.container = container;
    this.renderer = new WebGLRenderer({ antialias: false, preserveDrawingBuffer: true, powerPreference: 'high-performance' });
    this.renderer.setPixelRatio(Math.min(window.devicePixelRatio || 1, 2));
    this.renderer.setClearColor(BACKGROUND, 1);
    container.appendChild(this.renderer.domElement);
    this.renderer.domElement.id = 'map-canvas';

    this.scene = new Scene();
    this.scene.background = new Color(BACKGROUND);

    this.camera = new PerspectiveCamera(45, 1, 0.05, 5000);
    this.camera.up.set(0, 0, 1); // our data is z-up; must be set before OrbitControls is made
    this.camera.position.set(-20, -20, 15);
    this.camera.lookAt(0, 0, 0);

    this.controls = new OrbitControls(this.camera, this.renderer.domElement);
    this.controls.enableDamping = true;
    this.controls.dampingFactor = 0.15;
    this.controls.screenSpacePanning = true;
    this.controls.addEventListener('change', () => this.requestRender());

    this.material = new PointsMaterial({ size: 2, sizeAttenuation: false, vertexColors: true });
    this.points = null;
    this.framed = false;
    this.dirty = true;

    this._resize = () => this.resize();
    window.addEventListener('resize', this._resize);
    if (typeof ResizeObserver === 'function') {
      this._ro = new ResizeObserver(this._resize);
      this._ro.observe(container);
    }
    this.resize();
    this.renderer.setAnimationLoop(() => this._frame());
  }

  get pointCount() {
    return this.points ? this.points.geometry.getAttribute('position').count : 0;
  }

  requestRender() {
    this.dirty = true;
  }

  resize() {
    const w = Math.max(1, this.container.clientWidth);
    const h = Math.max(1, this.container.clientHeight);
    this.renderer.setSize(w, h, true);
    this.camera.aspect = w / h;
    this.camera.updateProjectionMatrix();
    this.requestRender();
  }

  setPointSize(px) {
    this.material.size = px;
    this.material.needsUpdate = true;
    this.requestRender();
  }

  /**
   * Replaces the rendered map. `geometry` may be null (no scans yet).
   * The old geometry is disposed; the shared material is kept (its vertexColors may change).
   */
  setMap(geometry) {
    if (this.points) {
      this.scene.remove(this.points);
      this.points.geometry.dispose();
      this.points = null;
    }
    if (geometry && geometry.getAttribute('position') && geometry.getAttribute('position').count > 0) {
      const hasColor = !!geometry.getAttribute('color');
      if (this.material.vertexColors !== hasColor) {
        this.material.vertexColors = hasColor;
        this.material.color.set(hasColor ? 0xffffff : 0xb8c4d0);
        this.material.needsUpdate = true;
      }
      geometry.computeBoundingBox();
      geometry.computeBoundingSphere();
      this.points = new Points(geometry, this.material);
      this.points.frustumCulled = false;
      this.scene.add(this.points);
      if (!this.framed) {
        this.frame();
        this.framed = true;
      } else {
        this._fitClipPlanes();
      }
    } else if (geometry) {
      geometry.dispose();
    }
    this.requestRender();
  }

  /** Puts the whole map in view, looking from the south-west and above. */
  frame() {
    if (!this.points) return;
    const geom = this.points.geometry;
    if (!geom.boundingBox) geom.computeBoundingBox();
    const box = geom.boundingBox;
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

  _fitClipPlanes() {
    const sphere = this.points?.geometry.boundingSphere;
    if (!sphere) return;
    const r = Math.max(sphere.radius, 0.5);
    this.camera.near = Math.max(0.01, r / 2000);
    this.camera.far = Math.max(100, r * 50);
    this.controls.maxDistance = r * 20;
    this.camera.updateProjectionMatrix();
  }

  _frame() {
    const moving = this.controls.update();
    if (moving || this.dirty) {
      this.dirty = false;
      this.renderer.render(this.scene, this.camera);
    }
  }

  dispose() {
    this.renderer.setAnimationLoop(null);
    window.removeEventListener('resize', this._resize);
    this._ro?.disconnect();
    this.setMap(null);
    this.material.dispose();
    this.controls.dispose();
    this.renderer.dispose();
  }
}
