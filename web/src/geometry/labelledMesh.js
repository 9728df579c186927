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

/**
 * Why a face whose sides have these labels (loop order, 'R' | 'S') is no face type of a
 * composite, in words; null when it is one. The types (solver CompositeTopology): planar (no S),
 * a cone (S R R), a strip (S R S R, its curves opposite) or a strip narrowed to a point (S R S).
 */
export function faceTypeProblem(labels) {
  const n = labels.length;
  const curved = labels.filter((l) => l === 'S').length;
  if (curved === 0) return null;
  if (curved > 2) return `it would have ${curved} curved (S) sides; a face has at most two`;
  if (curved === 1) return n === 3 ? null : `it would have one curved (S) side among ${n}; only a triangle (a cone: S R R) has one`;
  if (n === 3) return null;
  if (n !== 4) return `with two curved (S) sides it would have ${n} sides; a strip has four (S R S R) or three (S R S)`;
  const i = labels.indexOf('S');
  return labels[(i + 2) % 4] === 'S' ? null : 'its two curved (S) sides would meet at a corner; a strip\'s curves are opposite sides';
}

/**
 * Why relabelling `edges` as `label` leaves some face of no type ("face 2: …"), or null. The
 * server also checks what the labels alone do not say (the spline spaces of a strip's curves).
 */
export function relabelProblem(model, edges, label) {
  const changed = new Set(edges);
  for (let f = 0; f < model.faces.length; f++) {
    const loop = model.faces[f];
    if (!loop.some((e) => changed.has(e))) continue;
    const problem = faceTypeProblem(loop.map((e) => (changed.has(e) ? label : model.edges[e].type)));
    if (problem) return `face ${f}: ${problem}`;
  }
  return null;
}

/** Why the two faces of `edge` cannot become one face, or null (the labels alone, as above). */
export function mergeProblem(model, edge) {
  const faces = [];
  model.faces.forEach((loop, f) => { if (loop.includes(edge)) faces.push(f); });
  if (faces.length !== 2) return `edge ${edge} is on the outline: it has one face`;
  // Each loop from the side after the edge on: the joined face's sides in order.
  const rest = faces.map((f) => {
    const loop = model.faces[f];
    const i = loop.indexOf(edge);
    return [...loop.slice(i + 1), ...loop.slice(0, i)];
  });
  const problem = faceTypeProblem([...rest[0], ...rest[1]].map((e) => model.edges[e].type));
  return problem ? `faces ${faces[0]} and ${faces[1]} joined: ${problem}` : null;
}
