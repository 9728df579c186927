#pragma once

namespace devsurf::terms {

/// The residual of a one-sided guard (an inequality g ≤ 0 as a least-squares row), C¹:
///   ρ(g) = 0 for g ≤ 0,  g²/(2m) for 0 < g ≤ m,  g − m/2 for g > m.
/// A plain hinge max(0, g) has a kink at the bound: Gauss–Newton does not see the guard until a
/// step has crossed it and then pushes back by the whole amount, so the iterates chatter across
/// the bound (measured on the ruling guard during drags: every other step shortened to α = 1/32).
/// With the ramp, a small crossing costs a small residual and the pushback grows smoothly.
constexpr double kHingeRamp = 0.05;  ///< m, in the units of g (the guards scale g to be dimensionless)

inline double hingeResidual(double g) {
  if (g <= 0.0) return 0.0;
  if (g <= kHingeRamp) return 0.5 * g * g / kHingeRamp;
  return g - 0.5 * kHingeRamp;
}

/// dρ/dg.
inline double hingeSlope(double g) {
  if (g <= 0.0) return 0.0;
  if (g <= kHingeRamp) return g / kHingeRamp;
  return 1.0;
}

}  // namespace devsurf::terms
