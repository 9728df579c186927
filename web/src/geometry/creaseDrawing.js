// The maths of the crease-pattern drawing board (pure, no DOM): strokes of a scene's drawing as
// polylines (a curved stroke as a centripetal Catmull-Rom spline through its points, or its
// polyline when it has many), the fit of the sheet into a board, snapping a point to stroke
// vertices and then onto strokes, the sheet's outline loops and whether a point lies on the sheet,
// picking a stroke, and where a point is inserted into a stroke.
//
// Sheet coordinates: x right, y up (the scene's units). Screen coordinates: CSS px, y down.

/** Origami Simulator's colours (darkened where they would vanish on paper), dashes as the Development view. */
export const STROKE_STYLES = {
  B: { color: '#151820', width: 2, dash: '' },
  M: { color: '#d62828', width: 2.4, dash: '9 3 2 3' },
  V: { color: '#1d6fd6', width: 2.4, dash: '6 4' },
  F: { color: '#c99a06', width: 1.8, dash: '2 3' },
  C: { color: '#2b9348', width: 2.4, dash: '' },
};
/** Fold angle magnitude of new M and V creases (degrees). */
export const DEFAULT_FOLD_ANGLE = 90;
/** Fold angle magnitude of an M or V stroke without one: a full fold (scene schema, the server). */
export const ABSENT_FOLD_ANGLE = 180;
/**
 * What a curved M or V crease at a full fold (180°, or none given) aims at: only a straight crease
 * lays its sides onto each other (the server's composite::kCurvedFullFoldDeg).
 */
export const CURVED_FULL_FOLD_ANGLE = 90;
/**
 * A curved stroke with this many points or more is drawn as its polyline (an SVG curve, already
 * sampled), as the server does (composite::DrawingOptions::curveSegments = 16).
 */
export const CURVE_POLYLINE_POINTS = 17;
/** Snapping distance (screen px). */
export const SNAP_PX = 10;
/** Samples per span of a Catmull-Rom curve. */
const SPAN_SAMPLES = 12;

const dist = (a, b) => Math.hypot(a[0] - b[0], a[1] - b[1]);
export { dist };

/** The strokes of a scene's drawing, or null when the scene has none. */
export function drawingStrokes(scene) {
  const d = scene && scene.model && scene.model.drawing;
  return d && Array.isArray(d.strokes) ? d.strokes : null;
}

/**
 * The diagonal of the sheet a scene is drawn on (the bounding box of its drawing's points, in
 * scene units), or null for a scene without a drawing. Folding does not change it.
 */
export function drawingDiagonal(scene) {
  const strokes = drawingStrokes(scene);
  if (!strokes) return null;
  let [x0, y0, x1, y1] = [Infinity, Infinity, -Infinity, -Infinity];
  for (const s of strokes) {
    for (const p of s.points || []) {
      if (!Number.isFinite(p[0]) || !Number.isFinite(p[1])) continue;
      x0 = Math.min(x0, p[0]); x1 = Math.max(x1, p[0]);
      y0 = Math.min(y0, p[1]); y1 = Math.max(y1, p[1]);
    }
  }
  const d = Math.hypot(x1 - x0, y1 - y0);
  return d > 0 && Number.isFinite(d) ? d : null;
}

/**
 * The fold angle magnitude a stroke aims at (degrees): |fold_angle|, 180 for M/V without, 90 for a
 * curved one at 180 or without; undefined for others.
 */
export function foldAngleMagnitude(stroke) {
  if (!stroke || (stroke.assignment !== 'M' && stroke.assignment !== 'V')) return undefined;
  const a = stroke.fold_angle;
  const magnitude = typeof a === 'number' && Number.isFinite(a) && a !== 0 ? Math.abs(a) : ABSENT_FOLD_ANGLE;
  return stroke.curved && magnitude >= 180 ? CURVED_FULL_FOLD_ANGLE : magnitude;
}

/**
 * A centripetal Catmull-Rom spline through `points` (closed: back to the first): {points, span},
 * span[k] = index of the input point the k-th segment of the polyline starts after.
 */
export function catmullRom(points, closed = false, samples = SPAN_SAMPLES) {
  const n = points.length;
  if (n < 3) return { points: points.map((p) => [p[0], p[1]]), span: n === 2 ? [0] : [] };
  const at = (i) => {
    if (closed) return points[((i % n) + n) % n];
    if (i < 0) return [2 * points[0][0] - points[1][0], 2 * points[0][1] - points[1][1]];
    if (i >= n) return [2 * points[n - 1][0] - points[n - 2][0], 2 * points[n - 1][1] - points[n - 2][1]];
    return points[i];
  };
  const out = [[points[0][0], points[0][1]]];
  const span = [];
  const spans = closed ? n : n - 1;
  for (let i = 0; i < spans; i++) {
    const p0 = at(i - 1), p1 = at(i), p2 = at(i + 1), p3 = at(i + 2);
    const knot = (a, b) => Math.max(Math.sqrt(dist(a, b)), 1e-12);
    const t1 = knot(p0, p1), t2 = t1 + knot(p1, p2), t3 = t2 + knot(p2, p3);
    const lerp = (a, b, ta, tb, t) => {
      const w = (t - ta) / (tb - ta);
      return [a[0] + (b[0] - a[0]) * w, a[1] + (b[1] - a[1]) * w];
    };
    for (let k = 1; k <= samples; k++) {
      if (k === samples) {
        out.push([p2[0], p2[1]]);
      } else {
        const t = t1 + ((t2 - t1) * k) / samples;
        const a1 = lerp(p0, p1, 0, t1, t), a2 = lerp(p1, p2, t1, t2, t), a3 = lerp(p2, p3, t2, t3, t);
        const b1 = lerp(a1, a2, 0, t2, t), b2 = lerp(a2, a3, t1, t3, t);
        out.push(lerp(b1, b2, t1, t2, t));
      }
      span.push(i);
    }
  }
  return { points: out, span };
}

/** A stroke as drawn: {points, span} (see catmullRom); closed strokes end where they start. */
export function strokePolyline(stroke) {
  const pts = (stroke && stroke.points) || [];
  const closed = !!stroke.closed;
  if (stroke.curved && pts.length >= 3 && pts.length < CURVE_POLYLINE_POINTS) return catmullRom(pts, closed);
  const out = pts.map((p) => [p[0], p[1]]);
  const span = pts.slice(1).map((_, i) => i);
  if (closed && pts.length > 2) {
    out.push([pts[0][0], pts[0][1]]);
    span.push(pts.length - 1);
  }
  return { points: out, span };
}

/** Per stroke: {index, assignment, vertices (its points), polyline, span}. */
export function strokeGeometry(strokes) {
  return (strokes || []).map((s, index) => {
    const line = strokePolyline(s);
    return { index, assignment: s.assignment, closed: !!s.closed, vertices: s.points || [], polyline: line.points, span: line.span };
  });
}

/** Bounding box {x0, y0, x1, y1} of the outline strokes (all strokes when there is none), or null. */
export function sheetBounds(geometry) {
  const outline = geometry.filter((g) => g.assignment === 'B');
  let x0 = Infinity, y0 = Infinity, x1 = -Infinity, y1 = -Infinity;
  for (const g of outline.length ? outline : geometry) {
    for (const p of g.polyline) {
      if (p[0] < x0) x0 = p[0];
      if (p[0] > x1) x1 = p[0];
      if (p[1] < y0) y0 = p[1];
      if (p[1] > y1) y1 = p[1];
    }
  }
  return x0 <= x1 && y0 <= y1 ? { x0, y0, x1, y1 } : null;
}

/**
 * The fit of bounds `b` into W × H px with `margin`: {scale (px per unit), cx, cy (sheet point at
 * the centre), ox, oy (that centre in px)}.
 */
export function fitTransform(b, W, H, margin = 24) {
  const bw = Math.max(b.x1 - b.x0, 1e-9);
  const bh = Math.max(b.y1 - b.y0, 1e-9);
  const scale = Math.max(1e-9, Math.min((W - 2 * margin) / bw, (H - 2 * margin) / bh));
  return { scale, cx: (b.x0 + b.x1) / 2, cy: (b.y0 + b.y1) / 2, ox: W / 2, oy: H / 2 };
}

export function toScreen(t, p) {
  return [t.ox + (p[0] - t.cx) * t.scale, t.oy - (p[1] - t.cy) * t.scale];
}

export function toSheet(t, q) {
  return [t.cx + (q[0] - t.ox) / t.scale, t.cy - (q[1] - t.oy) / t.scale];
}

/** The point of segment ab nearest to p: {point, t, distance}. */
export function nearestOnSegment(p, a, b) {
  const dx = b[0] - a[0], dy = b[1] - a[1];
  const len2 = dx * dx + dy * dy;
  let t = len2 > 0 ? ((p[0] - a[0]) * dx + (p[1] - a[1]) * dy) / len2 : 0;
  t = Math.max(0, Math.min(1, t));
  const point = [a[0] + t * dx, a[1] + t * dy];
  return { point, t, distance: dist(p, point) };
}

/** The point of a polyline nearest to p: {point, segment, distance} (null for fewer than 2 points). */
export function nearestOnPolyline(p, poly) {
  let best = null;
  for (let k = 0; k + 1 < poly.length; k++) {
    const r = nearestOnSegment(p, poly[k], poly[k + 1]);
    if (!best || r.distance < best.distance) best = { point: r.point, segment: k, distance: r.distance };
  }
  return best;
}

/**
 * Snaps p to the nearest stroke vertex within `tolerance` (sheet units), else to the nearest point
 * on a stroke within it: {point, kind: 'vertex'|'stroke'|null, stroke (index or -1)}. Stroke
 * `exclude` is left out (the stroke whose point is being moved).
 */
export function snapPoint(p, geometry, tolerance, { exclude = -1 } = {}) {
  let best = null;
  for (const g of geometry) {
    if (g.index === exclude) continue;
    for (const v of g.vertices) {
      const d = dist(p, v);
      if (d <= tolerance && (!best || d < best.distance)) best = { point: [v[0], v[1]], kind: 'vertex', stroke: g.index, distance: d };
    }
  }
  if (best) return best;
  for (const g of geometry) {
    if (g.index === exclude) continue;
    const r = nearestOnPolyline(p, g.polyline);
    if (r && r.distance <= tolerance && (!best || r.distance < best.distance)) best = { point: r.point, kind: 'stroke', stroke: g.index, distance: r.distance };
  }
  return best || { point: [p[0], p[1]], kind: null, stroke: -1, distance: 0 };
}

/**
 * The sheet's outline as loops of points: closed outline strokes as they are, open ones chained
 * end to end (within `tolerance`); a chain that does not close is closed by its last segment.
 */
export function outlineLoops(geometry, tolerance = 1e-6) {
  const loops = [];
  const pieces = [];
  for (const g of geometry) {
    if (g.assignment !== 'B' || g.polyline.length < 2) continue;
    if (g.closed) loops.push(g.polyline.slice());
    else pieces.push(g.polyline.slice());
  }
  while (pieces.length) {
    let chain = pieces.shift();
    let grown = true;
    while (grown && dist(chain[0], chain[chain.length - 1]) > tolerance) {
      grown = false;
      const end = chain[chain.length - 1];
      for (let i = 0; i < pieces.length; i++) {
        const q = pieces[i];
        if (dist(q[0], end) <= tolerance) chain = chain.concat(q.slice(1));
        else if (dist(q[q.length - 1], end) <= tolerance) chain = chain.concat(q.slice(0, -1).reverse());
        else continue;
        pieces.splice(i, 1);
        grown = true;
        break;
      }
    }
    if (chain.length >= 3) loops.push(chain);
  }
  return loops;
}

/** Whether p lies on the sheet: inside its outline loops (even-odd) or within `tolerance` of them. */
export function insideSheet(p, loops, tolerance = 0) {
  if (!loops.length) return true;
  let inside = false;
  for (const loop of loops) {
    const n = loop.length;
    for (let i = 0, j = n - 1; i < n; j = i++) {
      const a = loop[i], b = loop[j];
      if ((a[1] > p[1]) !== (b[1] > p[1]) && p[0] < ((b[0] - a[0]) * (p[1] - a[1])) / (b[1] - a[1]) + a[0]) inside = !inside;
      if (tolerance > 0 && nearestOnSegment(p, a, b).distance <= tolerance) return true;
    }
  }
  return inside;
}

/**
 * The stroke a click at p picks: the nearest crease within `tolerance`, else the nearest outline
 * stroke within it; -1 for none.
 */
export function hitStroke(p, geometry, tolerance) {
  let crease = null;
  let outline = null;
  for (const g of geometry) {
    const r = nearestOnPolyline(p, g.polyline);
    if (!r || r.distance > tolerance) continue;
    if (g.assignment === 'B') {
      if (!outline || r.distance < outline.distance) outline = { index: g.index, distance: r.distance };
    } else if (!crease || r.distance < crease.distance) {
      crease = { index: g.index, distance: r.distance };
    }
  }
  return crease ? crease.index : outline ? outline.index : -1;
}

/** The point of `points` within `tolerance` of p (the nearest), or -1. */
export function hitPoint(p, points, tolerance) {
  let best = -1;
  let bestD = Infinity;
  points.forEach((q, k) => {
    const d = dist(p, q);
    if (d <= tolerance && d < bestD) {
      best = k;
      bestD = d;
    }
  });
  return best;
}

/** Where a point at p goes into a stroke (its geometry g): the index it takes among the points. */
export function insertionIndex(g, p) {
  const r = nearestOnPolyline(p, g.polyline);
  if (!r) return g.vertices.length;
  return g.span[r.segment] + 1;
}

/**
 * The `curved` flag of a reshaped stroke with `count` points: 2 points are straight, a curved
 * stroke stays curved, a straight crease given a third point becomes curved; undefined (the
 * server keeps the stroke's own) for a polyline stroke.
 */
export function reshapedCurved(stroke, count) {
  if (count === 2) return false;
  if (stroke.curved) return true;
  if ((stroke.points || []).length === 2 && count === 3) return true;
  return undefined;
}

/** p rounded to a power of ten no larger than `resolution` (sheet units), without float noise. */
export function roundPoint(p, resolution) {
  if (!(resolution > 0) || !Number.isFinite(resolution)) return [p[0], p[1]];
  const step = Math.pow(10, Math.floor(Math.log10(resolution)));
  return p.map((v) => Number((Math.round(v / step) * step).toPrecision(12)));
}

/** A grid step (sheet units) whose lines lie at least `minPx` apart at `scale` px per unit: 1, 2, 5 × 10^k. */
export function gridStep(scale, minPx = 18) {
  const target = minPx / scale;
  const p = Math.pow(10, Math.floor(Math.log10(target)));
  for (const m of [1, 2, 5, 10]) if (m * p >= target) return m * p;
  return 10 * p;
}
