// Gauss image of a quad mesh with M fixed (004_… §2.2, §3.2): the solved vertex normals give the
// curvatures of the smooth surface the mesh samples (checked against analytic K, H and rulings).
//
// Sign convention (004_… §2.2.1, s = −dn): the solve puts the normals on the front side of the
// faces (counter-clockwise seen from there); curvature is positive where the surface bends
// toward that side. A sphere seen from outside has H = −1/r, a cylinder seen from inside (front =
// the side of the axis) H = +1/(2r).

#include <gtest/gtest.h>

#include "support/QuadGridTesting.h"

#include <algorithm>
#include <cmath>
#include <iostream>
#include <stdexcept>
#include <utility>

#include <Eigen/Geometry>

#include "devsurf/metrics/CheckerboardCurvature.h"
#include "devsurf/models/quad_mesh/GaussImage.h"

namespace devsurf::models::quad_mesh {
namespace {

using devsurf::testing::QuadGrid;
using devsurf::testing::quadGrid;
using metrics::checkerboardCurvature;
using metrics::FaceCurvature;

std::vector<FaceCurvature> solvedCurvatures(const QuadGrid& grid) {
  const Eigen::MatrixX3d normals = solveGaussImage(grid.vertices, grid.faces, grid.triples);
  EXPECT_TRUE(normals.allFinite());
  return checkerboardCurvature(grid.vertices, normals, grid.faces);
}

/// Latitude band |v| ≤ 1.2 of a sphere of radius r, faces counter-clockwise seen from outside.
QuadGrid sphereBand(double r, int cells) {
  return quadGrid(
      [r](double u, double v) {
        return Eigen::Vector3d(r * std::cos(v) * std::cos(u), r * std::cos(v) * std::sin(u),
                               r * std::sin(v));
      },
      0.0, 2 * M_PI, 2 * cells, -1.2, 1.2, cells, true);
}

/// Closed cylinder band of radius r and height 1 with 2·cells × cells/2 faces; the front side is
/// the axis side (`inside`) or the outside.
QuadGrid cylinder(double r, int cells, bool inside) {
  const double sign = inside ? -1.0 : 1.0;
  return quadGrid(
      [r, sign](double u, double v) {
        return Eigen::Vector3d(r * std::cos(u), sign * r * std::sin(u), v);
      },
      0.0, 2 * M_PI, 2 * cells, 0.0, 1.0, cells / 2, true);
}

TEST(GaussImage, SphereNormalsPointOutwardAndGiveKOneOverRSquared) {
  const double r = 2.0;
  double previous = 0.0;
  for (int cells : {16, 32}) {
    const QuadGrid grid = sphereBand(r, cells);
    const Eigen::MatrixX3d normals = solveGaussImage(grid.vertices, grid.faces, grid.triples);
    double normError = 0.0;
    for (Eigen::Index i = 0; i < normals.rows(); ++i) {
      EXPECT_GT(normals.row(i).dot(grid.vertices.row(i)), 0.0);  // front = outside
      normError = std::max(normError, std::abs(normals.row(i).norm() - 1.0));
    }
    double gaussError = 0.0, meanError = 0.0;
    for (const FaceCurvature& c : checkerboardCurvature(grid.vertices, normals, grid.faces)) {
      gaussError = std::max(gaussError, std::abs(c.gauss * r * r - 1.0));
      meanError = std::max(meanError, std::abs(-c.mean * r - 1.0));
    }
    std::cout << "sphere " << 2 * cells << "×" << cells << ": max |K r² − 1| = " << gaussError
              << ", max |−H r − 1| = " << meanError << ", max ||n| − 1| = " << normError << "\n";
    EXPECT_LT(gaussError, cells == 16 ? 0.025 : 0.007);
    EXPECT_LT(meanError, cells == 16 ? 0.012 : 0.0035);
    if (previous > 0.0) {
      EXPECT_LT(gaussError, previous / 3.0);  // second order
    }
    previous = gaussError;
  }
}

TEST(GaussImage, CylinderSeenFromInsideHasZeroKHalfOverRAndRulingsAlongTheAxis) {
  const double r = 0.5;
  for (bool inside : {true, false}) {
    const QuadGrid grid = cylinder(r, 16, inside);
    double gaussMax = 0.0, meanError = 0.0, rulingAngle = 0.0;
    for (const FaceCurvature& c : solvedCurvatures(grid)) {
      gaussMax = std::max(gaussMax, std::abs(c.gauss));
      meanError = std::max(meanError, std::abs((inside ? c.mean : -c.mean) * 2 * r - 1.0));
      rulingAngle = std::max(rulingAngle, std::acos(std::min(1.0, std::abs(c.ruling.z()))));
    }
    std::cout << "cylinder 32×8 (front " << (inside ? "inside" : "outside")
              << "): max |K| = " << gaussMax << ", max |±2rH − 1| = " << meanError
              << ", max ruling angle to the axis = " << rulingAngle << " rad\n";
    EXPECT_LT(gaussMax, 1e-9);
    EXPECT_LT(meanError, 0.01);
    EXPECT_LT(rulingAngle, 1e-6);
  }
}

/// max |K − K(face centre)| ÷ max |K| on a torus R = 2, r = 0.7 with 2·cells × cells faces.
double torusGaussError(int cells) {
  const double R = 2.0, r = 0.7;
  const QuadGrid grid = quadGrid(
      [R, r](double u, double v) {
        return Eigen::Vector3d((R + r * std::cos(v)) * std::cos(u),
                               (R + r * std::cos(v)) * std::sin(u), r * std::sin(v));
      },
      0.0, 2 * M_PI, 2 * cells, 0.0, 2 * M_PI, cells, true, true);
  const std::vector<FaceCurvature> curvatures = solvedCurvatures(grid);
  double error = 0.0, largest = 0.0, lowest = 0.0, highest = 0.0;
  for (size_t f = 0; f < curvatures.size(); ++f) {
    const double v = grid.faceCentres[f].y();
    const double exact = std::cos(v) / (r * (R + r * std::cos(v)));
    error = std::max(error, std::abs(curvatures[f].gauss - exact));
    largest = std::max(largest, std::abs(exact));
    lowest = std::min(lowest, curvatures[f].gauss);
    highest = std::max(highest, curvatures[f].gauss);
  }
  // Both signs, near the extremes 1/(r(R + r)) = 0.529 and −1/(r(R − r)) = −1.099.
  EXPECT_GT(highest, 0.5);
  EXPECT_LT(lowest, -1.0);
  return error / largest;
}

TEST(GaussImage, TorusGaussCurvatureOfBothSignsConvergesToTheAnalyticValue) {
  const double coarse = torusGaussError(16), fine = torusGaussError(32);
  std::cout << "torus: max |ΔK| / max |K| = " << coarse << " (32×16), " << fine << " (64×32)\n";
  EXPECT_LT(coarse, 0.02);
  EXPECT_LT(fine, 0.005);
  EXPECT_LT(fine, coarse / 3.0);
}

/// Largest relative K error on z = ½(x² − y²) + 0.1 x³ over [−1, 1]² (cells × cells faces), for
/// faces with centres in |x|, |y| < 0.75 (`interior`) and for all faces.
std::pair<double, double> graphGaussErrors(int cells) {
  // K = f_xx f_yy / (1 + f_x² + f_y²)² < 0 everywhere (f_xx = 1 + 0.6x ≥ 0.4, f_yy = −1).
  const QuadGrid grid = quadGrid(
      [](double x, double y) {
        return Eigen::Vector3d(x, y, 0.5 * (x * x - y * y) + 0.1 * x * x * x);
      },
      -1.0, 1.0, cells, -1.0, 1.0, cells);
  const std::vector<FaceCurvature> curvatures = solvedCurvatures(grid);
  double interior = 0.0, all = 0.0;
  for (size_t f = 0; f < curvatures.size(); ++f) {
    const double x = grid.faceCentres[f].x(), y = grid.faceCentres[f].y();
    const double fx = x + 0.3 * x * x, fy = -y, fxx = 1.0 + 0.6 * x, fyy = -1.0;
    const double exact = fxx * fyy / std::pow(1.0 + fx * fx + fy * fy, 2);
    const double error = std::abs(curvatures[f].gauss / exact - 1.0);
    all = std::max(all, error);
    if (std::abs(x) < 0.75 && std::abs(y) < 0.75) interior = std::max(interior, error);
  }
  return {interior, all};
}

TEST(GaussImage, GraphSurfaceGaussCurvatureIsWithinOnePercentAwayFromTheBoundary) {
  const auto [coarse, coarseAll] = graphGaussErrors(20);
  const auto [fine, fineAll] = graphGaussErrors(40);
  std::cout << "graph: max relative K error for |x|, |y| < 0.75: " << coarse << " (20×20), "
            << fine << " (40×40); all faces " << coarseAll << ", " << fineAll << "\n";
  EXPECT_LT(coarse, 0.01);
  EXPECT_LT(fine, coarse / 3.0);
}

/// Cone with apex 0, axis z, half angle 0.5, t ∈ [1, 2] along the rulings, sampled on
/// cellsU × cellsU/3 cells with θ = u + skew·v: for skew ≠ 0 no mesh polyline follows a ruling.
QuadGrid cone(int cellsU, double skew) {
  const double alpha = 0.5;
  return quadGrid(
      [alpha, skew](double u, double v) {
        const double theta = u + skew * v, t = 1.0 + v;
        return Eigen::Vector3d(t * std::sin(alpha) * std::cos(theta),
                               t * std::sin(alpha) * std::sin(theta), t * std::cos(alpha));
      },
      0.0, M_PI, cellsU, 0.0, 1.0, cellsU / 3);
}

struct RulingErrors {
  double interiorAngle = 0.0;  ///< largest angle (rad) to the true ruling, boundary faces off
  double angle = 0.0;          ///< the same over all faces
  double gaussRatio = 0.0;     ///< largest |K| / H² (0 on a developable)
};

/// The true ruling at a face: from the apex to the face's vertex centroid, projected into the
/// face plane.
RulingErrors coneRulingErrors(const QuadGrid& grid, int cellsU) {
  RulingErrors errors;
  const std::vector<FaceCurvature> curvatures = solvedCurvatures(grid);
  for (size_t f = 0; f < curvatures.size(); ++f) {
    const FaceCurvature& c = curvatures[f];
    Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
    for (int vertex : grid.faces[f]) centroid += grid.vertices.row(vertex).transpose() / 4.0;
    const Eigen::Vector3d ruling = (centroid - centroid.dot(c.normal) * c.normal).normalized();
    const double angle = std::acos(std::min(1.0, std::abs(ruling.dot(c.ruling))));
    errors.angle = std::max(errors.angle, angle);
    const auto& [i, j] = grid.faceCells[f];
    if (std::min({i, j, cellsU - 1 - i, cellsU / 3 - 1 - j}) >= 1)
      errors.interiorAngle = std::max(errors.interiorAngle, angle);
    errors.gaussRatio = std::max(errors.gaussRatio, std::abs(c.gauss) / (c.mean * c.mean));
  }
  return errors;
}

TEST(GaussImage, ConeRulingsPassThroughTheApexAlsoOnAMeshNotAlignedWithThem) {
  for (double skew : {0.0, 0.6})
    for (int cells : {24, 48}) {
      const RulingErrors e = coneRulingErrors(cone(cells, skew), cells);
      std::cout << "cone " << cells << "×" << cells / 3 << ", skew " << skew
                << ": ruling angle max " << e.angle << " rad (interior " << e.interiorAngle
                << "), max |K| / H² " << e.gaussRatio << "\n";
      EXPECT_LT(e.interiorAngle, 1e-3);
      EXPECT_LT(e.angle, 0.02);
      // Aligned: K ≈ 0. Skewed: K is far less accurate (see GaussImageOptions::anchorWeight).
      EXPECT_LT(e.gaussRatio, skew == 0.0 ? 0.03 : 0.35);
    }
}

TEST(GaussImage, ConeNormalsDoNotDriftTowardTheDegenerateGaussImageWithMoreIterations) {
  // Without the direction anchor, 50 iterations move the normals of this cone most of the way to
  // the constant normal −e_z / sin(0.5) (|n| = 2.09), which also satisfies eq. 3 and 5.
  const QuadGrid grid = cone(24, 0.6);
  GaussImageOptions few, many;
  few.iterations = 10;
  many.iterations = 50;
  const Eigen::MatrixX3d a = solveGaussImage(grid.vertices, grid.faces, grid.triples, few);
  const Eigen::MatrixX3d b = solveGaussImage(grid.vertices, grid.faces, grid.triples, many);
  EXPECT_LT((a - b).cwiseAbs().maxCoeff(), 1e-6);
  EXPECT_LT(b.rowwise().norm().maxCoeff(), 1.01);
}

TEST(GaussImage, PlaneWithATriangleGetsTheUnitPlaneNormalEverywhere) {
  // 3×3 vertices in z = 0.3 and a triangle on the right border; normals are exactly e_z.
  QuadGrid grid = quadGrid([](double x, double y) { return Eigen::Vector3d(x, y, 0.3); }, 0.0,
                           2.0, 2, 0.0, 2.0, 2);
  grid.vertices.conservativeResize(10, 3);
  grid.vertices.row(9) << 3.0, 0.5, 0.3;
  grid.faces.push_back({2, 9, 5, -1});
  const Eigen::MatrixX3d normals = solveGaussImage(grid.vertices, grid.faces, grid.triples);
  for (Eigen::Index i = 0; i < normals.rows(); ++i)
    EXPECT_LT((normals.row(i) - Eigen::RowVector3d(0, 0, 1)).norm(), 1e-9) << "vertex " << i;
  for (const FaceCurvature& c : checkerboardCurvature(grid.vertices, normals, grid.faces)) {
    EXPECT_NEAR(c.gauss, 0.0, 1e-9);
    EXPECT_NEAR(c.mean, 0.0, 1e-9);
  }
}

TEST(GaussImage, NormalsDoNotDependOnTheScaleOfTheMesh) {
  const QuadGrid grid = sphereBand(1.0, 8);
  const Eigen::MatrixX3d unit = solveGaussImage(grid.vertices, grid.faces, grid.triples);
  const Eigen::MatrixX3d large =
      solveGaussImage(100.0 * grid.vertices, grid.faces, grid.triples);
  EXPECT_LT((unit - large).cwiseAbs().maxCoeff(), 1e-9);
}

TEST(GaussImage, RefusesBadFacesTriplesAndUnusedVertices) {
  const QuadGrid grid = sphereBand(1.0, 4);
  std::vector<std::array<int, 4>> faces = grid.faces;
  faces[0][2] = static_cast<int>(grid.vertices.rows());
  EXPECT_THROW(solveGaussImage(grid.vertices, faces, grid.triples), std::invalid_argument);
  std::vector<std::array<int, 3>> triples = grid.triples;
  triples[1] = {0, 1, 0};
  EXPECT_THROW(solveGaussImage(grid.vertices, grid.faces, triples), std::invalid_argument);
  Eigen::MatrixX3d extra = grid.vertices;
  extra.conservativeResize(extra.rows() + 1, 3);
  extra.row(extra.rows() - 1).setZero();
  EXPECT_THROW(solveGaussImage(extra, grid.faces, grid.triples), std::invalid_argument);
}

}  // namespace
}  // namespace devsurf::models::quad_mesh
