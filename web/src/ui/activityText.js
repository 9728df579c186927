// The words of the Participants panel's activity list: what a co-designer's edit did, in the words
// the panels use (crease board, Crease panel, Fold slider), one line per journalled edit.
//
// Drags, fold moves, presence and pings are not listed one message at a time: a drag is listed
// once at its release ("moved …"), a fold gesture at its let-go ("folded the sheet to 64 %").

import { targetLabel } from '../commands/Command.js';
import { foldAngleMagnitude } from '../geometry/creaseDrawing.js';

/** The messages that are shown live (or are no edit) and get no line of their own. */
export const UNLISTED_MESSAGES = new Set(['join', 'presence', 'ping', 'drag', 'fold']);

/** What a drawn line of each assignment is called (M and V fold; F does not; C is cut). */
const LINE_WORDS = { M: 'mountain crease', V: 'valley crease', F: 'flat line', C: 'cut' };
const CREASE_WORDS = { fold: 'a curved fold', geodesic: 'a geodesic crease', smooth: 'smooth', none: 'free (no condition)' };

const plural = (n, one, many = `${one}s`) => `${n} ${n === 1 ? one : many}`;
const percent = (x) => `${Math.round(Number(x) * 100)} %`;
const keysOf = (obj) => Object.keys(obj || {}).map((k) => k.replace(/_/g, ' '));

/**
 * "valley crease (90°)": a drawn line's kind, with the angle a crease folds to (absent: 180°, a
 * curved one 90°, as foldAngleMagnitude).
 */
function lineWords(e) {
  const what = LINE_WORDS[e.assignment] || 'line';
  if (e.assignment !== 'M' && e.assignment !== 'V') return what;
  const curved = e.type === 'draw_crease' && e.curved === true;
  return `${what} (${foldAngleMagnitude({ assignment: e.assignment, fold_angle: e.fold_angle, curved })}°)`;
}

/**
 * One line for an edit a participant made (the `edit` of an `edit` message), without the name.
 * @param {object} e  the edit, as the server broadcasts it (a client message without `op`)
 * @param {{foldAmount?: number}} [context]  foldAmount: the last amount this participant's fold
 *        gesture sent (its `fold_end` carries none)
 * @returns {string|null}  null for the messages of UNLISTED_MESSAGES and unknown types
 */
export function describeEdit(e, context = {}) {
  if (!e || typeof e.type !== 'string' || UNLISTED_MESSAGES.has(e.type)) return null;
  const describe = {
    set_fixed: () => `${e.fixed ? 'fixed' : 'freed'} ${targetLabel(e.target)}`,
    add_handle: () => `added a handle at ${targetLabel(e.target)}`,
    remove_handle: () => `removed the handle of ${targetLabel(e.target)}`,
    set_solver: () => `changed ${[...keysOf(e.solver), ...['drag_iterations', 'release_iterations', 'normals'].filter((k) => k in e).map((k) => k.replace(/_/g, ' '))].join(', ')}`,
    set_params: () => `changed ${keysOf(e.params).join(', ')}`,
    set_units: () => `set the units to ${e.units}`,
    solve: () => (e.iterations ? `solved (at most ${e.iterations} iterations)` : 'solved'),
    undo: () => 'undid an edit',
    redo: () => 'redid an edit',
    reset: () => 'reset the scene',
    drag_end: () => `moved ${targetLabel(e.target)}`,
    fold_end: () => (Number.isFinite(context.foldAmount) ? `folded the sheet to ${percent(context.foldAmount)}` : 'moved the fold slider'),
    rotate_points: () => `turned ${plural((e.targets || []).length, 'point')} by ${e.angle}°`,
    set_crease: () => `made edge ${e.edge} ${CREASE_WORDS[e.crease] || e.crease}`,
    draw_crease: () => `drew a ${e.curved ? 'curved' : 'straight'} ${lineWords(e)}`,
    erase_crease: () => `erased crease ${e.crease}`,
    relabel_crease: () => `made crease ${e.crease} a ${lineWords(e)}`,
    reshape_crease: () => `reshaped crease ${e.crease}${e.curved === undefined ? '' : e.curved ? ' (curved)' : ' (straight)'}`,
    add_control_point: () => `added a control point to edge ${e.edge}`,
    remove_control_point: () => `removed control point ${e.index} of edge ${e.edge}`,
    relabel_edge: () => {
      const edges = e.edges || [];
      return `made edge${edges.length > 1 ? 's' : ''} ${edges.join(', ')} ${e.label === 'S' ? 'curved (S)' : 'a ruling (R)'}`;
    },
    split_face: () => `split face ${e.face}`,
    merge_faces: () => `joined the faces of edge ${e.edge}`,
    split_along_ruling: () => `cut the strips of edge ${e.edge} by a ruling${Number.isFinite(e.at) ? ` at ${percent(e.at)}` : ''}`,
    split_edge: () => `added a vertex on edge ${e.edge}`,
    remove_vertex: () => `removed vertex ${e.vertex}`,
  }[e.type];
  return describe ? describe() : null;
}
