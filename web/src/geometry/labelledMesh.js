// The labelled mesh of a composite scene (model.faces: loops of edge indices; model.edges[k]:
// {v: [v0, v1], type: 'R' | 'S'}): what the Crease panel's edits of it act on.

/** The corners of face f in loop order (corner k: where loop edges k − 1 and k meet). */
export function faceCorners(model, f) {
  const loop = model.faces[f];
  const n = loop.length;
  return loop.map((e, k) => {
    const a = model.edges[loop[(k + n - 1) % n]].v;
    const b = model.edges[e].v;
    return a[0] === b[0] || a[0] === b[1] ? a[0] : a[1];
  });
}

/**
 * The edges to relabel with `edge` so its faces keep a valid type: the edge, and with `opposite`
 * the side across each of its four-sided faces that has the same label (a strip's other curve, a
 * planar quad's opposite side).
 */
export function relabelGroup(model, edge, opposite = true) {
  const group = [edge];
  if (!opposite) return group;
  const label = model.edges[edge].type;
  model.faces.forEach((loop) => {
    const i = loop.indexOf(edge);
    if (i < 0 || loop.length !== 4) return;
    const across = loop[(i + 2) % 4];
    if (model.edges[across].type === label && !group.includes(across)) group.push(across);
  });
  return group;
}

/**
 * The face two vertices can split: one where both are corners and not neighbours along its
 * loop, and no edge joins them yet. → {face, vertices: [a, b]} or null.
 */
export function splitCandidate(model, a, b) {
  if (a === b) return null;
  if (model.edges.some((e) => (e.v[0] === a && e.v[1] === b) || (e.v[0] === b && e.v[1] === a))) return null;
  for (let f = 0; f < model.faces.length; f++) {
    const corners = faceCorners(model, f);
    const i = corners.indexOf(a);
    const j = corners.indexOf(b);
    if (i < 0 || j < 0) continue;
    const n = corners.length;
    if ((i + 1) % n === j || (j + 1) % n === i) continue;
    return { face: f, vertices: [a, b] };
  }
  return null;
}
