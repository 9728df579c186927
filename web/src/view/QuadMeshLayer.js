// The 3D view's objects of a quad_mesh session (M): the faces as triangles coloured per face,
// the wireframe edges on top coloured per edge, the rulings of the developable faces and the
// glued pairs as links. A spline session (a control net, issue 14) adds the limit surface M^∞
// (smooth-shaded sample grids of its patches), its rulings and the control mesh's edges (the
// control points are the view's point sprites). While M^∞ is the surface shown (quad.showsLimit)
// it replaces M's faces, edges and face rulings; in the 'refined' display M is drawn as without
// a spline, with the control net over it. Geometries live in QuadMeshBuffers / SplineBuffers;
// this only owns the three.js objects.

import * as THREE from 'three';
import { LineMaterial } from 'three/examples/jsm/lines/LineMaterial.js';
import { LineSegments2 } from 'three/examples/jsm/lines/LineSegments2.js';
import { LineSegmentsGeometry } from 'three/examples/jsm/lines/LineSegmentsGeometry.js';

/** Width of the rulings of M^∞ in CSS px (wide lines: they are what the surface is about). */
export const SPLINE_RULING_WIDTH_PX = 2.5;

export const QUAD_COLORS = {
  rulings: 0xc2410c,
  glue: 0x5ee6a0,
  /** The rulings of M^∞: dark violet, apart from the face rulings and from both ends of the K map. */
  splineRulings: 0x3b0764,
  /** The control mesh's edges: a stronger blue than the control points (CONTROL_POINT_COLOR), seen on paper and on the background. */
  controlNet: 0x2b8ed6,
};

export class QuadMeshLayer {
  /**
   * @param {THREE.Object3D} parent
   * @param {import('../geometry/QuadMeshBuffers.js').QuadMeshBuffers} quad
   */
  constructor(parent, quad) {
    this.quad = quad;
    this.group = new THREE.Group();
    this.group.name = 'quad-mesh';
    this.group.visible = false;
    parent.add(this.group);
    this.surfaceMaterial = new THREE.MeshStandardMaterial({
      vertexColors: true, side: THREE.DoubleSide, roughness: 0.7, metalness: 0.0,
      polygonOffset: true, polygonOffsetFactor: 1, polygonOffsetUnits: 1,
    });
    const add = (object, order, name) => {
      object.frustumCulled = false;
      object.renderOrder = order;
      object.name = name;
      this.group.add(object);
      return object;
    };
    this.surface = add(new THREE.Mesh(quad.surface, this.surfaceMaterial), 0, 'quad-surface');
    this.edges = add(new THREE.LineSegments(quad.edgeLines, new THREE.LineBasicMaterial({ vertexColors: true })), 2, 'quad-edges');
    this.rulings = add(new THREE.LineSegments(quad.rulings, new THREE.LineBasicMaterial({ color: QUAD_COLORS.rulings, transparent: true, opacity: 0.85 })), 3, 'quad-rulings');
    // Glue links are drawn over everything: after a solve they are short, so they must not hide.
    this.glue = add(new THREE.LineSegments(quad.glueLines, new THREE.LineBasicMaterial({ color: QUAD_COLORS.glue, depthTest: false, transparent: true })), 4, 'quad-glue');

    const s = quad.spline;
    // M^∞ is pushed back further than M's faces: its rulings lie on the true surface, which bulges
    // past the flat triangles between samples.
    this.splineMaterial = new THREE.MeshStandardMaterial({
      vertexColors: true, side: THREE.DoubleSide, roughness: 0.6, metalness: 0.0,
      polygonOffset: true, polygonOffsetFactor: 2, polygonOffsetUnits: 4,
    });
    this.splineSurface = add(new THREE.Mesh(s.surface, this.splineMaterial), 0, 'spline-surface');
    // Wide lines share SplineBuffers' segment array (x0 y0 z0 x1 y1 z1 per ruling segment): sync().
    this.splineRulingGeometry = new LineSegmentsGeometry();
    this.splineRulingMaterial = new LineMaterial({ color: QUAD_COLORS.splineRulings, linewidth: SPLINE_RULING_WIDTH_PX });
    this.splineRulings = add(new LineSegments2(this.splineRulingGeometry, this.splineRulingMaterial), 3, 'spline-rulings');
    this._rulingArray = null;
    this._rulingVersion = -1;
    // The control net is seen through the surface (it lies off it), like a strip's control polygons.
    this.controlNet = add(new THREE.LineSegments(s.controlLines, new THREE.LineBasicMaterial({
      color: QUAD_COLORS.controlNet, transparent: true, opacity: 0.9, depthTest: false,
    })), 4, 'control-net');
    this.visible = false;
    this.options = {};
  }

  /** Before a render: the wide rulings follow SplineBuffers (same array; re-shared when it grew). */
  sync() {
    const s = this.quad.spline;
    if (s.version === this._rulingVersion) return;
    this._rulingVersion = s.version;
    const attr = s.rulings.getAttribute('position');
    const g = this.splineRulingGeometry;
    if (!attr) {
      g.instanceCount = 0;
      return;
    }
    if (attr.array !== this._rulingArray) {
      g.dispose();
      g.setPositions(attr.array);
      this._rulingArray = attr.array;
    } else {
      g.getAttribute('instanceStart').data.needsUpdate = true;
    }
    g.instanceCount = s.present ? s.rulingSegments : 0;
  }

  /** Visibility of the layer and of its parts: {surface, edges, rulings, glue, controlNet}. */
  setVisible(visible, options = {}) {
    this.visible = visible;
    this.options = options;
    this.refresh();
  }

  /** Applies the visibility again (after the spline appeared or the display changed). */
  refresh() {
    const o = this.options;
    const spline = this.quad.hasSpline;
    const limit = this.quad.showsLimit;
    this.group.visible = this.visible;
    this.surface.visible = o.surface !== false && !limit;
    this.edges.visible = o.edges !== false && !limit;
    this.rulings.visible = o.rulings !== false && !limit;
    this.glue.visible = o.glue !== false;
    this.splineSurface.visible = o.surface !== false && limit;
    this.splineRulings.visible = o.rulings !== false && limit;
    this.controlNet.visible = spline && o.controlNet !== false;
  }
}
