// Choosing a region of a user's shape (issue 15): the shape's points drawn in a small three.js
// view; a click on a point makes it the centre of a ball (the brush), whose radius the caller
// sets; points inside the ball are drawn highlighted. Orbit with drag, zoom with the wheel.

import * as THREE from 'three';
import { OrbitControls } from 'three/examples/jsm/controls/OrbitControls.js';

const OUTSIDE = new THREE.Color(0x8c96a3);
const INSIDE = new THREE.Color(0xe67e22);

export class RegionPicker {
  /** @param {{onPick: (centre: number[]) => void}} options  called when a click picks a point */
  constructor({ onPick }) {
    this.onPick = onPick;
    this.element = document.createElement('div');
    this.element.className = 'region-picker';
    this.element.dataset.testid = 'region-view';
    this.canvas = document.createElement('canvas');
    this.element.appendChild(this.canvas);
    this.renderer = new THREE.WebGLRenderer({ canvas: this.canvas, antialias: true });
    this.renderer.setClearColor(0xf6f7f9);
    this.scene = new THREE.Scene();
    this.camera = new THREE.PerspectiveCamera(35, 1, 0.001, 1000);
    this.controls = new OrbitControls(this.camera, this.canvas);
    this.controls.addEventListener('change', () => this.render());
    this.centre = null;
    this.radius = 0;
    this.points = null;
    this.ball = new THREE.Mesh(new THREE.SphereGeometry(1, 32, 16),
      new THREE.MeshBasicMaterial({ color: INSIDE, wireframe: true, transparent: true, opacity: 0.18 }));
    this.ball.visible = false;
    this.scene.add(this.ball);
    // A click (not a drag) picks the nearest point under the pointer.
    let down = null;
    this.canvas.addEventListener('pointerdown', (e) => { down = [e.clientX, e.clientY]; });
    this.canvas.addEventListener('pointerup', (e) => {
      if (!down || Math.hypot(e.clientX - down[0], e.clientY - down[1]) > 4) return;
      down = null;
      this._pick(e);
    });
    this._resize = () => this.resize();
    window.addEventListener('resize', this._resize);
  }

  /** Draws a preview answer of POST /api/references and frames it. */
  show(preview) {
    if (this.points) {
      this.scene.remove(this.points);
      this.points.geometry.dispose();
    }
    const geometry = new THREE.BufferGeometry();
    const positions = new Float32Array(preview.positions);
    geometry.setAttribute('position', new THREE.BufferAttribute(positions, 3));
    geometry.setAttribute('color', new THREE.BufferAttribute(new Float32Array(positions.length), 3));
    this.diagonal = preview.diagonal || 1;
    const size = this.diagonal;
    this.points = new THREE.Points(geometry, new THREE.PointsMaterial({ size: size / 250, vertexColors: true }));
    this.scene.add(this.points);
    const [lo, hi] = preview.bounding_box;
    const centre = new THREE.Vector3((lo[0] + hi[0]) / 2, (lo[1] + hi[1]) / 2, (lo[2] + hi[2]) / 2);
    this.camera.near = size / 1000;
    this.camera.far = size * 100;
    this.camera.position.copy(centre).add(new THREE.Vector3(0.4, 0.5, 1.2).normalize().multiplyScalar(size * 1.15));
    this.controls.target.copy(centre);
    this.controls.update();
    this.centre = null;
    this.ball.visible = false;
    this.resize();
    this._colour();
  }

  /** Sets the region's centre ([x, y, z] or null) and radius (shape units). */
  setRegion(centre, radius) {
    this.centre = centre ? new THREE.Vector3(...centre) : null;
    this.radius = radius;
    this.ball.visible = !!this.centre && radius > 0;
    if (this.ball.visible) {
      this.ball.position.copy(this.centre);
      this.ball.scale.setScalar(radius);
    }
    this._colour();
  }

  /** Points of the preview inside the current ball. */
  insideCount() {
    return this._inside;
  }

  resize() {
    const width = this.element.clientWidth || 480, height = this.element.clientHeight || 320;
    this.renderer.setPixelRatio(window.devicePixelRatio || 1);
    this.renderer.setSize(width, height, false);
    this.camera.aspect = width / height;
    this.camera.updateProjectionMatrix();
    this.render();
  }

  render() {
    this.renderer.render(this.scene, this.camera);
  }

  dispose() {
    window.removeEventListener('resize', this._resize);
    this.controls.dispose();
    this.renderer.dispose();
  }

  _colour() {
    this._inside = 0;
    if (!this.points) return this.render();
    const p = this.points.geometry.getAttribute('position');
    const c = this.points.geometry.getAttribute('color');
    const r2 = this.radius * this.radius;
    for (let i = 0; i < p.count; ++i) {
      const inside = this.centre && this.radius > 0
        && (p.getX(i) - this.centre.x) ** 2 + (p.getY(i) - this.centre.y) ** 2 + (p.getZ(i) - this.centre.z) ** 2 <= r2;
      if (inside) this._inside += 1;
      const colour = inside ? INSIDE : OUTSIDE;
      c.setXYZ(i, colour.r, colour.g, colour.b);
    }
    c.needsUpdate = true;
    this.render();
  }

  _pick(event) {
    if (!this.points) return;
    const rect = this.canvas.getBoundingClientRect();
    const ndc = new THREE.Vector2(((event.clientX - rect.left) / rect.width) * 2 - 1, -((event.clientY - rect.top) / rect.height) * 2 + 1);
    const raycaster = new THREE.Raycaster();
    raycaster.params.Points.threshold = this.diagonal / 150;
    raycaster.setFromCamera(ndc, this.camera);
    const hits = raycaster.intersectObject(this.points);
    if (!hits.length) return;
    const nearest = hits[0];  // sorted by distance from the camera: the front of the shape
    const p = this.points.geometry.getAttribute('position');
    this.onPick([p.getX(nearest.index), p.getY(nearest.index), p.getZ(nearest.index)]);
  }
}
