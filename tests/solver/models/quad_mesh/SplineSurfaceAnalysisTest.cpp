// The spline M^∞ of a control mesh (issue 14): patches refined and merged into one watertight
// S^k(M), the analysis of the bicubic surface itself against exact oracles (polynomial surfaces
// whose control nets come from blossoms), normal jumps across shared sides, and the checks that
// name a malformed net's field.
#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <iostream>
#include <map>
#include <set>
#include <stdexcept>

#include <Eigen/Geometry>

#include "devsurf/models/quad_mesh/QuadMeshModel.h"
#include "devsurf/models/quad_mesh/SplineSurface.h"
#include "devsurf/spline/CubicSubdivision.h"

namespace devsurf::models::quad_mesh {
namespace {

/// The knots k_{i+1}, k_{i+2}, k_{i+3} of control point i of a clamped cubic with n points and
/// uniform interior knots 0, 1, …, n − 3, mapped to x = x0 + h·t.
std::array<double, 3> controlKnots(int n, int i, double x0, double h) {
  std::vector<double> k(4, 0.0);
  for (int j = 1; j <= n - 4; ++j) k.push_back(j);
  for (int j = 0; j < 4; ++j) k.push_back(n - 3);
  return {x0 + h * k[i + 1], x0 + h * k[i + 2], x0 + h * k[i + 3]};
}

/// Control point coordinate of a cubic polynomial c0 + c1 x + c2 x² + c3 x³ (its blossom).
double blossom(const std::array<double, 3>& x, const std::array<double, 4>& c) {
  const double s1 = (x[0] + x[1] + x[2]) / 3.0, s2 = (x[0] * x[1] + x[0] * x[2] + x[1] * x[2]) / 3.0,
               s3 = x[0] * x[1] * x[2];
  return c[0] + c[1] * s1 + c[2] * s2 + c[3] * s3;
}

/// One patch over [x0, x0 + (columns−3)h] × [y0, …] of z = f(x) + g(y), f and g cubic polynomials:
/// exactly a bicubic B-spline.
ControlNet polynomialNet(int rows, int columns, double h, const std::array<double, 4>& f, const std::array<double, 4>& g,
                         double x0 = 0.0, double y0 = 0.0) {
  ControlNet net;
  net.rows = rows;
  net.columns = columns;
  net.points.resize(rows * columns, 3);
  for (int r = 0; r < rows; ++r)
    for (int c = 0; c < columns; ++c) {
      const auto kx = controlKnots(columns, c, x0, h), ky = controlKnots(rows, r, y0, h);
      net.points.row(r * columns + c) << blossom(kx, {0, 1, 0, 0}), blossom(ky, {0, 1, 0, 0}),
          blossom(kx, f) + blossom(ky, g);
    }
  return net;
}

TEST(SplineSurfaceAnalysis, GaussianCurvatureOfAParaboloidMatchesTheFormulaAtEverySample) {
  // z = a x² + b y²: K = 4ab / (1 + 4a²x² + 4b²y²)².
  const double a = 0.3, b = -0.2;
  const ControlNet net = polynomialNet(6, 7, 0.5, {0, 0, a, 0}, {0, 0, b, 0}, -1.0, -0.8);
  const SplineSurfaceAnalysis s = analyzeSplineSurface(net, net.points);
  ASSERT_EQ(s.samples.size(), 1u);
  double worst = 0.0;
  for (Eigen::Index i = 0; i < s.samples[0].rows(); ++i) {
    const double x = s.samples[0](i, 0), y = s.samples[0](i, 1);
    EXPECT_NEAR(s.samples[0](i, 2), a * x * x + b * y * y, 1e-12);
    const double q = 1 + 4 * a * a * x * x + 4 * b * b * y * y;
    worst = std::max(worst, std::abs(s.gauss[0][i] - 4 * a * b / (q * q)));
  }
  EXPECT_LT(worst, 1e-10);
  EXPECT_GT(s.gaussMaxScaled, 0.1);
  EXPECT_TRUE(s.rulings.empty()) << "a saddle has no rulings";
}

TEST(SplineSurfaceAnalysis, ACubicCylinderHasZeroCurvatureAndStraightRulingsAcrossThePatch) {
  // z = 0.4 x³ − 0.3 x: K = 0 exactly; its rulings are the lines x = const.
  const ControlNet net = polynomialNet(7, 8, 0.4, {0, -0.3, 0, 0.4}, {0, 0, 0, 0}, -1.0, -1.0);
  const SplineSurfaceAnalysis s = analyzeSplineSurface(net, net.points);
  EXPECT_LT(s.gaussMaxScaled, 1e-10);
  ASSERT_GE(s.rulings.size(), 10u);
  const double yMin = net.points.col(1).minCoeff(), yMax = net.points.col(1).maxCoeff();
  for (const Eigen::MatrixX3d& r : s.rulings) {
    EXPECT_LT(r.col(0).maxCoeff() - r.col(0).minCoeff(), 1e-6) << "a ruling runs along y";
    EXPECT_NEAR(r.col(1).minCoeff(), yMin, 1e-9) << "and spans the patch";
    EXPECT_NEAR(r.col(1).maxCoeff(), yMax, 1e-9);
  }
}

/// Two patches side by side sharing column 0 of B = last column of A; B's columns are A's grid
/// continued by `next` (a function of the column index c ≥ 0 of B and the row).
ControlNet twoPatches(const std::function<Eigen::Vector3d(int, int)>& pointA,
                      const std::function<Eigen::Vector3d(int, int)>& pointB, int rows = 6, int columns = 6) {
  ControlNet net;
  net.rounds = 2;
  std::vector<Eigen::Vector3d> points;
  ControlPatch a{rows, columns, {}}, b{rows, columns, {}};
  for (int r = 0; r < rows; ++r)
    for (int c = 0; c < columns; ++c) {
      a.indices.push_back(static_cast<int>(points.size()));
      points.push_back(pointA(r, c));
    }
  for (int r = 0; r < rows; ++r)
    for (int c = 0; c < columns; ++c) {
      if (c == 0) {
        b.indices.push_back(a.indices[static_cast<std::size_t>(r * columns + columns - 1)]);
        continue;
      }
      b.indices.push_back(static_cast<int>(points.size()));
      points.push_back(pointB(r, c));
    }
  net.points.resize(static_cast<Eigen::Index>(points.size()), 3);
  for (std::size_t i = 0; i < points.size(); ++i) net.points.row(static_cast<Eigen::Index>(i)) = points[i].transpose();
  net.patches = {a, b};
  return net;
}

TEST(SplineSurfaceAnalysis, PatchesMeetingAtAKinkReportTheKinkAngleAsTheNormalJump) {
  // A flat in z = 0 over x ∈ [0, 1]; B turned up by 30° about the shared line x = 1.
  const double angle = 30.0 * M_PI / 180.0;
  const ControlNet net = twoPatches([](int r, int c) { return Eigen::Vector3d(c / 5.0, r / 5.0, 0.0); },
                                    [angle](int r, int c) {
                                      return Eigen::Vector3d(1.0 + c / 5.0 * std::cos(angle), r / 5.0,
                                                             c / 5.0 * std::sin(angle));
                                    });
  const SplineSurfaceAnalysis s = analyzeSplineSurface(net, net.points);
  EXPECT_EQ(s.sharedSides, 1);
  EXPECT_NEAR(s.normalJumpMaxDegrees, 30.0, 1e-9);
}

TEST(SplineSurfaceAnalysis, PatchesWhoseNetsMirrorAcrossTheSideJoinWithoutANormalJump) {
  // B's second column is 2b − a (the smoothness rows hold): C1, so no jump, though B curves on.
  auto a = [](int r, int c) { return Eigen::Vector3d(c / 5.0, r / 5.0, 0.3 * (c / 5.0) * (c / 5.0) + 0.1 * r * c / 25.0); };
  const ControlNet net = twoPatches(a, [&a](int r, int c) {
    if (c == 1) return Eigen::Vector3d(2.0 * a(r, 5) - a(r, 4));
    return Eigen::Vector3d(1.0 + c / 5.0, r / 5.0, 0.3 + 0.2 * c / 5.0 - 0.4 * (c / 5.0) * (c / 5.0) + 0.1 * r / 5.0);
  });
  const SplineSurfaceAnalysis s = analyzeSplineSurface(net, net.points);
  EXPECT_EQ(s.sharedSides, 1);
  EXPECT_LT(s.normalJumpMaxDegrees, 1e-6);
  for (const auto& t : splineSmoothnessTriples(net))
    EXPECT_LT((net.points.row(t[0]) - 2 * net.points.row(t[1]) + net.points.row(t[2])).norm(), 1e-12);
}

/// A 2 × 2 arrangement of 5 × 6 patches over one 9 × 11 grid of points (sharing the middle row
/// and column), z a smooth bump.
ControlNet fourPatches(int rounds) {
  ControlNet net;
  net.rounds = rounds;
  const int R = 9, C = 11;
  net.points.resize(R * C, 3);
  for (int r = 0; r < R; ++r)
    for (int c = 0; c < C; ++c) {
      const double x = c / 10.0, y = r / 8.0;
      net.points.row(r * C + c) << x, y, 0.2 * std::sin(2.0 * x) * std::cos(y);
    }
  for (int pr : {0, 4})
    for (int pc : {0, 5}) {
      ControlPatch p{5, 6, {}};
      for (int r = 0; r < 5; ++r)
        for (int c = 0; c < 6; ++c) p.indices.push_back((pr + r) * C + pc + c);
      net.patches.push_back(p);
    }
  return net;
}

TEST(SplineRefinement, PatchesSharingSidesRefineIntoOneWatertightGrid) {
  for (int rounds : {0, 1, 2, 3}) {
    const ControlNet net = fourPatches(rounds);
    const SplineRefinement s = splineRefinement(net);
    const int r = spline::cubicSubdividedCount(5, rounds), c = spline::cubicSubdividedCount(6, rounds);
    EXPECT_EQ(s.subdivision.rows(), (2 * r - 1) * (2 * c - 1)) << "shared sides merged, rounds " << rounds;
    EXPECT_EQ(s.faces.size(), 4u * (r - 1) * (c - 1));
    // Every refined vertex is an affine combination of control points.
    const Eigen::VectorXd sums = s.subdivision * Eigen::VectorXd::Ones(net.points.rows());
    EXPECT_LT((sums.array() - 1.0).abs().maxCoeff(), 1e-12);
    // Watertight: every interior edge has two faces, the boundary is one loop of 2(2r−2)+2(2c−2) edges.
    std::map<std::pair<int, int>, int> directed;
    for (const Face& f : s.faces)
      for (int k = 0; k < 4; ++k) ++directed[{f[k], f[(k + 1) % 4]}];
    int boundary = 0;
    for (const auto& [e, n] : directed) {
      EXPECT_EQ(n, 1) << "an edge used twice the same way: orientations disagree";
      if (!directed.count({e.second, e.first})) ++boundary;
    }
    EXPECT_EQ(boundary, 2 * (2 * r - 2) + 2 * (2 * c - 2));
    // The model builds on it (OpenMesh topology, one connected manifold sheet).
    QuadMeshModel model(splineSurfaceDesign(net));
    EXPECT_EQ(model.topology().vertexCount(), s.subdivision.rows());
  }
}

TEST(SplineRefinement, ARefinedSharedSideIsTheRefinedBoundaryCurveOfBothPatches) {
  const ControlNet net = fourPatches(3);
  const SplineRefinement s = splineRefinement(net);
  const Eigen::MatrixX3d refined = s.subdivision * net.points;
  // Each patch refined alone, its vertices compared with the merged mesh's.
  for (std::size_t p = 0; p < net.patches.size(); ++p) {
    Eigen::MatrixX3d local(30, 3);
    for (int i = 0; i < 30; ++i) local.row(i) = net.points.row(net.patches[p].indices[static_cast<std::size_t>(i)]);
    const Eigen::MatrixX3d alone = spline::cubicGridSubdivisionMatrix(5, 6, 3) * local;
    for (Eigen::Index v = 0; v < alone.rows(); ++v)
      EXPECT_LT((alone.row(v) - refined.row(s.patchVertices[p][static_cast<std::size_t>(v)])).norm(), 1e-14);
  }
}

/// What splineRefinement says of a net: its refusal, or "accepted".
std::string message(const ControlNet& net) {
  try {
    splineRefinement(net);
  } catch (const std::invalid_argument& e) {
    return std::string(e.what());
  }
  return std::string("accepted");
}

TEST(SplineRefinement, MalformedNetsAreRefusedNamingTheField) {
  ControlNet net = fourPatches(2);
  net.patches[1].indices[7] = 500;
  EXPECT_NE(message(net).find("control.patches[1].indices[7]"), std::string::npos) << message(net);
  net = fourPatches(2);
  net.patches[2].indices[8] = net.patches[2].indices[9];
  EXPECT_NE(message(net).find("control.patches[2].indices: control point"), std::string::npos) << message(net);
  net = fourPatches(2);
  net.patches[3].rows = 3;
  EXPECT_NE(message(net).find("control.patches[3]: a bicubic patch"), std::string::npos) << message(net);
  net = fourPatches(2);
  net.patches.pop_back();  // points of the fourth patch no longer used
  EXPECT_NE(message(net).find("no patch uses it"), std::string::npos) << message(net);
  net = fourPatches(2);
  // Patch 1 with its rows reversed: its faces face the other way.
  ControlPatch& p = net.patches[1];
  std::vector<int> flipped;
  for (int r = p.rows - 1; r >= 0; --r)
    for (int c = 0; c < p.columns; ++c) flipped.push_back(p.indices[static_cast<std::size_t>(r * p.columns + c)]);
  p.indices = flipped;
  EXPECT_NE(message(net).find("face opposite ways"), std::string::npos) << message(net);
  net = fourPatches(2);
  net.points(3, 1) = std::nan("");
  EXPECT_NE(message(net).find("control.points"), std::string::npos) << message(net);
  net = fourPatches(2);
  net.rounds = 5;
  EXPECT_NE(message(net).find("control.rounds"), std::string::npos) << message(net);
}

/// The net with control points no patch uses dropped and the patches' indices renumbered.
ControlNet withoutUnusedPoints(ControlNet net) {
  std::vector<int> renumber(static_cast<std::size_t>(net.points.rows()), -1);
  int used = 0;
  for (ControlPatch& p : net.patches)
    for (int& i : p.indices) {
      if (renumber[static_cast<std::size_t>(i)] < 0) renumber[static_cast<std::size_t>(i)] = used++;
      i = renumber[static_cast<std::size_t>(i)];
    }
  Eigen::MatrixX3d kept(used, 3);
  for (std::size_t i = 0; i < renumber.size(); ++i)
    if (renumber[i] >= 0) kept.row(renumber[i]) = net.points.row(static_cast<Eigen::Index>(i));
  net.points = kept;
  return net;
}

TEST(SplineRefinement, PatchesMeetingOffAWholeSharedSideAreRefusedAsAGap) {
  // A T-junction: patch 1 of the 2 × 2 arrangement replaced by a 4 × 4 patch whose corner sits in
  // the middle of patch 0's right side (grid column 5) and that shares only rows 1 … 4 of it.
  ControlNet net = fourPatches(2);
  const int C = 11;
  const Eigen::Index first = net.points.rows();
  ControlPatch t{4, 4, {}};
  net.points.conservativeResize(first + 12, 3);
  int extra = 0;
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c) {
      if (c == 0) {
        t.indices.push_back((r + 1) * C + 5);
        continue;
      }
      net.points.row(first + extra) << 0.5 + 0.1 * c, (r + 1) / 8.0, 0.0;
      t.indices.push_back(static_cast<int>(first + extra++));
    }
  net.patches.erase(net.patches.begin() + 1);
  net.patches.push_back(t);
  std::string m = message(withoutUnusedPoints(net));
  EXPECT_NE(m.find("control.patches[3].indices[0]"), std::string::npos) << m;
  EXPECT_NE(m.find("T-junction"), std::string::npos) << m;
  // Touching at a corner only is accepted (one shared refined vertex there).
  net = fourPatches(2);
  net.patches = {net.patches[0], net.patches[3]};
  EXPECT_EQ(message(withoutUnusedPoints(net)), "accepted");
  // Three patches meeting at one corner (an L): accepted.
  net = fourPatches(2);
  net.patches.pop_back();
  EXPECT_EQ(message(withoutUnusedPoints(net)), "accepted");
  // Two patches sharing two sides (a ring: B's last column is A's first): accepted.
  {
    ControlNet ring;
    ring.rounds = 1;
    const int rows = 5, columns = 10;  // points around: column c of the ring, c mod 10
    ring.points.resize(rows * columns, 3);
    for (int r = 0; r < rows; ++r)
      for (int c = 0; c < columns; ++c) {
        const double angle = 2 * M_PI * c / columns;
        ring.points.row(r * columns + c) << std::cos(angle), std::sin(angle), 0.3 * r;
      }
    ControlPatch a{rows, 6, {}}, b{rows, 6, {}};
    for (int r = 0; r < rows; ++r)
      for (int c = 0; c < 6; ++c) {
        a.indices.push_back(r * columns + c);
        b.indices.push_back(r * columns + (c + 5) % columns);
      }
    ring.patches = {a, b};
    EXPECT_EQ(message(ring), "accepted");
    EXPECT_EQ(splineSharedSides(ring).size(), 2u);
  }
  // An interior point of one patch used by another: refused.
  net = fourPatches(2);
  net.patches[3].indices[7] = net.patches[0].indices[7];
  m = message(withoutUnusedPoints(net));
  EXPECT_NE(m.find("control.patches[3].indices[7]"), std::string::npos) << m;
}

/// Two patches meeting at a 40° kink (each a plane, so developable), their far columns held (E_pos
/// on the control points), solved with the given smoothness: the analysis of M^∞ before and after.
struct KinkSolve {
  SplineSurfaceAnalysis before, after;
  double lengthError = 0.0;
};
KinkSolve kinkSolved(double smoothness) {
  const double angle = 40.0 * M_PI / 180.0;
  ControlNet net = twoPatches([](int r, int c) { return Eigen::Vector3d(c / 5.0, r / 5.0, 0.0); },
                              [angle](int r, int c) {
                                return Eigen::Vector3d(1.0 + c / 5.0 * std::cos(angle), r / 5.0, c / 5.0 * std::sin(angle));
                              });
  net.smoothness = smoothness;
  QuadMeshDesign d = splineSurfaceDesign(net);
  for (int r = 0; r < 6; ++r)
    for (int i : {net.patches[0].indices[static_cast<std::size_t>(r * 6)], net.patches[1].indices[static_cast<std::size_t>(r * 6 + 5)]})
      d.handles.push_back({{MeshSide::Control, i}, net.points.row(i).transpose(), 1.0});
  d.schedule.roundIterations = 20;
  d.schedule.rounds = 5;
  QuadMeshModel model(d);
  engine::SolverOptions options;
  options.maxIterations = 100;
  model.solve(options);
  return {analyzeSplineSurface(net, net.points), analyzeSplineSurface(net, model.controlPoints()),
          model.quality().lengthError};
}

TEST(SplineSurfaceModel, SmoothnessAcrossSharedSidesClosesAKinkWhileTheSheetStaysDevelopable) {
  // Asked for smoothness, the optimization rounds the kink into a developable bend.
  const KinkSolve k = kinkSolved(1.0);
  std::cout << "kink " << k.before.normalJumpMaxDegrees << "° → normal jump " << k.after.normalJumpMaxDegrees
            << "°, |K|·d² max " << k.after.gaussMaxScaled << " mean " << k.after.gaussMeanScaled << ", L-Err "
            << 100 * k.lengthError << " %\n";
  EXPECT_NEAR(k.before.normalJumpMaxDegrees, 40.0, 1e-9);
  EXPECT_LT(k.after.normalJumpMaxDegrees, 2.0);
  EXPECT_LT(k.lengthError, 0.01);
  EXPECT_LT(k.after.gaussMeanScaled, 0.5);
}

TEST(SplineSurfaceModel, WithoutSmoothnessNoTermSmoothsAcrossTheSharedSide) {
  // Without smoothness asked, fairness and E_map keep to polylines within a patch: the patches may
  // meet at an angle (a crease line between patches). What still rounds the kink (to ~7.5°) is
  // fairness within the patches: S^k(M) of a uniform clamped net is not uniformly spaced near its
  // boundary (the end stencils), its second differences there are not zero, and evening them out
  // moves the side's neighbours in both patches' planes at once (measured: round-0 E_fair 6e-4
  // at the start, every other term < 1e-10).
  const KinkSolve kept = kinkSolved(0.0);
  // A vanishing smoothness weight: the across-side fairness and E_map rows are back, the
  // smoothness rows weigh nothing.
  const KinkSolve rounded = kinkSolved(1e-12);
  std::cout << "kink 40° without smoothness → normal jump " << kept.after.normalJumpMaxDegrees
            << "° (with polylines across the side: " << rounded.after.normalJumpMaxDegrees << "°), L-Err "
            << 100 * kept.lengthError << " %\n";
  EXPECT_GT(kept.after.normalJumpMaxDegrees, rounded.after.normalJumpMaxDegrees + 3.0);
  EXPECT_LT(kept.lengthError, 0.01);
}

}  // namespace
}  // namespace devsurf::models::quad_mesh
