// Approximating a segmented reference by glued developable patches (issue 15, 004_… §5,
// Fig. 20–21): the start segmentedApproximation builds, and what Algorithm 1 makes of it. Lengths
// and distances are recomputed here from the meshes, not taken from the model's own quality().
#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <map>
#include <random>
#include <set>

#include <Eigen/Geometry>

#include "devsurf/models/quad_mesh/QuadMeshModel.h"
#include "devsurf/models/quad_mesh/SegmentedApproximation.h"
#include "devsurf/reference/SurfaceSegmentation.h"
#include "support/TriangulatedGrid.h"

namespace devsurf::models::quad_mesh {
namespace {

/// Edges of every face once (triangles and quads), as the L-Err of Fig. 22 counts them.
std::set<std::pair<int, int>> faceEdges(const std::vector<Face>& faces) {
  std::set<std::pair<int, int>> edges;
  for (const Face& f : faces)
    for (int k = 0, n = faceSize(f); k < n; ++k) edges.insert(std::minmax(f[k], f[(k + 1) % n]));
  return edges;
}

/// ‖L′ − L‖ / ‖L‖ over the edges (Fig. 22), from the two vertex sets.
double lengthError(const std::vector<Face>& faces, const Eigen::MatrixX3d& M, const Eigen::MatrixX3d& U) {
  double num = 0.0, den = 0.0;
  for (const auto& [a, b] : faceEdges(faces)) {
    const double l = (M.row(a) - M.row(b)).norm(), l2 = (U.row(a) - U.row(b)).norm();
    num += (l2 - l) * (l2 - l);
    den += l * l;
  }
  return std::sqrt(num / den);
}

engine::SolverOptions sceneDefaults(int iterations) {
  engine::SolverOptions o;  // as `devsurf solve` runs a scene with only "iterations" set
  o.maxIterations = iterations;
  o.regularization = 0.01;
  return o;
}

/// What every start must be: a valid quad-dominant mesh on the reference, glue pairs between
/// pieces at one point, no vertex in a single quad, every piece's unfolding unflipped.
void expectAValidStart(const SegmentedApproximation& s, const std::function<double(const Eigen::Vector3d&)>& offReference,
                       double tolerance, const std::string& what) {
  const QuadMeshDesign& d = s.design;
  ASSERT_NO_THROW(QuadMeshTopology(static_cast<int>(d.mesh.rows()), d.faces)) << what;
  ASSERT_EQ(s.facePiece.size(), d.faces.size()) << what;
  ASSERT_EQ(s.facePatch.size(), d.faces.size()) << what;
  std::vector<int> pieceOfVertex(d.mesh.rows(), -1), facesAt(d.mesh.rows(), 0);
  for (std::size_t f = 0; f < d.faces.size(); ++f)
    for (int k = 0; k < faceSize(d.faces[f]); ++k) {
      const int v = d.faces[f][k];
      if (pieceOfVertex[v] >= 0) {
        ASSERT_EQ(pieceOfVertex[v], s.facePiece[f]) << what << ": a vertex in two pieces";
      }
      pieceOfVertex[v] = s.facePiece[f];
      ++facesAt[v];
    }
  for (Eigen::Index v = 0; v < d.mesh.rows(); ++v) {
    ASSERT_GE(pieceOfVertex[v], 0) << what << ": vertex " << v << " in no face";
    ASSERT_LT(offReference(d.mesh.row(v).transpose()), tolerance) << what << ": vertex " << v << " off the reference";
  }
  // eq. 1 holds a quad's diagonals only: no quad may have a corner in no other face.
  for (const Face& f : d.faces) {
    if (faceSize(f) != 4) continue;
    for (int k = 0; k < 4; ++k) {
      ASSERT_GT(facesAt[f[k]], 1) << what << ": a quad's corner in no other face";
    }
  }
  for (const GluePair& g : d.glue) {
    ASSERT_EQ(g.on, MeshSide::Mesh);
    EXPECT_EQ((d.mesh.row(g.a) - d.mesh.row(g.b)).norm(), 0.0) << what << ": glued vertices apart at the start";
  }
  // Unflipped unfoldings: every face counter-clockwise in M′ (its triangles' signed areas > 0).
  for (const Face& f : d.faces)
    for (int k = 1; k + 1 < faceSize(f); ++k) {
      const Eigen::Vector2d a = d.unfolding.row(f[0]).head<2>(), b = d.unfolding.row(f[k]).head<2>(),
                            c = d.unfolding.row(f[k + 1]).head<2>();
      ASSERT_GT((b - a).x() * (c - a).y() - (b - a).y() * (c - a).x(), 0.0) << what;
    }
  EXPECT_EQ(d.variable, VariableMeshes::Both);
  ASSERT_TRUE(d.reference.has_value());
}

TEST(SegmentedApproximation, ACylinderInTwoPatchesStartsOnItNearlyIsometricAndSolvesBelowFigure22) {
  Eigen::MatrixX3d V;
  Eigen::MatrixX3i T;
  devsurf::testing::triangulatedGrid(48, 18, 2.0 * M_PI / 3.0, 1.5, [](double s, double z) { return Eigen::Vector3d(std::cos(s), std::sin(s), z); }, V, T);
  std::vector<int> patch(T.rows());
  for (Eigen::Index t = 0; t < T.rows(); ++t) patch[t] = V(T(t, 0), 1) + V(T(t, 1), 1) + V(T(t, 2), 1) < 3.0 * std::sin(M_PI / 3.0) ? 0 : 1;
  SegmentedApproximationOptions options;
  options.targetFaces = 600;
  const SegmentedApproximation s = segmentedApproximation(V, T, patch, options);
  auto offCylinder = [](const Eigen::Vector3d& p) { return std::abs(p.head<2>().norm() - 1.0); };
  // Points interpolated on the reference's chords: within the chord height (Δθ)²/8 ≈ 2.4e-4.
  expectAValidStart(s, offCylinder, 3e-4, "cylinder");
  EXPECT_EQ(s.pieces, 2);
  EXPECT_GT(s.design.glue.size(), 10u);
  std::set<int> patches(s.facePatch.begin(), s.facePatch.end());
  EXPECT_EQ(patches, (std::set<int>{0, 1}));
  EXPECT_LT(lengthError(s.design.faces, s.design.mesh, s.design.unfolding), 2e-3) << "each piece unrolled near-isometrically";

  QuadMeshModel model(s.design);
  model.solve(sceneDefaults(40));
  const Eigen::MatrixX3d M = model.meshVertices(), U = model.unfoldingVertices();
  const double L = lengthError(s.design.faces, M, U);
  EXPECT_LE(L, 4.1e-4) << "Fig. 22 row 20b: L-Err 0.041 %";
  const double diagonal = (V.colwise().maxCoeff() - V.colwise().minCoeff()).norm();
  double gap = 0.0, off = 0.0;
  for (const GluePair& g : s.design.glue) gap = std::max(gap, (M.row(g.a) - M.row(g.b)).norm());
  for (Eigen::Index v = 0; v < M.rows(); ++v) off = std::max(off, offCylinder(M.row(v).transpose()));
  EXPECT_LE(gap, 1e-6 * diagonal);
  EXPECT_LE(off, 2e-3 * diagonal) << "a developable reference is kept";
  EXPECT_LT(U.col(2).cwiseAbs().maxCoeff(), 1e-12) << "M′ planar";
}

TEST(SegmentedApproximation, ASaddleInNinePatchesBecomesPiecewiseDevelopableCloseToIt) {
  // z = 0.35(x² − y²) over [−1, 1]²: K < 0 everywhere, so no single developable is close.
  Eigen::MatrixX3d V;
  Eigen::MatrixX3i T;
  auto saddle = [](double x, double y) { return 0.35 * (x * x - y * y); };
  devsurf::testing::triangulatedGrid(30, 30, 2.0, 2.0, [&saddle](double u, double v) { return Eigen::Vector3d(u - 1, v - 1, saddle(u - 1, v - 1)); }, V, T);
  std::vector<int> quadrant(T.rows());
  for (Eigen::Index t = 0; t < T.rows(); ++t) {
    const Eigen::Vector3d c = (V.row(T(t, 0)) + V.row(T(t, 1)) + V.row(T(t, 2))).transpose() / 3.0;
    quadrant[t] = static_cast<int>(std::floor(1.5 * (c.x() + 1.0 - 1e-9))) + 3 * static_cast<int>(std::floor(1.5 * (c.y() + 1.0 - 1e-9)));
  }
  SegmentedApproximationOptions options;
  options.targetFaces = 800;
  const SegmentedApproximation s = segmentedApproximation(V, T, quadrant, options);
  auto offSaddle = [&saddle](const Eigen::Vector3d& p) { return std::abs(p.z() - saddle(p.x(), p.y())); };
  expectAValidStart(s, offSaddle, 2e-3, "saddle");
  EXPECT_EQ(s.pieces, 9);
  QuadMeshModel model(s.design);
  model.solve(sceneDefaults(40));
  const Eigen::MatrixX3d M = model.meshVertices(), U = model.unfoldingVertices();
  const double diagonal = (V.colwise().maxCoeff() - V.colwise().minCoeff()).norm();
  double squares = 0.0, gap = 0.0;
  for (Eigen::Index v = 0; v < M.rows(); ++v) squares += std::pow(offSaddle(M.row(v).transpose()), 2);
  for (const GluePair& g : s.design.glue) gap = std::max(gap, (M.row(g.a) - M.row(g.b)).norm());
  const double rms = std::sqrt(squares / static_cast<double>(M.rows()));
  const double L = lengthError(s.design.faces, M, U);
  std::printf("saddle, 9 patches, 40 iterations: L-Err %.4f %%, A-Err %.4f %%, vertical RMS %.3f %% of the diagonal\n",
              100 * L, 100 * model.quality().areaError, 100 * rms / diagonal);
  // Fig. 22 row 10 (a doubly curved shape approximated with proximity): L-Err 0.38 %, A-Err
  // 0.48 %. Measured 0.19 % / 0.15 %; more iterations stall near 0.16 % while the residual of
  // eq. 1 keeps falling (1e-5 → 1e-6): eq. 1 holds the quads' diagonals, and their edges drift.
  EXPECT_LE(L, 3.8e-3);
  EXPECT_LE(model.quality().areaError, 4.8e-3);
  EXPECT_LE(gap, 1e-6 * diagonal);
  EXPECT_LE(rms, 0.02 * diagonal);
}

TEST(SegmentedApproximation, EveryStartIsValidOverAHundredRandomShapesAndSegmentations) {
  std::mt19937 random(2015);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  for (int trial = 0; trial < 100; ++trial) {
    const double a = unit(random) - 0.5, b = unit(random) - 0.5, c = unit(random) - 0.5, e = 0.3 * (unit(random) - 0.5);
    const double w = 1.0 + 2.0 * unit(random), h = 1.0 + 2.0 * unit(random);
    auto height = [a, b, c, e](double x, double y) { return a * x * x + b * y * y + c * x * y + e * x * x * x; };
    const Eigen::Matrix3d turn = Eigen::AngleAxisd(6.0 * unit(random), Eigen::Vector3d(unit(random), unit(random), 1.0).normalized()).toRotationMatrix();
    Eigen::MatrixX3d V;
    Eigen::MatrixX3i T;
    devsurf::testing::triangulatedGrid(12 + trial % 8, 10 + trial % 7, w, h,
                  [&height, &turn](double x, double y) { return Eigen::Vector3d(turn * Eigen::Vector3d(x, y, height(x, y))); }, V, T);
    reference::NormalSegmentationOptions segmentation;
    segmentation.patches = 1 + trial % 7;
    segmentation.seed = static_cast<std::uint32_t>(trial);
    const std::vector<int> patch = reference::segmentByNormals(V, T, segmentation);
    SegmentedApproximationOptions options;
    options.targetFaces = 100 + 25 * (trial % 9);
    options.minPieceFaces = 1 + trial % 12;
    const SegmentedApproximation s = segmentedApproximation(V, T, patch, options);
    const Eigen::Matrix3d back = turn.transpose();
    auto offSurface = [&back, &height](const Eigen::Vector3d& p) {
      const Eigen::Vector3d q = back * p;
      return std::abs(q.z() - height(q.x(), q.y()));
    };
    expectAValidStart(s, offSurface, 0.02 * std::max(w, h), "trial " + std::to_string(trial));
    std::map<int, int> piecePatch;
    for (std::size_t f = 0; f < s.facePiece.size(); ++f) {
      const auto [it, inserted] = piecePatch.emplace(s.facePiece[f], s.facePatch[f]);
      ASSERT_EQ(it->second, s.facePatch[f]) << "trial " << trial << ": a piece spans two patches";
    }
    ASSERT_NO_THROW(QuadMeshModel model(s.design)) << "trial " << trial;
  }
}

TEST(SegmentedApproximation, RefusesInputItCannotUseNamingWhy) {
  Eigen::MatrixX3d V;
  Eigen::MatrixX3i T;
  devsurf::testing::triangulatedGrid(6, 6, 1.0, 1.0, [](double x, double y) { return Eigen::Vector3d(x, y, 0); }, V, T);
  std::vector<int> ok(T.rows(), 0);
  auto message = [&V, &T](const std::vector<int>& patch, const SegmentedApproximationOptions& o) -> std::string {
    try {
      segmentedApproximation(V, T, patch, o);
    } catch (const std::invalid_argument& e) {
      return e.what();
    }
    return "";
  };
  EXPECT_NE(message(std::vector<int>(3, 0), {}).find("3 values for 72 triangles"), std::string::npos);
  std::vector<int> negative = ok;
  negative[5] = -1;
  EXPECT_NE(message(negative, {}).find("patch ids[5] is negative"), std::string::npos);
  SegmentedApproximationOptions coarse;
  coarse.spacing = 5.0;
  EXPECT_NE(message(ok, coarse).find("larger than the reference's map"), std::string::npos);
  SegmentedApproximationOptions fine;
  fine.spacing = 1e-4;
  EXPECT_NE(message(ok, fine).find("2 000 000"), std::string::npos);
  Eigen::MatrixX3i holed(T.rows() - 2, 3);
  for (Eigen::Index t = 0, k = 0; t < T.rows(); ++t)
    if (t != 28 && t != 29) holed.row(k++) = T.row(t);
  EXPECT_THROW(segmentedApproximation(V, holed, std::vector<int>(holed.rows(), 0)), std::invalid_argument);
}

}  // namespace
}  // namespace devsurf::models::quad_mesh
