import { Command } from './Command.js';

const isIndex = (x) => Number.isInteger(x) && x >= 0;

/**
 * Composite sessions without a drawing: the edges become rulings ('R') or spline edges ('S'), as
 * a face type needs them together (a strip's two curves, a planar face's two opposite sides).
 */
export class RelabelEdgeCommand extends Command {
  constructor(edges, label, options) {
    super('relabel_edge', options);
    if (!Array.isArray(edges) || !edges.length || edges.length > 64 || !edges.every(isIndex)) {
      throw new TypeError('edges: expected 1 to 64 edge indices');
    }
    if (label !== 'R' && label !== 'S') throw new TypeError("label: expected 'R' or 'S'");
    this.edges = [...new Set(edges)];
    this.label = label;
    this.name = `make edge${this.edges.length > 1 ? 's' : ''} ${this.edges.join(', ')} ${label === 'S' ? 'splines (S)' : 'rulings (R)'}`;
  }

  fields() {
    return { edges: this.edges, label: this.label };
  }
}

/** Composite sessions without a drawing: a new ruling between two corners of a face splits it. */
export class SplitFaceCommand extends Command {
  constructor(face, vertices, options) {
    super('split_face', options);
    if (!isIndex(face)) throw new TypeError('face: expected an integer ≥ 0');
    if (!Array.isArray(vertices) || vertices.length !== 2 || !vertices.every(isIndex)) {
      throw new TypeError('vertices: expected two vertex indices');
    }
    this.face = face;
    this.vertices = vertices.slice();
    this.name = `split face ${face} between vertices ${vertices[0]} and ${vertices[1]}`;
  }

  fields() {
    return { face: this.face, vertices: this.vertices };
  }
}

/** Composite sessions without a drawing: interior edge `edge` goes and its two faces become one. */
export class MergeFacesCommand extends Command {
  constructor(edge, options) {
    super('merge_faces', options);
    if (!isIndex(edge)) throw new TypeError('edge: expected an integer ≥ 0');
    this.edge = edge;
    this.name = `join the faces of edge ${edge}`;
  }

  fields() {
    return { edge: this.edge };
  }
}

/**
 * Composite sessions without a drawing: a new ruling across the strip of S edge `edge`, at the
 * fraction `at` (0 < at < 1) of its curve, carried through every strip whose curves share that
 * spline space; each strip so cut becomes two. No curve moves.
 */
export class SplitAlongRulingCommand extends Command {
  constructor(edge, at = 0.5, options) {
    super('split_along_ruling', options);
    if (!isIndex(edge)) throw new TypeError('edge: expected an integer ≥ 0');
    if (!(Number.isFinite(at) && at > 0 && at < 1)) throw new TypeError('at: expected a fraction strictly between 0 and 1');
    this.edge = edge;
    this.at = at;
    this.name = `cut across the strips of edge ${edge} at ${Math.round(at * 100)} %`;
  }

  fields() {
    return { edge: this.edge, at: this.at };
  }
}

/** Composite sessions without a drawing: a new vertex on ruling `edge` at `at` from its v0. */
export class SplitEdgeCommand extends Command {
  constructor(edge, at = 0.5, options) {
    super('split_edge', options);
    if (!isIndex(edge)) throw new TypeError('edge: expected an integer ≥ 0');
    if (!(Number.isFinite(at) && at > 0 && at < 1)) throw new TypeError('at: expected a fraction strictly between 0 and 1');
    this.edge = edge;
    this.at = at;
    this.name = `add a vertex on edge ${edge}`;
  }

  fields() {
    return { edge: this.edge, at: this.at };
  }
}

/** Composite sessions without a drawing: vertex `vertex` between two rulings goes; they become one. */
export class RemoveVertexCommand extends Command {
  constructor(vertex, options) {
    super('remove_vertex', options);
    if (!isIndex(vertex)) throw new TypeError('vertex: expected an integer ≥ 0');
    this.vertex = vertex;
    this.name = `remove vertex ${vertex}`;
  }

  fields() {
    return { vertex: this.vertex };
  }
}
