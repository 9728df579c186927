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

TEST(CompositeFromStrips, ADisjointUnionKeepsEveryPartAsItWasWithItsIndicesMovedOn) {
  // Two sheets of two and three strips, the second lifted to z = 1, a fixed vertex and a handle on
  // the second: the union is both, and solving it leaves each part where it was.
  std::vector<CompositeDesign> parts;
  for (int count : {2, 3}) {
    std::vector<StripDesign> strips;
    for (int k = 0; k < count; ++k) strips.push_back(flatStrip(0.3 * k, 0.3 * (k + 1)));
    parts.push_back(compositeFromStrips(strips, strip::proposeBoundaryPairings(strips), CreaseKind::None));
  }
  parts[1].vertices.col(2).array() += 1.0;
  for (CompositeEdge& e : parts[1].edges)
    if (e.curve.points.rows() > 0) e.curve.points.col(2).array() += 1.0;
  parts[1].fixed.push_back(PointRef::ofVertex(1));
  parts[1].handles.push_back({PointRef::ofEdgePoint(0, 2), Eigen::Vector3d(0.4, 0.0, 1.0), 1.0});
  const CompositeDesign both = disjointUnion(parts);
  ASSERT_EQ(both.vertices.rows(), parts[0].vertices.rows() + parts[1].vertices.rows());
  ASSERT_EQ(both.edges.size(), parts[0].edges.size() + parts[1].edges.size());
  ASSERT_EQ(both.faces.size(), 5u);
  const int v0 = static_cast<int>(parts[0].vertices.rows()), e0 = static_cast<int>(parts[0].edges.size());
  EXPECT_EQ(both.vertices.bottomRows(parts[1].vertices.rows()), parts[1].vertices);
  for (std::size_t f = 0; f < parts[1].faces.size(); ++f)
    for (std::size_t k = 0; k < parts[1].faces[f].size(); ++k)
      EXPECT_EQ(both.faces[parts[0].faces.size() + f][k], parts[1].faces[f][k] + e0);
  for (std::size_t e = 0; e < parts[1].edges.size(); ++e) {
    EXPECT_EQ(both.edges[e0 + e].v0, parts[1].edges[e].v0 + v0);
    EXPECT_EQ(both.edges[e0 + e].v1, parts[1].edges[e].v1 + v0);
  }
  ASSERT_EQ(both.fixed.size(), 1u);
  EXPECT_EQ(both.fixed[0].vertex, 1 + v0);
  ASSERT_EQ(both.handles.size(), 1u);
  EXPECT_EQ(both.handles[0].point.edge, e0);
  EXPECT_EQ(both.handles[0].point.index, 2);
  CompositeModel model(both);
  engine::SolverOptions options;
  options.maxIterations = 3;
  model.solve(options);
  EXPECT_LT(model.quality().warpAngleMaxDeg, 1e-6);
  EXPECT_LT(model.design().vertices.topRows(v0).col(2).cwiseAbs().maxCoeff(), 1e-9);

  CompositeDesign sheet = parts[0];
  sheet.developmentSamples = 4;
  EXPECT_THROW(disjointUnion({sheet, parts[1]}), std::invalid_argument);
  EXPECT_THROW(disjointUnion({}), std::invalid_argument);
}

}  // namespace
}  // namespace devsurf::models::composite
