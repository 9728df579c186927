// Choosing a region of a user's shape (issue 15): the shape's points drawn in a small three.js
// view, and three tools to mark the region —
//   ball   a click on a point makes it the centre of a ball whose radius the caller sets;
//   brush  dragging paints: every point within the brush radius (a ball, in the shape's units) of
//          the point under the pointer joins the region, Shift-drag erases;
//   lasso  dragging draws a loop: the points inside it that face the viewer join the region,
//          Shift-lasso removes them.
// Points in the region are drawn highlighted. With the ball, drag orbits; with brush and lasso the
// left button marks and the right button orbits. The wheel zooms.

import * as THREE from 'three';
import { OrbitControls } from 'three/examples/jsm/controls/OrbitControls.js';

const OUTSIDE = new THREE.Color(0x8c96a3);
const INSIDE = new THREE.Color(0xe67e22);
const TOOLS = ['ball', 'brush', 'lasso'];

/**
 * Whether (x, y) lies inside the closed polygon `loop` ([[x, y], …], even–odd rule).
 * @param {number[][]} loop
 */
export function insidePolygon(loop, x, y) {
  let inside = false;
  for (let i = 0, j = loop.length - 1; i < loop.length; j = i++) {
    const [xi, yi] = loop[i], [xj, yj] = loop[j];
    if ((yi > y) !== (yj > y) && x < ((xj - xi) * (y - yi)) / (yj - yi) + xi) inside = !inside;
  }
  return inside;
}

/**
 * Which points are seen from the camera, from a coarse z-buffer of the points themselves, so a
 * lasso drawn over the front of a shape does not take the back with it: a point is seen when its
 * depth is within `tolerance` of the nearest in its screen cell and within `separation` of the
 * nearest in the cells around it (where the front has no point in a cell, a point of the back
 * would otherwise be the nearest there; a surface seen at a grazing angle changes depth fast
 * from cell to cell, hence the larger bound).
 * @param {Float32Array} ndc    per point x, y in normalized device coordinates and view depth, 3 × n
 * @param {number} width        canvas width in pixels
 * @param {number} height       canvas height in pixels
 * @param {number} tolerance    depth (shape units) within which a point counts as its cell's front
 * @param {number} separation   depth behind the neighbouring cells' front beyond which a point is
 *                              on another sheet (the far side of the shape)
 * @param {number} cellPixels   cell size
 * @returns {Uint8Array} 1 for a visible point
 */
export function visiblePoints(ndc, width, height, tolerance, separation = 5 * tolerance, cellPixels = 6) {
  const n = ndc.length / 3;
  const columns = Math.max(1, Math.ceil(width / cellPixels)), rows = Math.max(1, Math.ceil(height / cellPixels));
  const nearest = new Float32Array(columns * rows).fill(Infinity);
  const cellOf = new Int32Array(n).fill(-1);
  for (let i = 0; i < n; ++i) {
    const x = ndc[3 * i], y = ndc[3 * i + 1], depth = ndc[3 * i + 2];
    if (!(depth > 0) || x < -1 || x > 1 || y < -1 || y > 1) continue;
    const c = Math.min(columns - 1, Math.floor(((x + 1) / 2) * columns));
    const r = Math.min(rows - 1, Math.floor(((1 - y) / 2) * rows));
    cellOf[i] = r * columns + c;
    if (depth < nearest[cellOf[i]]) nearest[cellOf[i]] = depth;
  }
  const visible = new Uint8Array(n);
  for (let i = 0; i < n; ++i) {
    if (cellOf[i] < 0) continue;
    const c = cellOf[i] % columns, r = Math.floor(cellOf[i] / columns);
    let front = Infinity;
    for (let dr = -1; dr <= 1; ++dr)
      for (let dc = -1; dc <= 1; ++dc) {
        const rr = r + dr, cc = c + dc;
        if (rr >= 0 && rr < rows && cc >= 0 && cc < columns) front = Math.min(front, nearest[rr * columns + cc]);
      }
    const depth = ndc[3 * i + 2];
    visible[i] = depth <= nearest[cellOf[i]] + tolerance && depth <= front + separation ? 1 : 0;
  }
  return visible;
}

export class RegionPicker {
  /**
   * @param {{onPick: (centre: number[]) => void, onSelection?: (count: number) => void}} options
   *   onPick: a click with the ball picked a point; onSelection: the painted/lassoed region changed
   */
  constructor({ onPick, onSelection = () => {} }) {
    this.onPick = onPick;
    this.onSelection = onSelection;
    this.element = document.createElement('div');
    this.element.className = 'region-picker';
    this.element.dataset.testid = 'region-view';
    this.canvas = document.createElement('canvas');
    this.element.appendChild(this.canvas);
    // The lasso's loop, drawn over the canvas while it is dragged.
    this.overlay = document.createElementNS('http://www.w3.org/2000/svg', 'svg');
    this.overlay.setAttribute('class', 'region-lasso');
    this.loopLine = document.createElementNS('http://www.w3.org/2000/svg', 'polyline');
    this.overlay.appendChild(this.loopLine);
    this.element.appendChild(this.overlay);
    this.renderer = new THREE.WebGLRenderer({ canvas: this.canvas, antialias: true });
    this.renderer.setClearColor(0xf6f7f9);
    this.scene = new THREE.Scene();
    this.camera = new THREE.PerspectiveCamera(35, 1, 0.001, 1000);
    this.controls = new OrbitControls(this.camera, this.canvas);
    this.controls.addEventListener('change', () => this.render());
    this.tool = 'ball';
    this.centre = null;
    this.radius = 0;
    this.points = null;
    this.selected = new Uint8Array(0);
    this.ball = new THREE.Mesh(new THREE.SphereGeometry(1, 32, 16),
      new THREE.MeshBasicMaterial({ color: INSIDE, wireframe: true, transparent: true, opacity: 0.18 }));
    this.ball.visible = false;
    this.scene.add(this.ball);

    let down = null;      // ball: where the button went down (a click, not a drag, picks)
    let stroke = null;    // brush/lasso: {erase, loop: [[x, y] px…]}
    this.canvas.addEventListener('contextmenu', (e) => { if (this.tool !== 'ball') e.preventDefault(); });
    this.canvas.addEventListener('pointerdown', (e) => {
      down = [e.clientX, e.clientY];
      if (this.tool === 'ball' || e.button !== 0 || !this.points) return;
      stroke = { erase: e.shiftKey, loop: [this._pixel(e)] };
      this.canvas.setPointerCapture(e.pointerId);
      if (this.tool === 'brush') this._paint(e, stroke.erase);
      else this._drawLoop(stroke.loop);
    });
    this.canvas.addEventListener('pointermove', (e) => {
      if (!stroke) return;
      if (this.tool === 'brush') this._paint(e, stroke.erase);
      else {
        stroke.loop.push(this._pixel(e));
        this._drawLoop(stroke.loop);
      }
    });
    this.canvas.addEventListener('pointerup', (e) => {
      if (stroke) {
        if (this.tool === 'lasso') this._lasso(stroke.loop, stroke.erase);
        stroke = null;
        this._drawLoop([]);
        return;
      }
      if (this.tool !== 'ball' || !down || Math.hypot(e.clientX - down[0], e.clientY - down[1]) > 4) return;
      down = null;
      const index = this._pointUnder(e);
      if (index >= 0) {
        const p = this.points.geometry.getAttribute('position');
        this.onPick([p.getX(index), p.getY(index), p.getZ(index)]);
      }
    });
    this._resize = () => this.resize();
    window.addEventListener('resize', this._resize);
  }

  /** Draws a preview answer of POST /api/references and frames it; the region is emptied. */
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
    this.selected = new Uint8Array(positions.length / 3);
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
    this.onSelection(0);
  }

  /** 'ball' (click a centre), 'brush' (paint) or 'lasso' (draw around). */
  setTool(tool) {
    if (!TOOLS.includes(tool)) throw new TypeError(`tool: expected one of ${TOOLS.join(', ')}`);
    this.tool = tool;
    // Brush and lasso take the left button; the right one orbits.
    this.controls.mouseButtons = tool === 'ball'
      ? { LEFT: THREE.MOUSE.ROTATE, MIDDLE: THREE.MOUSE.DOLLY, RIGHT: THREE.MOUSE.PAN }
      : { LEFT: null, MIDDLE: THREE.MOUSE.DOLLY, RIGHT: THREE.MOUSE.ROTATE };
    this.element.dataset.tool = tool;
    this.ball.visible = tool === 'ball' && !!this.centre && this.radius > 0;
    this._colour();
  }

  /** Sets the ball's centre ([x, y, z] or null) and the ball's or brush's radius (shape units). */
  setRegion(centre, radius) {
    this.centre = centre ? new THREE.Vector3(...centre) : null;
    this.radius = radius;
    this.ball.visible = this.tool === 'ball' && !!this.centre && radius > 0;
    if (this.ball.visible) {
      this.ball.position.copy(this.centre);
      this.ball.scale.setScalar(radius);
    }
    this._colour();
  }

  /** Points of the preview in the region (the ball's, or the painted/lassoed one). */
  insideCount() {
    return this._inside;
  }

  /** Empties the painted/lassoed region. */
  clearSelection() {
    this.selected.fill(0);
    this._colour();
    this.onSelection(0);
  }

  /** The painted/lassoed region's points, n × 3 flattened (shape units). */
  selectedPositions() {
    const out = [];
    if (!this.points) return out;
    const p = this.points.geometry.getAttribute('position');
    for (let i = 0; i < this.selected.length; ++i)
      if (this.selected[i]) out.push(p.getX(i), p.getY(i), p.getZ(i));
    return out;
  }

  /** Marks with a lasso: `loop` in canvas pixels ([[x, y], …]); `erase` removes instead. */
  lasso(loop, erase = false) {
    this._lasso(loop, erase);
  }

  resize() {
    const width = this.element.clientWidth || 480, height = this.element.clientHeight || 320;
    this.renderer.setPixelRatio(window.devicePixelRatio || 1);
    this.renderer.setSize(width, height, false);
    this.overlay.setAttribute('viewBox', `0 0 ${width} ${height}`);
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

  _pixel(event) {
    const rect = this.canvas.getBoundingClientRect();
    return [event.clientX - rect.left, event.clientY - rect.top];
  }

  _drawLoop(loop) {
    this.loopLine.setAttribute('points', loop.map(([x, y]) => `${x},${y}`).join(' '));
  }

  _colour() {
    this._inside = 0;
    if (!this.points) return this.render();
    const p = this.points.geometry.getAttribute('position');
    const c = this.points.geometry.getAttribute('color');
    const r2 = this.radius * this.radius;
    const ball = this.tool === 'ball';
    for (let i = 0; i < p.count; ++i) {
      const inside = ball
        ? this.centre && this.radius > 0
          && (p.getX(i) - this.centre.x) ** 2 + (p.getY(i) - this.centre.y) ** 2 + (p.getZ(i) - this.centre.z) ** 2 <= r2
        : this.selected[i] === 1;
      if (inside) this._inside += 1;
      const colour = inside ? INSIDE : OUTSIDE;
      c.setXYZ(i, colour.r, colour.g, colour.b);
    }
    c.needsUpdate = true;
    this.render();
  }

  /** The index of the front-most point under the pointer, or −1. */
  _pointUnder(event) {
    if (!this.points) return -1;
    const rect = this.canvas.getBoundingClientRect();
    const ndc = new THREE.Vector2(((event.clientX - rect.left) / rect.width) * 2 - 1, -((event.clientY - rect.top) / rect.height) * 2 + 1);
    const raycaster = new THREE.Raycaster();
    raycaster.params.Points.threshold = this.diagonal / 150;
    raycaster.setFromCamera(ndc, this.camera);
    const hits = raycaster.intersectObject(this.points);
    return hits.length ? hits[0].index : -1;  // sorted by distance from the camera: the front
  }

  /** Brush: the points within the radius of the point under the pointer join (or leave) the region. */
  _paint(event, erase) {
    const index = this._pointUnder(event);
    if (index < 0 || !(this.radius > 0)) return;
    const p = this.points.geometry.getAttribute('position');
    const x = p.getX(index), y = p.getY(index), z = p.getZ(index), r2 = this.radius * this.radius;
    let changed = false;
    for (let i = 0; i < p.count; ++i) {
      if ((p.getX(i) - x) ** 2 + (p.getY(i) - y) ** 2 + (p.getZ(i) - z) ** 2 > r2) continue;
      const value = erase ? 0 : 1;
      if (this.selected[i] !== value) {
        this.selected[i] = value;
        changed = true;
      }
    }
    if (changed) {
      this._colour();
      this.onSelection(this._inside);
    }
  }

  _lasso(loop, erase) {
    if (!this.points || loop.length < 3) return;
    const width = this.canvas.clientWidth || 1, height = this.canvas.clientHeight || 1;
    const p = this.points.geometry.getAttribute('position');
    const projected = new Float32Array(3 * p.count);
    const v = new THREE.Vector3(), view = new THREE.Vector3();
    this.camera.updateMatrixWorld();
    for (let i = 0; i < p.count; ++i) {
      v.set(p.getX(i), p.getY(i), p.getZ(i));
      const depth = view.copy(v).applyMatrix4(this.camera.matrixWorldInverse).z;
      v.project(this.camera);
      projected[3 * i] = v.x;
      projected[3 * i + 1] = v.y;
      projected[3 * i + 2] = -depth;  // distance in front of the camera
    }
    // Tolerance: 1 % of the shape plus a cell's width in shape units at the shape's distance (a
    // surface turned 45° from the viewer changes depth by a cell width across a cell); the
    // neighbouring cells' front three tolerances. On CGAL's bunny no lassoed point is behind the
    // mesh (tests/web/fit-region.test.mjs casts the rays); 2 % + 3 cell widths took 17 of 304.
    const distance = this.camera.position.distanceTo(this.controls.target);
    const cellWidth = (6 * 2 * distance * Math.tan(THREE.MathUtils.degToRad(this.camera.fov / 2))) / height;
    const tolerance = 0.01 * this.diagonal + cellWidth;
    const visible = visiblePoints(projected, width, height, tolerance, 3 * tolerance);
    for (let i = 0; i < p.count; ++i) {
      if (!visible[i]) continue;
      const x = ((projected[3 * i] + 1) / 2) * width, y = ((1 - projected[3 * i + 1]) / 2) * height;
      if (insidePolygon(loop, x, y)) this.selected[i] = erase ? 0 : 1;
    }
    this._colour();
    this.onSelection(this._inside);
  }
}
