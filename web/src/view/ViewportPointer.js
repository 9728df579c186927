// Pointer handling of the 3D view (Viewport): control points are picked with a Raycaster on the
// point sprites (a few px of slack around their drawn radius; where the buffers rank points,
// `pickPriority`, the higher rank wins: a spline's control points over the vertices of its
// refined mesh) and dragged in the view plane through the point: pointerdown on a point switches
// orbiting off and selects it (an edge marker selects its edge; `pointDown` may take the press
// first, e.g. gluing picks), pointermove sends at most one DragCommand per animation frame
// (latest wins, DragCommandStream), pointerup sends the last position and a DragEndCommand.
// Shift/Ctrl/⌘-click on a point of a composite adds it to / removes it from the group selection
// (`toggleGroup`; no drag, no pan); elsewhere those modifiers still pan.
// A view-only editor (role 'view') selects points but starts no drag: nothing to send that the
// server would refuse. Hovering sets the cursor; a click on empty space clears the selection. The view draws what this
// sets on it: view.drag ({target, pointerId, plane, offset, position: the dragged point's latest
// position, commands}) and view.hovered.

import * as THREE from 'three';
import { sameTarget as sameEntry } from '../commands/Command.js';
import { DragCommandStream } from './DragCommandStream.js';
import { constrainedDragPosition } from './dragConstraint.js';

/** Keys while dragging: an axis, or with Shift the coordinate plane across it. */
const CONSTRAINT_KEYS = { x: 'x', y: 'y', z: 'z', X: 'yz', Y: 'zx', Z: 'xy' };

/** Same point target, or the same edge marker ({edgeMarker: e}). */
export function sameTarget(a, b) {
  if (!a || !b) return false;
  if (a.edgeMarker !== undefined || b.edgeMarker !== undefined) return a.edgeMarker === b.edgeMarker;
  return sameEntry(a, b);
}

export class ViewportPointer {
  /**
   * Listens to the view's canvas (and, in the capture phase, its container).
   * @param {import('./Viewport.js').Viewport} view
   * @param {object} options {pickSlackPx: how far outside a point's drawn radius a press still picks it}
   */
  constructor(view, { pickSlackPx }) {
    this.view = view;
    this.pickSlackPx = pickSlackPx;
    this._downAt = null;
    this._hoverEvent = null;
    this._hoverRaf = 0;
    this._bind();
  }

  _ndc(event) {
    const view = this.view;
    const rect = view.canvas.getBoundingClientRect();
    return new THREE.Vector2(((event.clientX - rect.left) / rect.width) * 2 - 1, -((event.clientY - rect.top) / rect.height) * 2 + 1);
  }

  /** Whether this editor may move points (it joined with an edit token and is connected). */
  editable() {
    const st = this.view.state;
    return !!st && st.canEdit;
  }

  /** The control point under the pointer: a Raycaster on the point sprites, a few px tolerance. */
  pick(event) {
    const view = this.view;
    if (!view.activeBuffers().hasData || !view.canvas) return null;
    view.layoutInstances();
    view.camera.updateMatrixWorld();
    const raycaster = new THREE.Raycaster();
    raycaster.setFromCamera(this._ndc(event), view.camera);
    const b = view.activeBuffers();
    const priority = b.pickPriority ? (item) => (item.edgeMarker !== undefined ? 0 : b.pickPriority(item)) : null;
    return view.points.pick(raycaster, (p) => view.worldPerPixel(p), this.pickSlackPx, priority);
  }

  _bind() {
    const view = this.view;
    const canvas = view.canvas;
    // Capture phase on the container: runs before OrbitControls' listener on the canvas, so a
    // press on a control point can switch orbiting off before it starts.
    view.container.addEventListener('pointerdown', (e) => this._onPointerDown(e), { capture: true });
    canvas.addEventListener('pointermove', (e) => this._onPointerMove(e));
    canvas.addEventListener('pointerup', (e) => this._onPointerUp(e));
    canvas.addEventListener('pointercancel', (e) => this._onPointerUp(e));
    // The connection dropped mid-drag: the drag is over (every frame would raise "not sent").
    if (view.state) view.state.on('editable', (editable) => { if (!editable) this._endDrag(true); });
    canvas.addEventListener('pointerleave', () => {
      if (!view.drag && view.hovered) {
        view.hovered = null;
        view.requestRender();
      }
    });
    canvas.addEventListener('contextmenu', (e) => e.preventDefault());
    // X, Y, Z while dragging hold the drag to that axis (Shift: the plane across it); again: free.
    window.addEventListener('keydown', (e) => {
      const c = CONSTRAINT_KEYS[e.key];
      const st = view.state;
      if (!c || !view.drag || !st || e.ctrlKey || e.metaKey || e.altKey) return;
      const current = (st.dragOptions && st.dragOptions.constraint) || 'free';
      st.dragOptions = { ...(st.dragOptions || {}), constraint: current === c ? 'free' : c };
      st.emit('drag-options', st.dragOptions);
      e.preventDefault();
      e.stopPropagation();
    }, { capture: true });
  }

  _onPointerDown(e) {
    const view = this.view;
    if (e.target !== view.canvas) return;
    const modified = e.ctrlKey || e.metaKey || e.shiftKey;
    this._downAt = { x: e.clientX, y: e.clientY, modified };
    if (e.button === 0 && modified) {
      this._groupPress(e);
      return;
    }
    if (e.button !== 0) return;
    const hit = this.pick(e);
    if (!hit) {
      view.controls.enabled = true;
      return;
    }
    e.preventDefault();
    if (hit.edgeMarker !== undefined) {
      // Edge markers select the edge (crease panel); they are not dragged.
      view.selectEdge(hit.edgeMarker);
      view.controls.enabled = true;
      this._downAt = null;
      return;
    }
    if (view.pointDown(hit)) {
      view.controls.enabled = true;
      this._downAt = null;
      view.requestRender();
      return;
    }
    view.select(hit);
    if (!this.editable()) {
      // A view-only editor selects the point (its coordinates are shown) but cannot move it: no
      // drag, nothing sent; the press orbits the camera as on empty space.
      view.controls.enabled = true;
      view.requestRender();
      return;
    }
    if (view.state && view.state.isFixed(hit)) {
      // A fixed point does not move: a drag would only pull against it (and its release would
      // take the sheet's fold as the design's, a fold the drag did not change). The press selects
      // it; a drag from it moves nothing (not even the camera) and says how to move it.
      this._fixedPress = { x: e.clientX, y: e.clientY, pointerId: e.pointerId, told: false };
      view.controls.enabled = false;
      view.requestRender();
      return;
    }
    view.controls.enabled = false;
    const p = view.activeBuffers().pointOf(hit);
    const point = new THREE.Vector3(p[0], p[1], p[2]);
    const normal = view.camera.getWorldDirection(new THREE.Vector3());
    const plane = new THREE.Plane().setFromNormalAndCoplanarPoint(normal, point);
    const onPlane = this._rayOnPlane(e, plane) || point.clone();
    view.drag = {
      target: hit,
      start: [p[0], p[1], p[2]],
      plane,
      offset: point.clone().sub(onPlane),
      pointerId: e.pointerId,
      position: null,
      commands: new DragCommandStream((c) => view.send(c), hit, 'viewport'),
    };
    try { view.canvas.setPointerCapture(e.pointerId); } catch { /* synthetic events */ }
    view.canvas.style.cursor = 'grabbing';
    view.requestRender();
  }

  /** Shift/Ctrl/⌘ + press on a point: toggles it in the group selection (OrbitControls stay out). */
  _groupPress(e) {
    const view = this.view;
    const hit = this.pick(e);
    if (!hit || hit.edgeMarker !== undefined || !view.toggleGroup(hit)) return;
    e.preventDefault();
    view.controls.enabled = false;
    this._downAt = null;
    view.requestRender();
  }

  _rayOnPlane(e, plane) {
    const view = this.view;
    const raycaster = new THREE.Raycaster();
    raycaster.setFromCamera(this._ndc(e), view.camera);
    return raycaster.ray.intersectPlane(plane, new THREE.Vector3());
  }

  _onPointerMove(e) {
    const view = this.view;
    const fixed = this._fixedPress;
    if (fixed && e.pointerId === fixed.pointerId) {
      if (!fixed.told && Math.hypot(e.clientX - fixed.x, e.clientY - fixed.y) >= 4) {
        fixed.told = true;
        view.state.emit('notice', 'This point is fixed: unfix it (F) to drag it.');
      }
      return;
    }
    const d = view.drag;
    if (d) {
      if (e.pointerId !== d.pointerId) return;
      const hit = this._rayOnPlane(e, d.plane);
      if (!hit) return;
      d.position = hit.add(d.offset);
      // Exact input: held to an axis or plane through the start, snapped to the grid.
      const options = view.state && view.state.dragOptions;
      if (options && (options.constraint !== 'free' || options.snap)) {
        const raycaster = new THREE.Raycaster();
        raycaster.setFromCamera(this._ndc(e), view.camera);
        const ray = { origin: raycaster.ray.origin.toArray(), direction: raycaster.ray.direction.toArray() };
        d.position.fromArray(constrainedDragPosition(d.start, d.position.toArray(), ray, options));
      }
      // At most one drag message per animation frame; the latest position wins.
      d.commands.move([d.position.x, d.position.y, d.position.z]);
      view.requestRender();
      return;
    }
    if (e.buttons) return;
    // Hover feedback, at most once per frame.
    this._hoverEvent = e;
    if (!this._hoverRaf) {
      this._hoverRaf = requestAnimationFrame(() => {
        this._hoverRaf = 0;
        const hit = this.pick(this._hoverEvent);
        view.canvas.style.cursor = hit ? (this.editable() ? 'grab' : 'pointer') : '';
        if (!sameTarget(hit, view.hovered)) {
          view.hovered = hit;
          view.requestRender();
        }
      });
    }
  }

  /**
   * Ends the drag in progress: its release is sent (`drag_end`), or, when the connection dropped
   * (`abandon`), nothing more is.
   */
  _endDrag(abandon) {
    const view = this.view;
    const d = view.drag;
    if (!d) return;
    if (abandon) d.commands.abandon();
    else d.commands.end();
    view.drag = null;
    view.controls.enabled = true;
    try { view.canvas.releasePointerCapture(d.pointerId); } catch { /* ignore */ }
    view.canvas.style.cursor = 'grab';
    view.requestRender();
  }

  _onPointerUp(e) {
    const view = this.view;
    const d = view.drag;
    if (d) {
      if (e.pointerId === d.pointerId) this._endDrag(false);
      return;
    }
    this._fixedPress = null;
    view.controls.enabled = true;
    // A click (no orbit) on empty space clears the selection (with Shift/Ctrl/⌘: keeps it).
    if (this._downAt && !this._downAt.modified && e.button === 0 && Math.hypot(e.clientX - this._downAt.x, e.clientY - this._downAt.y) < 4) {
      if (!this.pick(e)) view.select(null);
    }
    this._downAt = null;
  }
}
