// The 3D view's marks of a composite's group selection (rotate_points): the centre (the group's
// centroid) as a dot, the axis the Selection panel turns the group about as a dashed line through
// it (a fixed length on screen; none for the viewing direction, which points at the viewer), and
// the camera's viewing direction for the "view" axis. The group's points themselves
// are drawn as rings by Viewport.layoutInstances.

import * as THREE from 'three';
import { axisVector, centroid } from '../geometry/groupRotation.js';

const AXIS_HALF_LENGTH_PX = 70;
const AXIS_COLOR = 0xffffff;

const tmpC = new THREE.Vector3();
const tmpA = new THREE.Vector3();

export class GroupOverlay {
  /** @param {import('./Viewport.js').Viewport} view */
  constructor(view) {
    this.view = view;
    this.geometry = new THREE.BufferGeometry();
    this.geometry.setAttribute('position', new THREE.BufferAttribute(new Float32Array(6), 3).setUsage(THREE.DynamicDrawUsage));
    this.line = new THREE.Line(this.geometry, new THREE.LineDashedMaterial({
      color: AXIS_COLOR, dashSize: 1, gapSize: 0.6, depthTest: false, transparent: true, opacity: 0.85,
    }));
    this.line.name = 'group-axis';
    this.line.frustumCulled = false;
    this.line.renderOrder = 4;
    this.line.visible = false;
    view.scene.add(this.line);
    this.dotGeometry = new THREE.BufferGeometry();
    this.dotGeometry.setAttribute('position', new THREE.BufferAttribute(new Float32Array(3), 3).setUsage(THREE.DynamicDrawUsage));
    this.dot = new THREE.Points(this.dotGeometry, new THREE.PointsMaterial({
      color: AXIS_COLOR, size: 6, sizeAttenuation: false, depthTest: false, transparent: true,
    }));
    this.dot.name = 'group-centre';
    this.dot.frustumCulled = false;
    this.dot.renderOrder = 4;
    this.dot.visible = false;
    view.scene.add(this.dot);
  }

  /** The camera's viewing direction [x, y, z] (unit). */
  viewDirection() {
    return this.view.camera.getWorldDirection(new THREE.Vector3()).toArray();
  }

  /**
   * The centre of the turn: typed in the Selection panel, else the centroid of the points a
   * rotation turns now (group, or the selected point); null when there are none.
   */
  centre() {
    const view = this.view;
    if (view.kind !== 'composite') return null;
    const b = view.activeBuffers();
    const c = centroid(view.state.rotationTargets().map((t) => b.pointOf(t)));
    return c && view.state.rotateCentre ? view.state.rotateCentre : c;
  }

  /** Places the axis line (called with the point layout, every frame that renders). */
  layout() {
    const view = this.view;
    const st = view.state;
    const c = st.canEdit ? this.centre() : null;
    const axis = c && st.rotateAxis !== 'view' ? axisVector(st.rotateAxis) : null;
    this.dot.visible = !!c;
    this.line.visible = !!axis;
    if (!c) return;
    tmpC.fromArray(c);
    const dot = this.dotGeometry.getAttribute('position');
    dot.setXYZ(0, tmpC.x, tmpC.y, tmpC.z);
    dot.needsUpdate = true;
    this.dotGeometry.computeBoundingSphere();
    if (!axis) return;
    const half = AXIS_HALF_LENGTH_PX * view.worldPerPixel(tmpC);
    tmpA.fromArray(axis).multiplyScalar(half);
    const pos = this.geometry.getAttribute('position');
    pos.setXYZ(0, tmpC.x - tmpA.x, tmpC.y - tmpA.y, tmpC.z - tmpA.z);
    pos.setXYZ(1, tmpC.x + tmpA.x, tmpC.y + tmpA.y, tmpC.z + tmpA.z);
    pos.needsUpdate = true;
    this.geometry.computeBoundingSphere();
    // Dashes of about 8 px, gaps of about 5 px.
    this.line.material.dashSize = 8 * view.worldPerPixel(tmpC);
    this.line.material.gapSize = 5 * view.worldPerPixel(tmpC);
    this.line.computeLineDistances();
  }
}
