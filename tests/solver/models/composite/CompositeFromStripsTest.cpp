// Composites initialized from strips with paired boundaries (000_… Fig. 10d–e; issue 15).

#include <gtest/gtest.h>

#include "support/StripCovers.h"

#include <cmath>
#include <cstdio>
#include <random>
#include <set>
#include <vector>

#include <Eigen/Geometry>

#include "devsurf/io/QuadMesh.h"
#include "devsurf/models/composite/CompositeFromStrips.h"
#include "devsurf/models/composite/CompositeModel.h"
#include "devsurf/models/strip/StripCover.h"
#include "devsurf/reference/SurfaceDistance.h"

namespace devsurf::models::composite {
namespace {

using devsurf::testing::flatStrip;

using strip::BoundaryPairing;
using strip::Curve;
using strip::StripDesign;

reference::SurfaceDistance distanceToComposite(const Eigen::MatrixX3d& points, const CompositeModel& model,
                                               double tolerance) {
  const CompositeGeometry g = model.geometry(16, 8);
  const Eigen::MatrixX3i T = io::triangulateQuads(g.merged);
  return reference::surfaceDistance(points, g.merged.vertices, T, tolerance);
}

TEST(CompositeFromStrips, StripsSideBySideBecomeOneFacePerStripSharingTheirPairedEdges) {
  std::mt19937 rng(11);
  for (int trial = 0; trial < 200; ++trial) {
    const int count = 2 + static_cast<int>(rng() % 4);
    std::vector<StripDesign> strips;
    for (int k = 0; k < count; ++k) {
      StripDesign s = flatStrip(0.3 * k, 0.3 * (k + 1));
      if (rng() % 2) std::swap(s.a, s.b);
      if (rng() % 2) {
        s.a.points = s.a.points.colwise().reverse().eval();
        s.b.points = s.b.points.colwise().reverse().eval();
      }
      strips.push_back(std::move(s));
    }
    // Shuffled, so the strips are not listed in the order they lie in.
    std::shuffle(strips.begin(), strips.end(), rng);
    const std::vector<BoundaryPairing> pairings = strip::proposeBoundaryPairings(strips);
    ASSERT_EQ(static_cast<int>(pairings.size()), count - 1) << "trial " << trial;
    const CompositeDesign design = compositeFromStrips(strips, pairings, CreaseKind::Fold);  // validates
    EXPECT_EQ(static_cast<int>(design.faces.size()), count);
    EXPECT_EQ(design.vertices.rows(), 2 * (count + 1));
    int shared = 0;
    for (const CompositeEdge& e : design.edges) shared += e.crease == CreaseKind::Fold;
    EXPECT_EQ(shared, count - 1);
    EXPECT_EQ(static_cast<int>(design.edges.size()), (count + 1) + 2 * count);
    // The sheet is the rectangle [0, 1] × [0, 0.3·count]: its corners are vertices.
    std::set<std::pair<long, long>> corners;
    for (Eigen::Index v = 0; v < design.vertices.rows(); ++v)
      corners.insert({std::lround(10 * design.vertices(v, 0)), std::lround(10 * design.vertices(v, 1))});
    EXPECT_EQ(corners.size(), static_cast<std::size_t>(2 * (count + 1)));
    EXPECT_TRUE(corners.count({0, 0}) && corners.count({10, 3 * count}));
    // A composite the solver takes: the flat sheet stays flat and in place.
    if (trial % 20 == 0) {
      CompositeModel model(design);
      engine::SolverOptions options;
      options.maxIterations = 3;
      model.solve(options);
      EXPECT_LT(model.quality().warpAngleMaxDeg, 1e-6);
      EXPECT_LT(model.design().vertices.col(2).cwiseAbs().maxCoeff(), 1e-9);
    }
  }
}

TEST(CompositeFromStrips, PairingsThatCannotBeOrientedAlikeAreRefused) {
  const std::vector<StripDesign> strips = {flatStrip(0, 0.3), flatStrip(0.3, 0.6), flatStrip(0.6, 0.9)};
  const std::vector<BoundaryPairing> mobius = {{0, Curve::B, 1, Curve::A, false},
                                               {1, Curve::B, 2, Curve::A, false},
                                               {2, Curve::B, 0, Curve::A, true}};
  EXPECT_THROW(compositeFromStrips(strips, mobius, CreaseKind::None), std::invalid_argument);
  EXPECT_THROW(compositeFromStrips(strips, {{0, Curve::B, 1, Curve::A}, {1, Curve::A, 2, Curve::A}}, CreaseKind::None),
               std::invalid_argument);
  EXPECT_THROW(compositeFromStrips(strips, {{0, Curve::B, 3, Curve::A}}, CreaseKind::None), std::invalid_argument);
  EXPECT_THROW(compositeFromStrips({}, {}, CreaseKind::None), std::invalid_argument);
}

TEST(CompositeFromStrips, ASphereCapCoveredByFourPairedStripsSolvesAsOneComposite) {
  // 000_… Fig. 10d → e on a doubly curved shape: four strips fitted side by side, their
  // boundaries paired, then one composite with curved folds (or plain seams) along the pairs.
  std::mt19937 rng(4);
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  Eigen::MatrixX3d points(8000, 3);
  for (Eigen::Index j = 0; j < points.rows(); ++j) {
    const double x = uniform(rng), y = uniform(rng);
    points.row(j) << x, y, std::sqrt(4.0 - x * x - y * y);
  }
  strip::RegionCoverOptions options;
  options.strips = 4;
  const strip::RegionCover cover = strip::coverRegion(points, Eigen::MatrixX3d(0, 3), options);
  const Eigen::MatrixX3d region = devsurf::testing::coveredPoints(points, cover.layout);
  const double diagonal = (region.colwise().maxCoeff() - region.colwise().minCoeff()).norm();
  {
    // Seams (no crease condition): each face developable. Curved folds (CreaseKind::Fold) make
    // one sheet, which a doubly curved cap is not: measured RMS 3.4 % of the diagonal.
    const CreaseKind crease = CreaseKind::None;
    CompositeModel model(compositeFromStrips(cover.paired.strips, cover.pairings, crease));
    engine::SolverOptions solve;
    solve.maxIterations = 20;
    // Fairness would pull the composite off the shape (with ε_fair = 1e-3 and ε_reg = 1e-3 the
    // RMS grew from 0.25 % to 1 % of the diagonal in 10 iterations while the warp vanished).
    solve.regularization = 1e-2;
    solve.fairness = 0.0;
    const engine::SolveSummary summary = model.solve(solve);
    const CompositeQuality q = model.quality();
    const reference::SurfaceDistance d = distanceToComposite(region, model, 1e-2 * diagonal);
    std::printf("sphere cap, 4 strips as a composite (crease %s): RMS %.3g %% max %.3g %% of the diagonal, "
                "coverage %.4f, warp %.3g°, flatness %.3g, fold residual %.3g\n",
                creaseKindName(crease), 100 * d.rmsDistance / diagonal, 100 * d.maxDistance / diagonal, d.coverage,
                q.warpAngleMaxDeg, q.faceFlatnessMax, q.creaseFoldResidualMax);
    EXPECT_NE(summary.reason, engine::TerminationReason::Diverged);
    EXPECT_LE(q.warpAngleMaxDeg, 0.05);
    EXPECT_LE(d.rmsDistance, 0.004 * diagonal);
    EXPECT_GE(d.coverage, 0.95);
  }
}

TEST(CompositeFromStrips, RandomShapesInRandomPosesAreCoveredBySolvableComposites) {
  // Plausible scans: height fields with random curvature (both signs, up to 1/radius 0.8 on a
  // region 2 wide) and a cubic term, 3000 points, turned and moved at random, covered by 2–6 strips.
  std::mt19937 rng(29);
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  int developable = 0, cases = 0;
  for (int trial = 0; trial < 12; ++trial) {
    const double kx = 0.6 * uniform(rng), ky = 0.6 * uniform(rng), kxy = 0.3 * uniform(rng), c3 = 0.1 * uniform(rng);
    const Eigen::Matrix3d R = Eigen::Quaterniond::UnitRandom().toRotationMatrix();
    const Eigen::Vector3d t(uniform(rng), uniform(rng), uniform(rng));
    Eigen::MatrixX3d points(3000, 3);
    for (Eigen::Index j = 0; j < points.rows(); ++j) {
      const double x = uniform(rng), y = uniform(rng);
      const Eigen::Vector3d p(x, y, kx * x * x + ky * y * y + kxy * x * y + c3 * x * x * x);
      points.row(j) = (R * p + t).transpose();
    }
    strip::RegionCoverOptions options;
    options.strips = 2 + static_cast<int>(rng() % 5);
    const strip::RegionCover cover = strip::coverRegion(points, Eigen::MatrixX3d(0, 3), options);
    const Eigen::MatrixX3d region = devsurf::testing::coveredPoints(points, cover.layout);
    const double diagonal = (region.colwise().maxCoeff() - region.colwise().minCoeff()).norm();
    EXPECT_LT(strip::pairingGap(cover.paired.strips, cover.pairings).first, 1e-3 * diagonal) << "trial " << trial;
    CompositeModel model(compositeFromStrips(cover.paired.strips, cover.pairings, CreaseKind::None));
    engine::SolverOptions solve;
    solve.maxIterations = 20;
    solve.fairness = 0.0;
    const engine::SolveSummary summary = model.solve(solve);
    const double warp = model.quality().warpAngleMaxDeg;
    const reference::SurfaceDistance d = distanceToComposite(region, model, 1e-2 * diagonal);
    std::printf("trial %2d: %d strips, curvature (%.2f, %.2f, %.2f): warp %.2g°, RMS %.3g %% max %.3g %%, coverage %.3f\n",
                trial, options.strips, kx, ky, kxy, warp, 100 * d.rmsDistance / diagonal,
                100 * d.maxDistance / diagonal, d.coverage);
    EXPECT_NE(summary.reason, engine::TerminationReason::Diverged) << "trial " << trial;
    EXPECT_LE(d.rmsDistance, 0.01 * diagonal) << "trial " << trial;
    developable += warp <= 0.05;
    ++cases;
  }
  EXPECT_EQ(developable, cases) << "composites with warp ≤ 0.05° after 20 iterations";
}

}  // namespace
}  // namespace devsurf::models::composite
