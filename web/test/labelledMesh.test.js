import { readFileSync } from 'node:fs';
import { fileURLToPath } from 'node:url';
import { describe, expect, it } from 'vitest';
import { faceCorners, relabelGroup, splitCandidate } from '../src/geometry/labelledMesh.js';

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
});
