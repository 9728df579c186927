import { describe, expect, it } from 'vitest';
import * as THREE from 'three';
import { PointSprites, SHAPE_CUBE, SHAPE_SPHERE } from '../src/view/PointSprites.js';

// A 400×400 px view of the plane z = 0 from z = 10, looking down.
function setup() {
  const scene = new THREE.Scene();
  const camera = new THREE.PerspectiveCamera(45, 1, 0.1, 100);
  camera.position.set(0, 0, 10);
  camera.lookAt(0, 0, 0);
  camera.updateMatrixWorld();
  const worldPerPixel = (p) => (2 * (camera.position.z - p.z) * Math.tan(THREE.MathUtils.degToRad(22.5))) / 400;
  const sprites = new PointSprites(scene);
  return { scene, camera, worldPerPixel, sprites };
}

function rayAtPixel(camera, x, y) {
  const r = new THREE.Raycaster();
  r.setFromCamera(new THREE.Vector2((x / 400) * 2 - 1, -(y / 400) * 2 + 1), camera);
  return r;
}

describe('control point picking (Raycaster on point sprites)', () => {
  it('picks the point under the pointer within its pixel radius', () => {
    const { camera, worldPerPixel, sprites } = setup();
    sprites.begin(3);
    sprites.push(new THREE.Vector3(0, 0, 0), 7, 0xffffff, SHAPE_SPHERE, { curve: 'a', index: 0 });
    sprites.push(new THREE.Vector3(1, 0, 0), 7, 0xffffff, SHAPE_CUBE, { curve: 'a', index: 1 });
    sprites.push(new THREE.Vector3(0, 1, 0), 7, 0xffffff, SHAPE_SPHERE, { curve: 'b', index: 0 });
    sprites.end();
    const px = 1 / worldPerPixel(new THREE.Vector3()); // pixels per world unit at z = 0
    expect(sprites.pick(rayAtPixel(camera, 200, 200), worldPerPixel)).toEqual({ curve: 'a', index: 0 });
    expect(sprites.pick(rayAtPixel(camera, 200 + px + 4, 200), worldPerPixel)).toEqual({ curve: 'a', index: 1 });
    expect(sprites.pick(rayAtPixel(camera, 200, 200 - px - 3), worldPerPixel)).toEqual({ curve: 'b', index: 0 });
    // 12 px away from everything: nothing, unless the tolerance covers it.
    expect(sprites.pick(rayAtPixel(camera, 212, 212), worldPerPixel)).toBeNull();
    expect(sprites.pick(rayAtPixel(camera, 212, 212), worldPerPixel, 12)).toEqual({ curve: 'a', index: 0 });
  });

  it('grows its buffers and draws only the points pushed', () => {
    const { sprites } = setup();
    sprites.begin(100);
    for (let i = 0; i < 100; i++) sprites.push(new THREE.Vector3(i, 0, 0), 5, 0xff0000, SHAPE_SPHERE, { curve: 'a', index: i });
    sprites.end();
    expect(sprites.capacity).toBeGreaterThanOrEqual(100);
    expect(sprites.geometry.drawRange.count).toBe(100);
    const positions = sprites.geometry.attributes.position.array;
    sprites.begin(10);
    for (let i = 0; i < 10; i++) sprites.push(new THREE.Vector3(0, i, 0), 5, 0xff0000, SHAPE_SPHERE, { curve: 'b', index: i });
    sprites.end();
    expect(sprites.geometry.attributes.position.array).toBe(positions);
    expect(sprites.geometry.drawRange.count).toBe(10);
    expect(sprites.geometry.attributes.size.array[0]).toBe(10);
  });
});
