import { readFileSync } from 'node:fs';
import { fileURLToPath } from 'node:url';
import { describe, expect, it } from 'vitest';
import { readdirSync } from 'node:fs';
import { faceCorners, faceTypeProblem, mergeProblem, relabelGroup, relabelProblem, splitCandidate } from '../src/geometry/labelledMesh.js';

const example = (name) => JSON.parse(readFileSync(fileURLToPath(new URL(`../../examples/${name}.json`, import.meta.url)), 'utf8')).model;

describe('the labelled mesh of a composite scene', () => {
  it('lists a face\'s corners where its loop edges meet', () => {
    const model = example('composite-curved-fold');
    for (let f = 0; f < model.faces.length; f++) {
      const corners = faceCorners(model, f);
      expect(corners).toHaveLength(model.faces[f].length);
      expect(new Set(corners).size).toBe(corners.length);
      model.faces[f].forEach((e, k) => {
        // Edge k runs between corners k and k + 1.
        const v = model.edges[e].v;
        expect(new Set(v)).toEqual(new Set([corners[k], corners[(k + 1) % corners.length]]));
      });
    }
  });

  it('relabels a strip\'s curve with the curves across its faces, a planar quad\'s side with the opposite side', () => {
    const fold = example('composite-curved-fold');
    const crease = fold.edges.findIndex((e, k) => e.type === 'S' && fold.faces.filter((l) => l.includes(k)).length === 2);
    const group = relabelGroup(fold, crease);
    expect(group[0]).toBe(crease);
    expect(group).toHaveLength(3); // the crease and the boundary curve of each of its two strips
    expect(group.every((e) => fold.edges[e].type === 'S')).toBe(true);
    expect(relabelGroup(fold, crease, false)).toEqual([crease]);
    const box = example('composite-curved-box');
    const planar = box.faces.find((l) => l.every((e) => box.edges[e].type === 'R'));
    expect(relabelGroup(box, planar[1]).sort()).toEqual([planar[1], planar[3]].sort());
  });

  it('splits a face only between corners that are not neighbours and not yet joined', () => {
    const box = example('composite-curved-box');
    const f = box.faces.findIndex((l) => l.every((e) => box.edges[e].type === 'R'));
    const c = faceCorners(box, f);
    expect(splitCandidate(box, c[0], c[2])).toEqual({ face: f, vertices: [c[0], c[2]] });
    expect(splitCandidate(box, c[0], c[1])).toBeNull();
    expect(splitCandidate(box, c[0], c[0])).toBeNull();
  });

  // The face types as patterns of labels round a face (any rotation, either direction): an
  // independent statement of what faceTypeProblem judges by counting.
  const FACE_TYPES = ['RRR', 'RRRR', 'RRRRR', 'RRRRRR', 'SRR', 'SRS', 'SRSR'];
  const rotations = (word) => [...word].map((_, k) => word.slice(k) + word.slice(0, k));
  const isFaceType = (labels) => {
    const word = labels.join('');
    const reversed = [...word].reverse().join('');
    return FACE_TYPES.some((t) => t.length === word.length && (rotations(word).includes(t) || rotations(reversed).includes(t)));
  };

  it('judges every labelling of a face of 3 to 6 sides as the face types say', () => {
    let judged = 0;
    for (let n = 3; n <= 6; n++) {
      for (let bits = 0; bits < 1 << n; bits++) {
        const labels = [...Array(n)].map((_, k) => ((bits >> k) & 1 ? 'S' : 'R'));
        const problem = faceTypeProblem(labels);
        expect(problem === null, labels.join(' ')).toBe(isFaceType(labels));
        if (problem) expect(problem, labels.join(' ')).toMatch(/curved \(S\)/);
        judged++;
      }
    }
    expect(judged).toBe(8 + 16 + 32 + 64);
  });

  const composites = readdirSync(fileURLToPath(new URL('../../examples/', import.meta.url)))
    .filter((f) => /^composite-.*\.json$/.test(f)).map((f) => f.replace(/\.json$/, ''));

  it('finds every face of every shipped composite preset a valid type', () => {
    expect(composites.length).toBeGreaterThan(5);
    for (const name of composites) {
      const model = example(name);
      model.faces.forEach((loop, f) => expect(faceTypeProblem(loop.map((e) => model.edges[e].type)), `${name} face ${f}`).toBe(null));
    }
  });

  it('refuses to make one curve of a strip a ruling alone, and allows it with the curves across', () => {
    const fold = example('composite-curved-fold');
    const crease = fold.edges.findIndex((e, k) => e.type === 'S' && fold.faces.filter((l) => l.includes(k)).length === 2);
    expect(relabelProblem(fold, [crease], 'R')).toMatch(/^face \d+: it would have one curved \(S\) side among 4/);
    expect(relabelProblem(fold, relabelGroup(fold, crease), 'R')).toBe(null);
    // Every edge of every preset: the relabel the Crease panel would send is judged by the faces
    // it touches, exactly as relabelling the labels and judging each face again.
    for (const name of composites) {
      const model = example(name);
      model.edges.forEach((edge, e) => {
        for (const opposite of [true, false]) {
          const to = edge.type === 'S' ? 'R' : 'S';
          const group = relabelGroup(model, e, opposite);
          const labels = model.edges.map((x, k) => (group.includes(k) ? to : x.type));
          const bad = model.faces.some((loop) => !isFaceType(loop.map((k) => labels[k])));
          expect(relabelProblem(model, group, to) !== null, `${name} edge ${e} → ${to}`).toBe(bad);
        }
      });
    }
  });

  it('joins two faces only into a face of a valid type, and never across the outline', () => {
    const fold = example('composite-curved-fold');
    const outline = fold.edges.findIndex((e, k) => fold.faces.filter((l) => l.includes(k)).length === 1);
    expect(mergeProblem(fold, outline)).toMatch(/on the outline/);
    const crease = fold.edges.findIndex((e, k) => e.type === 'S' && fold.faces.filter((l) => l.includes(k)).length === 2);
    // Two strips joined across their shared curve: S R R S R R, no face type.
    expect(mergeProblem(fold, crease)).toMatch(/^faces \d+ and \d+ joined: /);
  });
});
