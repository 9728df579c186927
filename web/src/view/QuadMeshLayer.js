// The 3D view's objects of a quad_mesh session (M): the faces as triangles coloured per face,
// the wireframe edges on top coloured per edge, the rulings of the developable faces and the
// glued pairs as links. Geometries live in QuadMeshBuffers; this only owns the three.js objects.

import * as THREE from 'three';

export const QUAD_COLORS = {
  rulings: 0xc2410c,
  glue: 0x5ee6a0,
};

export class QuadMeshLayer {
  /**
   * @param {THREE.Object3D} parent
   * @param {import('../geometry/QuadMeshBuffers.js').QuadMeshBuffers} quad
   */
  constructor(parent, quad) {
    this.group = new THREE.Group();
    this.group.name = 'quad-mesh';
    this.group.visible = false;
    parent.add(this.group);
    this.surfaceMaterial = new THREE.MeshStandardMaterial({
      vertexColors: true, side: THREE.DoubleSide, roughness: 0.7, metalness: 0.0,
      polygonOffset: true, polygonOffsetFactor: 1, polygonOffsetUnits: 1,
    });
    const add = (object, order) => {
      object.frustumCulled = false;
      object.renderOrder = order;
      this.group.add(object);
      return object;
    };
    this.surface = add(new THREE.Mesh(quad.surface, this.surfaceMaterial), 0);
    this.edges = add(new THREE.LineSegments(quad.edgeLines, new THREE.LineBasicMaterial({ vertexColors: true })), 2);
    this.rulings = add(new THREE.LineSegments(quad.rulings, new THREE.LineBasicMaterial({ color: QUAD_COLORS.rulings, transparent: true, opacity: 0.85 })), 3);
    // Glue links are drawn over everything: after a solve they are short, so they must not hide.
    this.glue = add(new THREE.LineSegments(quad.glueLines, new THREE.LineBasicMaterial({ color: QUAD_COLORS.glue, depthTest: false, transparent: true })), 4);
  }

  /** Visibility of the layer and of its parts: {surface, edges, rulings, glue}. */
  setVisible(visible, options = {}) {
    this.group.visible = visible;
    this.surface.visible = options.surface !== false;
    this.edges.visible = options.edges !== false;
    this.rulings.visible = options.rulings !== false;
    this.glue.visible = options.glue !== false;
  }
}
