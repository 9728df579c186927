// The glue list of a quad_mesh scene edited as a value: a `set_params` glue replaces the whole list,
// so every edit builds the next list from the current one. A scene writes pairs of M as bare
// [i, j] items and the pairs of M′ as {on: 'unfolding', pairs} (older scenes: {on, pairs} groups
// for both); the edits work on groups [{on: 'mesh'|'unfolding', pairs: [[i, j], …]}], which the
// message's params.glue takes. Pure functions; the command is a SetParamsCommand.

import { SetParamsCommand } from './SetParamsCommand.js';

const sides = ['mesh', 'unfolding'];

/**
 * A copy of a scene's glue list as groups, `on` filled in and pairs copied; the scene's bare pairs
 * of M form one group, where the first of them stands.
 */
export function normalizedGlue(glue) {
  const groups = [];
  let bare = null;
  for (const g of Array.isArray(glue) ? glue : []) {
    if (Array.isArray(g)) {
      if (!bare) groups.push((bare = { on: 'mesh', pairs: [] }));
      bare.pairs.push([g[0], g[1]]);
    } else if (g && typeof g === 'object') {
      groups.push({ on: g.on || 'mesh', pairs: (g.pairs || []).map((p) => [p[0], p[1]]) });
    }
  }
  return groups;
}

/** Every glued pair in list order: [{on, pair: [i, j], group, index}] (group/index locate it). */
export function gluePairList(glue) {
  const out = [];
  normalizedGlue(glue).forEach((g, group) => g.pairs.forEach((pair, index) => out.push({ on: g.on, pair, group, index })));
  return out;
}

/** Whether vertices a and b are already glued to each other on `on`. */
export function isGlued(glue, on, a, b) {
  return gluePairList(glue).some((p) => p.on === on && ((p.pair[0] === a && p.pair[1] === b) || (p.pair[0] === b && p.pair[1] === a)));
}

/**
 * The glue list with pair (a, b) appended on `on` (to the last group of that side, or a new group).
 * Throws a TypeError for a vertex glued to itself or a pair already glued.
 */
export function withGluePair(glue, on, a, b) {
  if (!sides.includes(on)) throw new TypeError(`glue: on must be mesh or unfolding, not ${on}`);
  if (!Number.isInteger(a) || !Number.isInteger(b) || a < 0 || b < 0) throw new TypeError('glue: expected two vertex indices');
  if (a === b) throw new TypeError(`glue: vertex ${a} cannot be glued to itself`);
  if (isGlued(glue, on, a, b)) throw new TypeError(`glue: vertices ${a} and ${b} are already glued`);
  const next = normalizedGlue(glue);
  let group = -1;
  next.forEach((g, k) => { if (g.on === on) group = k; });
  if (group < 0) next.push({ on, pairs: [[a, b]] });
  else next[group].pairs.push([a, b]);
  return next;
}

/** The glue list without the pair at (group, index); groups left empty are dropped. */
export function withoutGluePair(glue, group, index) {
  const next = normalizedGlue(glue);
  if (!next[group] || !next[group].pairs[index]) throw new RangeError(`glue: no pair ${index} in group ${group}`);
  next[group].pairs.splice(index, 1);
  return next.filter((g) => g.pairs.length > 0);
}

/** The set_params command that replaces the glue list. */
export function glueCommand(glue, options) {
  const command = new SetParamsCommand('quad_mesh', { glue }, options);
  command.name = 'glue';
  return command;
}
