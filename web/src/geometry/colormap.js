// Colour map for the warp angle (degrees per vertex): 0° (developable) is a calm blue-green,
// larger warp goes through yellow to red. The upper end of the scale is a "nice" number at or
// above the current maximum, at least MIN_RANGE_DEG, so a developable surface reads as uniform.

// Stops of a perceptually ordered map (approximately "viridis" into "inferno"'s warm end).
const STOPS = [
  [0.0, [0.16, 0.45, 0.68]],
  [0.25, [0.13, 0.63, 0.6]],
  [0.5, [0.55, 0.78, 0.32]],
  [0.75, [0.99, 0.75, 0.2]],
  [1.0, [0.86, 0.2, 0.16]],
];

export const MIN_RANGE_DEG = 1;

/** Writes the colour for t ∈ [0, 1] into out[offset..offset+2] (linear 0..1 floats). */
export function colorAt(t, out, offset = 0) {
  if (!(t > 0)) t = 0;
  else if (t > 1) t = 1;
  let k = 1;
  while (k < STOPS.length - 1 && STOPS[k][0] < t) k++;
  const [t0, c0] = STOPS[k - 1];
  const [t1, c1] = STOPS[k];
  const s = (t - t0) / (t1 - t0);
  out[offset] = c0[0] + (c1[0] - c0[0]) * s;
  out[offset + 1] = c0[1] + (c1[1] - c0[1]) * s;
  out[offset + 2] = c0[2] + (c1[2] - c0[2]) * s;
  return out;
}

/** CSS colour string for t ∈ [0, 1]. */
export function cssColorAt(t) {
  const c = colorAt(t, [0, 0, 0]);
  return `rgb(${Math.round(c[0] * 255)}, ${Math.round(c[1] * 255)}, ${Math.round(c[2] * 255)})`;
}

/** The smallest of 1, 2, 2.5, 5 × 10^k that is ≥ value (and ≥ `min`, default MIN_RANGE_DEG). */
export function niceRange(value, min = MIN_RANGE_DEG) {
  const v = Math.max(Number.isFinite(value) ? value : 0, min);
  const p = Math.pow(10, Math.floor(Math.log10(v)));
  for (const m of [1, 2, 2.5, 5, 10]) if (m * p >= v - 1e-12) return m * p;
  return 10 * p;
}

/**
 * Fills `colors` (length 3n) from `values` (length n) over [0, range].
 * Colours are in the renderer's working (linear) space: three.js vertex colours are linear.
 */
export function fillColors(values, colors, range, toLinear = true) {
  const n = values.length;
  for (let i = 0; i < n; i++) {
    colorAt(values[i] / range, colors, 3 * i);
    if (toLinear) {
      colors[3 * i] = srgbToLinear(colors[3 * i]);
      colors[3 * i + 1] = srgbToLinear(colors[3 * i + 1]);
      colors[3 * i + 2] = srgbToLinear(colors[3 * i + 2]);
    }
  }
  return colors;
}

export function srgbToLinear(c) {
  return c < 0.04045 ? c * 0.0773993808 : Math.pow(c * 0.9478672986 + 0.0521327014, 2.4);
}

/** CSS linear-gradient() for a legend bar, left (0) to right (1). */
export function cssGradient(direction = 'to right') {
  const parts = [];
  for (let i = 0; i <= 10; i++) parts.push(`${cssColorAt(i / 10)} ${i * 10}%`);
  return `linear-gradient(${direction}, ${parts.join(', ')})`;
}

// Diverging map for signed fields (Gauss and mean curvature): blue below 0, a light neutral at 0,
// red above; t ∈ [−1, 1].
const DIVERGING = [
  [-1.0, [0.15, 0.3, 0.7]],
  [-0.5, [0.45, 0.62, 0.86]],
  [0.0, [0.9, 0.9, 0.88]],
  [0.5, [0.93, 0.58, 0.45]],
  [1.0, [0.72, 0.13, 0.15]],
];

/** Writes the diverging colour of t ∈ [−1, 1] (clamped; NaN → 0) into out[offset..offset+2]. */
export function divergingColorAt(t, out, offset = 0) {
  if (!(t > -1)) t = Number.isNaN(t) ? 0 : -1;
  else if (t > 1) t = 1;
  let k = 1;
  while (k < DIVERGING.length - 1 && DIVERGING[k][0] < t) k++;
  const [t0, c0] = DIVERGING[k - 1];
  const [t1, c1] = DIVERGING[k];
  const s = (t - t0) / (t1 - t0);
  for (let c = 0; c < 3; c++) out[offset + c] = c0[c] + (c1[c] - c0[c]) * s;
  return out;
}

/** CSS linear-gradient() of the diverging map, left (−1) to right (+1). */
export function cssDivergingGradient(direction = 'to right') {
  const parts = [];
  for (let i = 0; i <= 10; i++) {
    const c = divergingColorAt(i / 5 - 1, [0, 0, 0]);
    parts.push(`rgb(${Math.round(c[0] * 255)}, ${Math.round(c[1] * 255)}, ${Math.round(c[2] * 255)}) ${i * 10}%`);
  }
  return `linear-gradient(${direction}, ${parts.join(', ')})`;
}
