// Decade ranges and ticks for the residual plot's log scale.

/** Decades the plot shows at most below its largest value: a term that has reached rounding level
 * (1e-200 after a long drag) would squash every other curve into one line at the top. */
export const MAX_DECADES = 16;

/**
 * [10^floor(log10 min), 10^ceil(log10 max)] over the finite positive values, at least one decade
 * and at most MAX_DECADES (values below lie under the plot's floor).
 */
export function decadeRange(series) {
  let lo = Infinity;
  let hi = -Infinity;
  for (const values of series) {
    for (const v of values) {
      if (typeof v === 'number' && v > 0 && Number.isFinite(v)) {
        if (v < lo) lo = v;
        if (v > hi) hi = v;
      }
    }
  }
  if (!(lo <= hi)) return [1e-12, 1];
  let a = Math.floor(Math.log10(lo));
  let b = Math.ceil(Math.log10(hi));
  if (b <= a) b = a + 1;
  a = Math.max(a, b - MAX_DECADES, -300);
  b = Math.min(b, 300);
  return [Math.pow(10, a), Math.pow(10, b)];
}

/** Decade ticks between min and max, thinned to at most `maxTicks`. */
export function decadeSplits(min, max, maxTicks = 6) {
  const a = Math.round(Math.log10(min));
  const b = Math.round(Math.log10(max));
  const step = Math.max(1, Math.ceil((b - a) / (maxTicks - 1)));
  const out = [];
  for (let e = b; e >= a; e -= step) out.unshift(Math.pow(10, e));
  return out;
}
