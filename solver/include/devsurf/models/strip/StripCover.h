#pragma once

#include <cstdint>
#include <vector>

#include <Eigen/Core>

#include "devsurf/engine/Deadline.h"
#include "devsurf/engine/GuidedProjectionSolver.h"
#include "devsurf/models/strip/StripFromRegion.h"
#include "devsurf/models/strip/StripModel.h"

namespace devsurf::models::strip {

/// A boundary curve of one strip paired with a boundary curve of another (000_… §4.2: "the user
/// now indicates a pairing between one boundary curve, say a_i, with another boundary, say b_j").
struct BoundaryPairing {
  int first = -1;
  Curve firstCurve = Curve::A;
  int second = -1;
  Curve secondCurve = Curve::A;
  /// The first curve's start lies at the second curve's end (the two run in opposite directions).
  bool reversed = false;
  /// Mean distance between the two curves when paired (design units; each curve's samples to the
  /// other, averaged both ways).
  double distance = 0.0;
};

/// Proposes pairings for strips lying side by side: every pair of boundary curves of different
/// strips whose mean distance (both ways, 64 samples against a 256-point polyline) is at most
/// `tolerance` times the narrower strip's mean ruling length, closest first, each curve in at most
/// one pairing. The direction is the one whose ends are closer.
/// @throws std::invalid_argument for tolerance ≤ 0 or a strip with closed curves
std::vector<BoundaryPairing> proposeBoundaryPairings(const std::vector<StripDesign>& strips, double tolerance = 0.5);

/// Options of pairStripBoundaries.
struct StripPairingOptions {
  int rounds = 8;               ///< sweeps over all strips
  int iterationsPerRound = 10;  ///< guided-projection iterations of one strip per sweep
  /// Iterations of each strip in the last sweep (at least iterationsPerRound): ten iterations
  /// after its neighbours moved leave a strip in transit (on CGAL's bunny, regions whose warp
  /// swung between 0.3° and 22° from one sweep to the next); the last sweep lets it settle.
  int lastRoundIterations = 30;
  double boundaryWeight = 0.1;  ///< weight of "boundary_proximity" in the last sweep (eq. 9: 1e-3)
  /// The first sweep's weight over the last's; the sweeps between grow it geometrically, so the
  /// strips first follow their points and then close the gaps (1 = constant).
  double initialWeightRatio = 0.01;
  double regularization = 1e-3; ///< ε_reg (000_… Fig. 17 row 10)
  double fairness = 1e-3;       ///< ε_fair at the first iteration of each solve
  StripOptions strip;           ///< the strip model's options
  /// When the sweeps must give up (every strip solve checks it; engine::DeadlineExceeded).
  engine::Deadline deadline;
};

/// The state after one sweep.
struct StripPairingRound {
  double gapMax = 0.0;   ///< largest distance of a paired curve's samples from its partner, design units
  double gapMean = 0.0;  ///< mean of those distances
  double warpMaxDeg = 0.0;
};

struct StripPairingResult {
  std::vector<StripDesign> strips;             ///< boundary targets cleared
  std::vector<StripPairingRound> rounds;
};

/// Largest and mean distance of samples of the paired curves from each other (both ways,
/// corners included), design units.
std::pair<double, double> pairingGap(const std::vector<StripDesign>& strips, const std::vector<BoundaryPairing>& pairings);

/// Fig. 10d: strips side by side "subjected to the approximation procedure, with proximity of
/// boundaries as an additional optimization goal". Every paired curve gets a BoundaryTarget on its
/// partner's current curve (samples on the partner's tangent lines, ends pinned to its ends), and
/// each strip keeps its own approximation target. The paper solves all strips in one system; here
/// the strips are solved one after another against their neighbours' current boundaries (a block
/// Gauss–Seidel sweep), `rounds` times, so every strip model stays the ordinary StripModel.
/// @throws std::invalid_argument for pairings naming a missing strip or a curve twice
StripPairingResult pairStripBoundaries(std::vector<StripDesign> strips, const std::vector<BoundaryPairing>& pairings,
                                       const StripPairingOptions& options = {});

/// A region laid out in `count` bands side by side, a strip each (a simple layout; 000_… leaves
/// finding one to the user). In the points' PCA frame (centroid c, axes e₁, e₂, normal) a
/// quadratic height field gives the direction of least normal curvature r (fitQuadraticHeightField;
/// e₂ where the region is flat) and the direction s across it. The region is clipped to the
/// rectangle |⟨p − c, s⟩| ≤ keep·max, |⟨p − c, r⟩| ≤ keep·max and cut at equal-count quantiles of
/// ⟨p − c, r⟩: each band runs along s, and a strip over it with its rulings across it has them
/// along r, where a developable's rulings run.
struct RegionLayout {
  std::vector<std::vector<int>> bands;  ///< indices of each band's points, bands in order along r
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero(), e1 = Eigen::Vector3d::UnitX(), e2 = Eigen::Vector3d::UnitY(),
                  normal = Eigen::Vector3d::UnitZ();
  Eigen::Vector2d along{1.0, 0.0}, across{0.0, 1.0};  ///< s and r in (e₁, e₂) coordinates
  double size = 1.0;                   ///< the height field's coordinate scale
  QuadraticHeightField field;
  double halfLength = 0.0;             ///< the rectangle's half-size along s
  std::vector<double> cuts;            ///< count + 1 values of ⟨p − c, r⟩: the rectangle's sides and
                                       ///< the lines between neighbouring bands
  /// The point of the height field above c + t₁ s + t₂ r.
  Eigen::Vector3d pointAt(double t1, double t2) const;
};

/// @throws std::invalid_argument for count < 1, fewer than 6·count points (in the rectangle) or
///         points on a line
RegionLayout regionLayout(const Eigen::MatrixX3d& points, int count, double keep = 0.7);

/// Options of coverRegion.
struct RegionCoverOptions {
  int strips = 4;                 ///< bands, one strip each
  double keep = 0.7;              ///< regionLayout: the rectangle's half-sizes over the extents
  double thinRadius = 0.0;        ///< thinning radius; 0 = reference::suggestedThinningRadius
  std::uint32_t seed = 1;         ///< thinning order
  /// Control points and degree of every curve (the rulings option is not used: they run across
  /// the bands).
  RegionStripOptions placement;
  StripPairingOptions pairing;    ///< the sweeps
  /// ApproximationTarget::overhangWeight of every band's strip. Off by default: measured on CGAL's
  /// bunny cut into 24 clusters (38 regions), 0.001 covered 26 regions and 0.01 21, against 27
  /// without: pulling the strips back onto their bands slows the sweeps' convergence more than
  /// it saves.
  double overhangWeight = 0.0;
};

/// A region covered by strips side by side, their boundaries paired.
struct RegionCover {
  RegionLayout layout;
  std::vector<StripDesign> placed;          ///< the strips at the start (approximation targets set)
  std::vector<BoundaryPairing> pairings;    ///< strip k's b with strip k + 1's a
  StripPairingResult paired;                ///< the strips after the sweeps
  /// Fraction of the thinned points whose fitted normal is more than 75° from the layout's plane
  /// normal: where the region wraps around the shape, it is not a height field over the plane and
  /// the layout's bands do not describe it.
  double steepFraction = 0.0;
};

/// 000_… Fig. 10 on a region, automatically laid out: regionLayout; per band thinning
/// (reference::thinPointCloud, normals from the plane of each ball) as the approximation target
/// of eq. (9)–(11); the rectangle's sides and the lines between the bands, lifted onto the height
/// field, as the strips' curves — strip k between line k (its a) and line k + 1 (its b), so
/// neighbours start on one curve; then pairStripBoundaries, which fits every strip to its band
/// while keeping the paired curves on each other (Fig. 10b and d in one).
/// @param[in] normals  N×3 or empty (then fitted by the thinning)
/// @throws std::invalid_argument for too few points, or bands whose thinning leaves fewer than 6
RegionCover coverRegion(const Eigen::MatrixX3d& points, const Eigen::MatrixX3d& normals,
                        const RegionCoverOptions& options = {});

}  // namespace devsurf::models::strip
