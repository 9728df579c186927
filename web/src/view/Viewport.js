// The 3D view: shaded strip coloured by warp angle, boundary curves a/b, control polygons and
// control points (free: spheres; fixed: cubes; handles: magenta with their target), rulings and
// normals (toggles), other participants' selection/drag in their colour. Control points are
// picked with a Raycaster and dragged in the view plane by ViewportPointer.js: pointerdown on a
// point disables orbiting, pointermove sends at most one DragCommand per animation frame
// (latest wins), pointerup sends the last position and a DragEndCommand.

import * as THREE from 'three';
import { OrbitControls } from 'three/examples/jsm/controls/OrbitControls.js';
import { colorAt } from '../geometry/colormap.js';
import { targetKey, targetLabel, targetOf } from '../commands/Command.js';
import { PointSprites, SHAPE_CUBE, SHAPE_DIAMOND, SHAPE_RING, SHAPE_SPHERE } from './PointSprites.js';
import { GroupOverlay } from './GroupOverlay.js';
import { QuadMeshLayer } from './QuadMeshLayer.js';
import { ViewportPointer, sameTarget } from './ViewportPointer.js';

export const COLORS = {
  background: 0x161a21,
  curveA: 0xff9f43,
  curveB: 0x48cae4,
  polygon: 0xb8c0cc,
  point: 0xf4f6f8,
  fixed: 0x8d99ae,
  handle: 0xff4fd8,
  selected: 0xffd60a,
  // a composite's group selection (rotate_points; white as in 000_… Fig. 8), drawn as rings
  group: 0xffffff,
  hover: 0xffffff,
  rulings: 0x10131a,
  normals: 0x9be15d,
  ghost: 0xffd60a,
  // composites (fold-pattern convention: mountain red, valley blue)
  mountain: 0xff5a4f,
  valley: 0x4ea8ff,
  flatEdge: 0xc9d1dc,
  boundary: 0xe8ecf2,
  vertex: 0xf4f6f8,
  edgePoint: 0xc8f1fa,
  edgeMarker: 0x9aa5b5,
  edgeSelected: 0xffd60a,
  // the points a strip approximates (scene model.approximation)
  reference: 0x9be15d,
};

const POINT_RADIUS_PX = 7;
const PICK_TOLERANCE_PX = 12;
const CURVES = ['a', 'b'];

const tmpV = new THREE.Vector3();
const tmpV2 = new THREE.Vector3();
const tmpM = new THREE.Matrix4();
const tmpQ = new THREE.Quaternion();
const tmpS = new THREE.Vector3();
const tmpC = new THREE.Color();
const tmpW = new THREE.Vector3();
const tmpDir = new THREE.Vector3();

const SOFTWARE_GL = /swiftshader|llvmpipe|softpipe|software/i;

/**
 * The 3D view's renderer. Multisampling is cheap on a GPU but expensive with software GL
 * (SwiftShader, llvmpipe), and it is fixed when the context is made: the context is made without
 * it and asked for its renderer; in software it is kept (one context: a second one for the probe
 * cost ~30 ms of a page load), on a GPU it is given up for one with antialiasing.
 * Returns {renderer, softwareGL}; throws without WebGL 2.
 */
function createRenderer() {
  const canvas = document.createElement('canvas');
  const gl = canvas.getContext('webgl2', {
    alpha: false, depth: true, stencil: false, antialias: false, premultipliedAlpha: true,
    preserveDrawingBuffer: false, powerPreference: 'high-performance',
  });
  let softwareGL = false;
  if (gl) {
    const ext = gl.getExtension('WEBGL_debug_renderer_info');
    softwareGL = SOFTWARE_GL.test(String(ext ? gl.getParameter(ext.UNMASKED_RENDERER_WEBGL) : gl.getParameter(gl.RENDERER)));
    if (softwareGL) return { renderer: new THREE.WebGLRenderer({ canvas, context: gl }), softwareGL };
    const lose = gl.getExtension('WEBGL_lose_context');
    if (lose) lose.loseContext();
  }
  return { renderer: new THREE.WebGLRenderer({ antialias: true, powerPreference: 'high-performance' }), softwareGL };
}

/** An InstancedMesh that grows (is recreated) when more instances are needed. */
class InstancePool {
  constructor(parent, geometry, material, name, renderOrder = 0) {
    this.parent = parent;
    this.renderOrder = renderOrder;
    this.geometry = geometry;
    this.material = material;
    this.name = name;
    this.capacity = 0;
    this.mesh = null;
    /** instance → payload (e.g. {curve, index}) */
    this.items = [];
    this._ensure(16);
  }

  _ensure(n) {
    if (n <= this.capacity) return;
    let cap = Math.max(16, this.capacity);
    while (cap < n) cap *= 2;
    if (this.mesh) {
      this.parent.remove(this.mesh);
      this.mesh.dispose();
    }
    this.mesh = new THREE.InstancedMesh(this.geometry, this.material, cap);
    this.mesh.name = this.name;
    this.mesh.instanceMatrix.setUsage(THREE.DynamicDrawUsage);
    this.mesh.setColorAt(0, tmpC.set(0xffffff));
    this.mesh.frustumCulled = false;
    this.mesh.renderOrder = this.renderOrder;
    this.mesh.count = 0;
    this.capacity = cap;
    this.parent.add(this.mesh);
  }

  begin(n) {
    this._ensure(n);
    this.items.length = 0;
    this.mesh.count = 0;
  }

  push(position, scale, color, item) {
    const i = this.mesh.count++;
    tmpM.compose(position, tmpQ.identity(), tmpS.setScalar(scale));
    this.mesh.setMatrixAt(i, tmpM);
    this.mesh.setColorAt(i, tmpC.set(color));
    this.items[i] = item;
  }

  end() {
    this.mesh.instanceMatrix.needsUpdate = true;
    if (this.mesh.instanceColor) this.mesh.instanceColor.needsUpdate = true;
    this.mesh.computeBoundingSphere();
  }
}

export class Viewport {
  /**
   * @param {HTMLElement} container  the element holding the canvas (data-testid="viewport")
   * @param {object} deps  {state, buffers (StripBuffers), composite (CompositeBuffers),
   *   quad (QuadMeshBuffers), send(command), select(target|null), selectEdge(edge|null),
   *   pointDown(target) → true when it consumed the press (no drag; e.g. gluing picks),
   *   toggleGroup(target) → true when a Shift/Ctrl-click on the point toggled it in the group}
   */
  constructor(container, deps) {
    this.container = container;
    this.state = deps.state;
    this.buffers = deps.buffers;
    this.composite = deps.composite;
    this.quad = deps.quad || null;
    this.pointDown = deps.pointDown || (() => false);
    this.selectEdge = deps.selectEdge || (() => {});
    this.toggleGroup = deps.toggleGroup || (() => false);
    /** 'strip' | 'composite' | 'quad_mesh': which buffers are shown. */
    this.kind = 'strip';
    this.send = deps.send;
    this.select = deps.select;
    this.options = { rulings: true, normals: false, polygons: true, surface: true, reference: true };
    /** Points of the scene's approximation target shown (0 when none). */
    this.referenceCount = 0;
    this.pointRadiusPx = POINT_RADIUS_PX;
    this.dirty = true;
    /** Hovered and dragged point, set by the pointer handling (ViewportPointer), drawn here. */
    this.hovered = null;
    this.drag = null;
    this.hasFit = false;
    this.webgl = true;

    try {
      ({ renderer: this.renderer, softwareGL: this.softwareGL } = createRenderer());
    } catch (e) {
      this.webgl = false;
      this.renderer = null;
      const msg = document.createElement('div');
      msg.className = 'viewport-fallback';
      msg.textContent = 'WebGL is not available in this browser: the 3D view is off (the development and panels still work).';
      container.appendChild(msg);
    }
    this.camera = new THREE.PerspectiveCamera(35, 1, 0.01, 1000);
    this.camera.up.set(0, 0, 1);
    this.camera.position.set(3, -6, 4);
    this.scene = new THREE.Scene();
    this.scene.background = new THREE.Color(COLORS.background);
    this._buildScene();

    if (this.renderer) {
      this.renderer.setPixelRatio(Math.min(window.devicePixelRatio || 1, 2));
      this.points.setPixelRatio(this.renderer.getPixelRatio());
      this.canvas = this.renderer.domElement;
      this.canvas.className = 'viewport-canvas';
      container.appendChild(this.canvas);
      this.controls = new OrbitControls(this.camera, this.canvas);
      this.controls.enableDamping = true;
      this.controls.dampingFactor = 0.12;
      this.controls.addEventListener('change', () => this.requestRender());
      this.pointer = new ViewportPointer(this, { pickSlackPx: PICK_TOLERANCE_PX - POINT_RADIUS_PX });
    } else {
      this.canvas = null;
      this.controls = { target: new THREE.Vector3(), update: () => false, enabled: true };
    }

    this.labels = document.createElement('div');
    this.labels.className = 'viewport-labels';
    container.appendChild(this.labels);
    this._labelEls = new Map();

    this._resizeObserver = new ResizeObserver(() => this.resize());
    this._resizeObserver.observe(container);
    this.resize();

    this._loop = this._loop.bind(this);
    this._raf = null;
    this.disposed = false;
    this.requestRender();
  }

  _buildScene() {
    const b = this.buffers;
    const scene = this.scene;
    scene.add(new THREE.HemisphereLight(0xffffff, 0x3a4050, 1.4));
    const head = new THREE.DirectionalLight(0xffffff, 1.8);
    head.position.set(0.3, 0.6, 1);
    this.camera.add(head);
    scene.add(this.camera);

    this.surfaceMaterial = new THREE.MeshStandardMaterial({
      vertexColors: true, side: THREE.DoubleSide, roughness: 0.65, metalness: 0.0,
      polygonOffset: true, polygonOffsetFactor: 1, polygonOffsetUnits: 1,
    });
    this.surfaceMesh = new THREE.Mesh(b.surface, this.surfaceMaterial);
    this.surfaceMesh.frustumCulled = false;
    scene.add(this.surfaceMesh);

    this.curveLines = {};
    this.polygonLines = {};
    for (const c of CURVES) {
      const color = c === 'a' ? COLORS.curveA : COLORS.curveB;
      this.curveLines[c] = new THREE.Line(b.curves[c], new THREE.LineBasicMaterial({ color }));
      this.curveLines[c].frustumCulled = false;
      this.curveLines[c].renderOrder = 2;
      scene.add(this.curveLines[c]);
      this.polygonLines[c] = new THREE.Line(b.polygons[c], new THREE.LineBasicMaterial({ color: COLORS.polygon, transparent: true, opacity: 0.7, depthTest: false }));
      this.polygonLines[c].frustumCulled = false;
      this.polygonLines[c].renderOrder = 3;
      scene.add(this.polygonLines[c]);
    }
    this.rulingLines = new THREE.LineSegments(b.rulings, new THREE.LineBasicMaterial({ color: COLORS.rulings, transparent: true, opacity: 0.45 }));
    this.rulingLines.frustumCulled = false;
    this.rulingLines.renderOrder = 1;
    scene.add(this.rulingLines);
    // The reference points a fitted strip approximates (000_… §4.2), drawn as dots the surface
    // can hide: a point in front of the strip is one it does not reach yet.
    this.referenceGeometry = new THREE.BufferGeometry();
    this.referenceCloud = new THREE.Points(this.referenceGeometry, new THREE.PointsMaterial({
      color: COLORS.reference, size: 4, sizeAttenuation: false, transparent: true, opacity: 0.9,
    }));
    this.referenceCloud.frustumCulled = false;
    this.referenceCloud.visible = false;
    this.referenceCloud.renderOrder = 1;
    scene.add(this.referenceCloud);
    this.normalLines = new THREE.LineSegments(b.normals, new THREE.LineBasicMaterial({ color: COLORS.normals }));
    this.normalLines.frustumCulled = false;
    this.normalLines.visible = false;
    scene.add(this.normalLines);

    // Control points: sprites drawn on top of the surface so they can always be grabbed
    // (spheres; fixed points as cubes).
    this.points = new PointSprites(scene);
    const targetMaterial = new THREE.MeshBasicMaterial({ wireframe: true, depthTest: false, transparent: true });
    this.handleTargets = new InstancePool(scene, new THREE.OctahedronGeometry(1.4), targetMaterial, 'handle-targets', 5);
    const haloMaterial = new THREE.MeshBasicMaterial({ transparent: true, opacity: 0.38, depthTest: false, depthWrite: false });
    this.halos = new InstancePool(scene, new THREE.SphereGeometry(1, 16, 10), haloMaterial, 'presence-halos', 4);

    this.handleLinkGeometry = new THREE.BufferGeometry();
    this.handleLinks = new THREE.LineSegments(this.handleLinkGeometry, new THREE.LineBasicMaterial({ color: COLORS.handle, transparent: true, opacity: 0.8, depthTest: false }));
    this.handleLinks.frustumCulled = false;
    scene.add(this.handleLinks);

    // Composites: faces, creases by assignment (mountain red dash-dot, valley blue dashed, flat
    // interior edges grey, boundary light), S-edge control polygons.
    const c = this.composite;
    this.compositeGroup = new THREE.Group();
    this.compositeGroup.visible = false;
    scene.add(this.compositeGroup);
    this.compositeSurface = new THREE.Mesh(c.surface, this.surfaceMaterial);
    this.compositeSurface.frustumCulled = false;
    this.compositeGroup.add(this.compositeSurface);
    const lines = (geometry, material, order) => {
      const l = new THREE.LineSegments(geometry, material);
      l.frustumCulled = false;
      l.renderOrder = order;
      this.compositeGroup.add(l);
      return l;
    };
    this.compositeLines = {
      boundary: lines(c.lines.boundary, new THREE.LineBasicMaterial({ color: COLORS.boundary }), 2),
      flat: lines(c.lines.flat, new THREE.LineBasicMaterial({ color: COLORS.flatEdge, transparent: true, opacity: 0.8 }), 2),
      mountain: lines(c.lines.mountain, new THREE.LineDashedMaterial({ color: COLORS.mountain, dashSize: 0.06, gapSize: 0.025 }), 2),
      valley: lines(c.lines.valley, new THREE.LineDashedMaterial({ color: COLORS.valley, dashSize: 0.035, gapSize: 0.03 }), 2),
      polygons: lines(c.lines.polygons, new THREE.LineBasicMaterial({ color: COLORS.polygon, transparent: true, opacity: 0.55, depthTest: false }), 3),
    };
    // The selected edge, drawn over everything.
    this.selectedEdgeGeometry = new THREE.BufferGeometry();
    this.selectedEdgeLine = new THREE.Line(this.selectedEdgeGeometry, new THREE.LineBasicMaterial({ color: COLORS.edgeSelected, depthTest: false, transparent: true }));
    this.selectedEdgeLine.frustumCulled = false;
    this.selectedEdgeLine.renderOrder = 4;
    this.compositeGroup.add(this.selectedEdgeLine);

    this.quadLayer = this.quad ? new QuadMeshLayer(scene, this.quad) : null;

    this.ghost = new THREE.Mesh(new THREE.SphereGeometry(1, 20, 12), new THREE.MeshBasicMaterial({ color: COLORS.ghost, wireframe: true, depthTest: false, transparent: true, opacity: 0.9 }));
    this.ghost.visible = false;
    this.ghost.renderOrder = 6;
    scene.add(this.ghost);
    this.groupOverlay = new GroupOverlay(this);
  }

  // ---- options -----------------------------------------------------------------------------

  setOption(name, value) {
    this.options[name] = value;
    const strip = this.kind === 'strip';
    this.rulingLines.visible = strip && this.options.rulings;
    this.normalLines.visible = strip && this.options.normals;
    for (const c of CURVES) {
      this.polygonLines[c].visible = strip && this.options.polygons;
      this.curveLines[c].visible = strip;
    }
    this.surfaceMesh.visible = strip && this.options.surface;
    this.referenceCloud.visible = strip && this.options.reference && this.referenceCount > 0;
    this.compositeGroup.visible = this.kind === 'composite';
    if (this.quadLayer) {
      this.quadLayer.setVisible(this.kind === 'quad_mesh', {
        surface: this.options.surface, rulings: this.options.rulings, glue: this.options.glue !== false, controlNet: this.options.polygons,
      });
    }
    this.compositeSurface.visible = this.options.surface;
    this.compositeLines.polygons.visible = this.options.polygons;
    this.requestRender();
  }

  /**
   * The points the scene's strip approximates (model.approximation.points, design coordinates),
   * or none.
   * @param {number[][]|undefined} points
   */
  setReferencePoints(points) {
    const list = Array.isArray(points) ? points.filter((p) => Array.isArray(p) && p.length === 3 && p.every(Number.isFinite)) : [];
    const array = new Float32Array(3 * list.length);
    list.forEach((p, i) => array.set(p, 3 * i));
    this.referenceGeometry.setAttribute('position', new THREE.BufferAttribute(array, 3));
    this.referenceGeometry.computeBoundingSphere();
    this.referenceCount = list.length;
    this.referenceGeometry.deleteAttribute('color');
    this.referenceCloud.material.vertexColors = false;
    this.referenceCloud.material.color.set(COLORS.reference);
    this.referenceCloud.material.needsUpdate = true;
    this.setOption('reference', this.options.reference);
    // Distances that arrived with a geometry before the scene did.
    if (this._referenceDistances) this.setReferenceDistances(...this._referenceDistances);
  }

  /**
   * Colours the reference points by their distance to the surface (issue 15): 0 calm blue-green,
   * three times `tolerance` (the coverage tolerance, 1 % of the points' size) and beyond red.
   * Ignored unless there is one distance per point.
   * @param {number[]|undefined} distances  per reference point, design units
   * @param {number} tolerance
   */
  setReferenceDistances(distances, tolerance) {
    this._referenceDistances = Array.isArray(distances) ? [distances, tolerance] : null;
    if (!Array.isArray(distances) || distances.length !== this.referenceCount || !(tolerance > 0)) return;
    const colors = new Float32Array(3 * distances.length);
    for (let i = 0; i < distances.length; ++i) colorAt(distances[i] / (3 * tolerance), colors, 3 * i);
    this.referenceGeometry.setAttribute('color', new THREE.BufferAttribute(colors, 3));
    if (!this.referenceCloud.material.vertexColors) {
      this.referenceCloud.material.vertexColors = true;
      this.referenceCloud.material.color.set(0xffffff);
      this.referenceCloud.material.needsUpdate = true;
    }
    this.requestRender();
  }

  /** Shows the strip's or the composite's objects. */
  setKind(kind) {
    if (kind === this.kind) return;
    this.kind = kind;
    this.hasFit = false;
    this.setOption('surface', this.options.surface);
  }

  /** The buffers of the shown model. */
  activeBuffers() {
    if (this.kind === 'quad_mesh' && this.quad) return this.quad;
    return this.kind === 'composite' ? this.composite : this.buffers;
  }

  /** After a composite geometry update: dash distances and the selected edge's highlight. */
  updateComposite() {
    for (const name of ['mountain', 'valley']) this.compositeLines[name].computeLineDistances();
    this._updateSelectedEdge();
    this.requestRender();
  }

  _updateSelectedEdge() {
    const e = this.state.selectedEdge;
    const edge = e !== null && e !== undefined ? this.composite.edge(e) : null;
    const g = this.selectedEdgeGeometry;
    if (!edge) {
      this.selectedEdgeLine.visible = false;
      return;
    }
    g.setAttribute('position', new THREE.BufferAttribute(Float32Array.from(edge.polyline), 3));
    g.computeBoundingSphere();
    this.selectedEdgeLine.visible = true;
  }

  setLargePoints(large) {
    this.pointRadiusPx = large ? POINT_RADIUS_PX * 1.35 : POINT_RADIUS_PX;
    this.requestRender();
  }

  // ---- rendering -----------------------------------------------------------------------------

  /**
   * Asks for a frame. Frames are drawn on demand only: an idle view requests no animation frames
   * (with software WebGL an always-running loop cost a page ~0.3 CPU-s per idle second). The loop
   * keeps running while the orbit controls still move the camera (their damping), then stops.
   */
  requestRender() {
    this.dirty = true;
    if (this._raf === null && !this.disposed) this._raf = requestAnimationFrame(this._loop);
  }

  _loop() {
    this._raf = null;
    const moved = this.controls.update();
    if (moved || this.dirty) this.renderNow();
    if (moved && this._raf === null) this._raf = requestAnimationFrame(this._loop);
  }

  /** Renders synchronously (used when applying an iterate, so its cost is measured). */
  /** Near/far planes follow the orbit distance (zooming never clips the strip). */
  _updateClipping() {
    const d = this.camera.position.distanceTo(this.controls.target) || 1;
    const near = d / 100;
    const far = d * 100;
    if (Math.abs(this.camera.near - near) > near * 0.05 || Math.abs(this.camera.far - far) > far * 0.05) {
      this.camera.near = near;
      this.camera.far = far;
      this.camera.updateProjectionMatrix();
    }
  }

  renderNow() {
    this.dirty = false;
    this._updateClipping();
    if (this.quadLayer) this.quadLayer.sync();
    this.layoutInstances();
    if (this.renderer) this.renderer.render(this.scene, this.camera);
    this._updateLabels();
  }

  resize() {
    const w = Math.max(1, this.container.clientWidth);
    const h = Math.max(1, this.container.clientHeight);
    this.width = w;
    this.height = h;
    this.camera.aspect = w / h;
    this.camera.updateProjectionMatrix();
    if (this.renderer) this.renderer.setSize(w, h);
    this.renderNow();
  }

  /** World units per CSS pixel at the depth of `p`. */
  worldPerPixel(p) {
    const d = tmpW.copy(p).sub(this.camera.position).dot(this.camera.getWorldDirection(tmpDir));
    const h = 2 * Math.max(d, 1e-6) * Math.tan(THREE.MathUtils.degToRad(this.camera.fov / 2));
    return h / this.height;
  }

  /** Places the control-point, handle and presence instances (screen-constant sizes). */
  layoutInstances() {
    const b = this.activeBuffers();
    const st = this.state;
    if (!b.hasData) return;
    const composite = this.kind === 'composite';
    const fixedSet = new Set(st.constraints.fixed.map((f) => targetKey(f)));
    const handleMap = new Map(st.constraints.handles.map((h) => [targetKey(h), h]));
    const targets = b.pointTargets();
    const markers = composite ? this.composite.edges.filter((e) => e.interior) : [];
    const total = targets.length;
    // Dense control polygons get smaller points so they stay apart (sized for the primary points).
    const dense = b.pointDensityCount ? b.pointDensityCount() : total;
    const density = dense > 120 ? 0.55 : dense > 40 ? 0.75 : 1;
    const radiusPx = this.pointRadiusPx * density;
    this.points.begin(total + markers.length);
    this.handleTargets.begin(handleMap.size);
    const links = [];
    const dragging = this.drag && this.drag.target;
    const groupKeys = new Set(composite ? st.group.map((t) => targetKey(t)) : []);
    for (const item of targets) {
      const p = b.pointOf(item);
      if (!p) continue;
      tmpV.set(p[0], p[1], p[2]);
      const key = targetKey(item);
      const selected = sameTarget(st.selection, item) || sameTarget(dragging, item);
      const hovered = sameTarget(this.hovered, item);
      const vertex = item.vertex !== undefined;
      const handle = handleMap.get(key);
      const fixed = fixedSet.has(key);
      const grouped = groupKeys.has(key);
      // Dense meshes (quad_mesh) draw their plain points smaller.
      const plain = b.pointScale && !(selected || hovered || handle || fixed || grouped) ? b.pointScale(item) : 1;
      const r = radiusPx * (selected ? 1.35 : grouped ? 1.3 : hovered ? 1.2 : 1) * (composite && !vertex ? 0.8 : 1) * plain;
      let color;
      if (b.pointColor) color = b.pointColor(item);
      else color = composite ? (vertex ? COLORS.vertex : COLORS.edgePoint) : b.slot(item.curve) === 'a' ? 0xffd9b0 : 0xc8f1fa;
      if (fixed) color = COLORS.fixed;
      if (handle) color = COLORS.handle;
      if (grouped) color = COLORS.group;
      if (selected) color = COLORS.selected;
      this.points.push(tmpV, r, color, grouped ? SHAPE_RING : fixed ? SHAPE_CUBE : SHAPE_SPHERE, item);
      if (handle) {
        const t = handle.position;
        tmpV2.set(t[0], t[1], t[2]);
        this.handleTargets.push(tmpV2, radiusPx * this.worldPerPixel(tmpV2), COLORS.handle, item);
        links.push(tmpV.x, tmpV.y, tmpV.z, t[0], t[1], t[2]);
      }
    }
    // Interior edges of a composite: a diamond at the midpoint selects the edge.
    for (const e of markers) {
      tmpV.fromArray(e.midpoint);
      const item = { edgeMarker: e.edge };
      const selected = st.selectedEdge === e.edge;
      const hovered = sameTarget(this.hovered, item);
      const color = selected ? COLORS.edgeSelected : e.assignment === 'M' ? COLORS.mountain : e.assignment === 'V' ? COLORS.valley : COLORS.edgeMarker;
      this.points.push(tmpV, radiusPx * (selected || hovered ? 1.2 : 0.95), color, SHAPE_DIAMOND, item);
    }
    this.points.end();
    this.handleTargets.end();
    this._setLinks(links);
    this.groupOverlay.layout();

    // Other participants' selection / drag, in their colour.
    const others = st.participants.filter((p) => p.id !== st.you && (p.dragging || p.selection));
    this.halos.begin(others.length);
    for (const p of others) {
      const t = p.dragging || p.selection;
      const q = b.pointOf(t);
      if (!q) continue;
      tmpV.set(q[0], q[1], q[2]);
      this.halos.push(tmpV, this.pointRadiusPx * this.worldPerPixel(tmpV) * (p.dragging ? 2.3 : 1.9), p.color || '#ffffff', { participant: p, target: t });
    }
    this.halos.end();

    if (this.drag && this.drag.position) {
      this.ghost.visible = true;
      this.ghost.position.copy(this.drag.position);
      this.ghost.scale.setScalar(this.pointRadiusPx * 0.8 * this.worldPerPixel(this.drag.position));
    } else {
      this.ghost.visible = false;
    }
  }

  _setLinks(values) {
    const g = this.handleLinkGeometry;
    const attr = g.getAttribute('position');
    if (!attr || attr.array.length < values.length) {
      g.dispose();
      g.setAttribute('position', new THREE.BufferAttribute(new Float32Array(Math.max(6, values.length * 2)), 3).setUsage(THREE.DynamicDrawUsage));
    }
    const a = g.getAttribute('position');
    a.array.set(values);
    a.needsUpdate = true;
    g.setDrawRange(0, values.length / 3);
  }

  /** Name tags of other participants next to what they selected or drag. */
  _updateLabels() {
    const st = this.state;
    const seen = new Set();
    if (this.activeBuffers().hasData) {
      for (const p of st.participants) {
        if (p.id === st.you || !(p.dragging || p.selection)) continue;
        const t = p.dragging || p.selection;
        const s = this.pointScreenPosition(t);
        if (!s) continue;
        seen.add(p.id);
        let el = this._labelEls.get(p.id);
        if (!el) {
          el = document.createElement('div');
          el.className = 'presence-tag';
          this.labels.appendChild(el);
          this._labelEls.set(p.id, el);
        }
        el.textContent = `${p.name || 'guest'}${p.dragging ? ' · dragging' : ''} ${targetLabel(t)}`;
        el.style.borderColor = p.color || '#fff';
        // To the right of the point, or to the left where it would leave the view.
        const w = el.offsetWidth;
        const x = s.x + 14 + w > this.width - 4 ? s.x - 14 - w : s.x + 14;
        const y = Math.min(Math.max(s.y - 28, 2), this.height - 24);
        el.style.transform = `translate(${Math.round(Math.max(2, x))}px, ${Math.round(y)}px)`;
      }
    }
    for (const [id, el] of this._labelEls) {
      if (!seen.has(id)) {
        el.remove();
        this._labelEls.delete(id);
      }
    }
  }

  // ---- camera ---------------------------------------------------------------------------------

  /** The diagonal of the surface's bounding box (design units), null before there is one. */
  designSize() {
    const b = this.activeBuffers();
    const pos = b.hasData && b.surface.getAttribute('position');
    if (!pos || !pos.count) return null;
    const box = new THREE.Box3().setFromBufferAttribute(pos);
    const d = box.getSize(new THREE.Vector3()).length();
    return d > 0 && Number.isFinite(d) ? d : null;
  }

  /** Whether part of the surface lies outside the view (the camera's frustum; ≤ 400 vertices tested). */
  surfaceOutsideView() {
    const b = this.activeBuffers();
    if (!b.hasData) return false;
    const pos = b.surface.getAttribute('position');
    if (!pos || !pos.count) return false;
    this.camera.updateMatrixWorld();
    const frustum = new THREE.Frustum().setFromProjectionMatrix(
      new THREE.Matrix4().multiplyMatrices(this.camera.projectionMatrix, this.camera.matrixWorldInverse));
    const p = new THREE.Vector3();
    const stride = Math.max(1, Math.floor(pos.count / 400));
    for (let i = 0; i < pos.count; i += stride) {
      p.fromBufferAttribute(pos, i);
      if (!frustum.containsPoint(p)) return true;
    }
    return false;
  }

  /** Fits the whole strip (surface, control points, handle targets) into the view. */
  fit() {
    const b = this.activeBuffers();
    if (!b.hasData) return;
    const pts = [];
    const pos = b.surface.getAttribute('position');
    if (pos) for (let i = 0; i < pos.array.length; i += 3) pts.push(new THREE.Vector3(pos.array[i], pos.array[i + 1], pos.array[i + 2]));
    for (const t of b.pointTargets()) {
      const p = b.pointOf(t);
      if (p) pts.push(new THREE.Vector3(p[0], p[1], p[2]));
    }
    for (const h of this.state.constraints.handles) {
      const t = targetOf(h);
      if (h.position && !(t && t.on === 'unfolding')) pts.push(new THREE.Vector3().fromArray(h.position));
    }
    if (!pts.length) return;
    const box = new THREE.Box3().setFromPoints(pts);
    const center = box.getCenter(new THREE.Vector3());
    let dir = this.camera.position.clone().sub(this.controls.target);
    if (!this.hasFit || dir.lengthSq() < 1e-12) dir = new THREE.Vector3(0.35, -1, 0.8);
    dir.normalize();
    // Camera basis looking along −dir with z up.
    const forward = dir.clone().negate();
    let right = new THREE.Vector3().crossVectors(forward, this.camera.up);
    if (right.lengthSq() < 1e-10) right = new THREE.Vector3(1, 0, 0);
    right.normalize();
    const up = new THREE.Vector3().crossVectors(right, forward).normalize();
    const tanV = Math.tan(THREE.MathUtils.degToRad(this.camera.fov) / 2);
    const tanH = tanV * this.camera.aspect;
    // Smallest distance at which every point is inside the frustum (with a margin).
    const margin = 1.2;
    let distance = 1e-3;
    const q = new THREE.Vector3();
    for (const p of pts) {
      q.copy(p).sub(center);
      const toward = q.dot(dir);
      distance = Math.max(distance, toward + (Math.abs(q.dot(right)) * margin) / tanH, toward + (Math.abs(q.dot(up)) * margin) / tanV);
    }
    this.controls.target.copy(center);
    this.camera.position.copy(center).addScaledVector(dir, distance);
    this.camera.lookAt(center);
    this._updateClipping();
    this.hasFit = true;
    this.requestRender();
  }

  /** CSS px position (relative to the viewport element) of a control point, or null. */
  controlPointScreenPosition(curve, index) {
    return this.pointScreenPosition({ curve, index });
  }

  /** CSS px position of a point target ({curve, index}, {vertex} or {edge, index}), or null. */
  pointScreenPosition(target) {
    const p = this.activeBuffers().pointOf(targetOf(target));
    return p ? this.worldToScreen(p) : null;
  }

  /** CSS px position of the selection marker of a composite's edge, or null. */
  edgeScreenPosition(e) {
    const edge = this.kind === 'composite' ? this.composite.edge(e) : null;
    return edge ? this.worldToScreen(edge.midpoint) : null;
  }

  worldToScreen(p) {
    this.camera.updateMatrixWorld();
    tmpV.set(p[0], p[1], p[2]).project(this.camera);
    return { x: ((tmpV.x + 1) / 2) * this.width, y: ((1 - tmpV.y) / 2) * this.height };
  }

  dispose() {
    this.disposed = true;  // no frames after this, whoever asks
    if (this._raf !== null) cancelAnimationFrame(this._raf);
    this._raf = null;
    this._resizeObserver.disconnect();
    if (this.renderer) this.renderer.dispose();
  }
}
