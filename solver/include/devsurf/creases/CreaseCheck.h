#pragma once

#include <Eigen/Core>

#include "devsurf/creases/FoldSamples.h"

namespace devsurf::creases {

/// Warp angle of the ruling from a to b in degrees, from exact tangents of the two boundary
/// curves (as metrics::warpAngleDeg, 001_… §5): the angle between the lines of da × (b − a) and
/// db × (b − a); 0 for a developable (one tangent plane along the ruling), 0 where a normal
/// vanishes.
double rulingWarpDeg(const Eigen::Vector3d& a, const Eigen::Vector3d& da, const Eigen::Vector3d& b,
                     const Eigen::Vector3d& db);

/// Planarity of the quad p0 p1 p2 p3 in degrees: the larger of the two dihedral angles between
/// the triangles of either diagonal split (between lines, in [0°, 90°]); 0 iff planar.
double quadWarpDeg(const Eigen::Vector3d& p0, const Eigen::Vector3d& p1, const Eigen::Vector3d& p2,
                   const Eigen::Vector3d& p3);

/// Signed curvature of the circle through p0, p1, p2 (Menger curvature; positive when the
/// polyline p0 → p1 → p2 turns left), 2 det(p1 − p0, p2 − p1) / (|p1 − p0| |p2 − p1| |p2 − p0|).
double signedMengerCurvature(const Eigen::Vector2d& p0, const Eigen::Vector2d& p1,
                             const Eigen::Vector2d& p2);

/// Checks of one sheet. Per-sample vectors have n entries, per-quad vectors n−1; an entry is NaN
/// where it cannot be computed (end samples for the finite-difference quantities, missing
/// derivative data for the exact ones, an undefined osculating plane). Maxima skip NaN entries and
/// are NaN when every entry is.
struct SheetCheck {
  /// +1 where the development lies left of the developed crease (traversed by increasing u), −1
  /// where it lies right (from det(c̄′, r̄), exact c̄′ when available, else central differences).
  Eigen::VectorXi side;
  /// Exact (from c′, c″ and the sheet's exact tangent plane span{c′, r}): angle in [0, π/2]
  /// between the crease's osculating plane and the sheet's tangent plane at c(u_i), in radians.
  Eigen::VectorXd tangentPlaneAngle;
  /// The same from the polylines only: osculating plane through c_{i−1}, c_i, c_{i+1}; tangent
  /// plane spanned by c_{i+1} − c_{i−1} and the ruling. O(h²) accurate.
  Eigen::VectorXd tangentPlaneAngleDiscrete;
  /// Exact geodesic curvature κ_g = det(c′, c″, N)/|c′|³ with the oriented normal N of
  /// FoldSamples' convention (so that κ_g equals the developed crease's signed curvature).
  Eigen::VectorXd geodesicCurvature;
  /// From the development by finite differences: signedMengerCurvature(c̄_{i−1}, c̄_i, c̄_{i+1}).
  Eigen::VectorXd geodesicCurvatureDev;
  /// Intrinsic, from the space mesh only: the sheet's angle θ at c_i between the crease edges
  /// and the ruling, turning angle α = side·(π − θ), κ = 2 sin α / d with d the chord of the
  /// unfolded vertex star (law of cosines). O(h²) accurate on smooth data.
  Eigen::VectorXd geodesicCurvatureMesh;
  Eigen::VectorXd rulingWarpDeg;  ///< per ruling, exact tangents (NaN without derivatives)
  Eigen::VectorXd quadWarpDeg;    ///< per quad (c_i, c_{i+1}, e_{i+1}, e_i), from positions
  double rulingWarpMaxDeg = 0.0;
  double quadWarpMaxDeg = 0.0;
  /// Max relative length error |ℓ − ℓ̄|/ℓ between the space mesh and its development over the
  /// quad edges (crease chords, far-boundary chords, rulings).
  double edgeLengthErrorMax = 0.0;
  double diagonalLengthErrorMax = 0.0;  ///< the same over both diagonals of every quad
  /// Exact isometry: max over samples and v ∈ {0, L/2, L} of the relative first-fundamental-form
  /// errors |E − Ē|/E, |F − F̄|/√E (for the ruled parametrization c + v r, r unit) and of the
  /// relative ruling length error (NaN without derivatives).
  double metricErrorMax = 0.0;
};

/// Checks of a sampled curved fold (both sheets).
struct CreaseCheckReport {
  SheetCheck sheet[2];
  /// max_i |θ₁ − θ₂| (radians) of the exact tangent-plane angles: the bisector property.
  double bisectorErrorMax = 0.0;
  double bisectorErrorMaxDiscrete = 0.0;  ///< the same from the polylines
  /// max_i |m × b| with m = (N₁ + N₂)/|N₁ + N₂|, b the osculating plane's unit normal (exact):
  /// zero iff the osculating plane bisects the sheets as a curved fold (not as a "geodesic"
  /// crease, Tang et al. 7* vs 8*).
  double foldNormalResidualMax = 0.0;
  double geodesicCurvatureErrorMax = 0.0;     ///< exact, max |κ_g1 − κ_g2| (7*)
  double geodesicCurvatureDevErrorMax = 0.0;  ///< from the developments, max |κ̄₁ − κ̄₂|
  double geodesicCurvatureMeshErrorMax = 0.0; ///< intrinsic mesh estimates, max |κ₁ − κ₂|
  /// max |c̄₁(u_i) − c̄₂(u_i)|: the two developments share the developed crease (0 when built in
  /// one frame, as all producers here do).
  double developedCreaseMismatch = 0.0;
  /// max |c₁(u_i) − c_i|, max |c₂(u_i) − c_i|: both sheets start on the crease polyline.
  double creaseMismatch = 0.0;
  /// True when at every sample the two developments lie on opposite sides of the developed crease
  /// (the paper continues across the crease).
  bool oppositeSides = false;
  /// Samples where the osculating plane is undefined (c′ × c″ ≈ 0), skipped by the exact checks.
  int osculatingPlaneUndefined = 0;
};

/// Runs all checks. Needs n ≥ 3 samples (interior samples for the finite differences).
/// @throws std::invalid_argument on inconsistent block sizes or n < 3
CreaseCheckReport checkCrease(const FoldSamples& fold);

}  // namespace devsurf::creases
