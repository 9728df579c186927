// Control points as screen-sized sprites in one draw call: shaded sphere impostors for free points,
// bevelled squares ("cubes") for fixed points. One vertex per point, so strips with hundreds of
// control points stay cheap even with software GL. Picked with a Raycaster (THREE.Points).

import * as THREE from 'three';

export const SHAPE_SPHERE = 0;
export const SHAPE_CUBE = 1;
/** A flat diamond (the pick markers of a composite's edges). */
export const SHAPE_DIAMOND = 2;
/** A sphere inside a ring (the points of a composite's group selection). */
export const SHAPE_RING = 3;

const vertexShader = /* glsl */ `
  attribute float size;
  attribute float shape;
  attribute vec3 pointColor;
  uniform float pixelRatio;
  varying vec3 vColor;
  varying float vShape;
  void main() {
    vColor = pointColor;
    vShape = shape;
    gl_Position = projectionMatrix * modelViewMatrix * vec4(position, 1.0);
    gl_PointSize = size * pixelRatio;
  }
`;

const fragmentShader = /* glsl */ `
  varying vec3 vColor;
  varying float vShape;
  void main() {
    vec2 p = gl_PointCoord * 2.0 - 1.0;
    p.y = -p.y;
    vec3 light = normalize(vec3(-0.45, 0.55, 0.75));
    vec3 c;
    if (vShape < 0.5) {
      float r2 = dot(p, p);
      if (r2 > 1.0) discard;
      vec3 n = vec3(p, sqrt(1.0 - r2));
      float diff = max(dot(n, light), 0.0);
      float spec = pow(max(dot(reflect(-light, n), vec3(0.0, 0.0, 1.0)), 0.0), 20.0);
      c = vColor * (0.3 + 0.8 * diff) + vec3(0.35 * spec);
      c = mix(c, vec3(0.04), smoothstep(0.72, 1.0, r2) * 0.75);
    } else if (vShape > 2.5) {
      float r = length(p);
      if (r > 1.0 || (r > 0.6 && r < 0.74)) discard;
      if (r >= 0.74) {
        c = vColor * (r > 0.92 ? 0.3 : 1.0);
      } else {
        vec2 q = p / 0.6;
        vec3 n = vec3(q, sqrt(max(1.0 - dot(q, q), 0.0)));
        c = vColor * (0.35 + 0.75 * max(dot(n, light), 0.0));
      }
    } else if (vShape > 1.5) {
      float m = abs(p.x) + abs(p.y);
      if (m > 0.95) discard;
      c = vColor * (m > 0.7 ? 0.35 : 1.0);
    } else {
      float m = max(abs(p.x), abs(p.y));
      if (m > 0.86) discard;
      float shade = 0.75 + 0.25 * (p.y - p.x) * 0.5;
      c = vColor * shade;
      if (m > 0.66) c *= 0.45;
    }
    gl_FragColor = vec4(c, 1.0);
    #include <colorspace_fragment>
  }
`;

const tmpColor = new THREE.Color();

export class PointSprites {
  constructor(parent) {
    this.capacity = 0;
    this.count = 0;
    /** index → payload ({curve, index}) */
    this.items = [];
    /** Pixel radius of each point (for picking). */
    this.radii = new Float32Array(0);
    this.geometry = new THREE.BufferGeometry();
    this.material = new THREE.ShaderMaterial({
      vertexShader,
      fragmentShader,
      uniforms: { pixelRatio: { value: 1 } },
      depthTest: false,
      depthWrite: false,
      transparent: true,
    });
    this.object = new THREE.Points(this.geometry, this.material);
    this.object.frustumCulled = false;
    this.object.renderOrder = 5;
    this.object.name = 'control-points';
    parent.add(this.object);
    this._ensure(16);
  }

  _ensure(n) {
    if (n <= this.capacity) return;
    let cap = Math.max(16, this.capacity);
    while (cap < n) cap *= 2;
    this.geometry.dispose();
    const attr = (itemSize) => new THREE.BufferAttribute(new Float32Array(cap * itemSize), itemSize).setUsage(THREE.DynamicDrawUsage);
    this.geometry.setAttribute('position', attr(3));
    this.geometry.setAttribute('pointColor', attr(3));
    this.geometry.setAttribute('size', attr(1));
    this.geometry.setAttribute('shape', attr(1));
    this.radii = new Float32Array(cap);
    this.capacity = cap;
  }

  setPixelRatio(ratio) {
    this.material.uniforms.pixelRatio.value = ratio;
  }

  begin(n) {
    this._ensure(n);
    this.count = 0;
    this.items.length = 0;
  }

  /** Adds a point: world position, radius in CSS px, colour, shape, payload. */
  push(position, radiusPx, color, shape, item) {
    const i = this.count++;
    const g = this.geometry;
    g.attributes.position.array.set([position.x, position.y, position.z], 3 * i);
    tmpColor.set(color);
    g.attributes.pointColor.array.set([tmpColor.r, tmpColor.g, tmpColor.b], 3 * i);
    // A cube's square is drawn within 86% of the sprite: scale it so it reads as large as a sphere.
    g.attributes.size.array[i] = 2 * radiusPx * (shape === SHAPE_CUBE ? 1.05 : 1);
    g.attributes.shape.array[i] = shape;
    this.radii[i] = radiusPx;
    this.items[i] = item;
  }

  end() {
    const g = this.geometry;
    for (const name of ['position', 'pointColor', 'size', 'shape']) {
      const a = g.attributes[name];
      a.clearUpdateRanges();
      a.addUpdateRange(0, this.count * a.itemSize);
      a.needsUpdate = true;
    }
    g.setDrawRange(0, this.count);
    g.computeBoundingSphere();
  }

  /**
   * Raycaster picking: points whose sprite covers the pointer. `worldPerPixel(p)` converts the
   * sprite radius to world units at the point's depth; among the hits the one of the highest
   * `priority(payload)` (default: all equal) and then nearest the ray (in pixels) wins. Returns
   * the payload or null.
   */
  pick(raycaster, worldPerPixel, tolerancePx = 0, priority = null) {
    if (!this.count) return null;
    let maxThreshold = 0;
    const pos = this.geometry.attributes.position.array;
    const p = new THREE.Vector3();
    for (let i = 0; i < this.count; i++) {
      p.fromArray(pos, 3 * i);
      maxThreshold = Math.max(maxThreshold, (this.radii[i] + tolerancePx) * worldPerPixel(p));
    }
    raycaster.params.Points = { threshold: maxThreshold };
    const hits = raycaster.intersectObject(this.object, false);
    let best = null;
    let bestRank = -Infinity;
    let bestScore = Infinity;
    for (const hit of hits) {
      const i = hit.index;
      if (i === undefined || i >= this.count) continue;
      p.fromArray(pos, 3 * i);
      const px = hit.distanceToRay / worldPerPixel(p);
      if (px > this.radii[i] + tolerancePx) continue;
      // Prefer the higher priority, then the point nearest the pointer, then the nearest to the camera.
      const rank = priority ? priority(this.items[i]) : 0;
      const score = px + hit.distance * 1e-9;
      if (rank > bestRank || (rank === bestRank && score < bestScore)) {
        bestRank = rank;
        bestScore = score;
        best = this.items[i];
      }
    }
    return best;
  }
}
