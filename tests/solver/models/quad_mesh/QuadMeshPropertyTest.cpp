// Random but plausible quad-mesh problems (seeded): bent and perturbed grids with a few triangles,
// handles and glue pairs, either or both meshes moving. Whatever the input, a solve leaves finite
// geometry, never folds a moving planar unfolding over, and does not make the isometry worse.

#include <cmath>
#include <random>

#include <gtest/gtest.h>

#include "devsurf/models/quad_mesh/QuadMeshModel.h"

namespace devsurf::models::quad_mesh {
namespace {

QuadMeshDesign randomDesign(std::mt19937& rng) {
  std::uniform_int_distribution<int> cells(2, 9);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  const int nu = cells(rng), nv = cells(rng);
  const double width = 1.0 + 3.0 * std::abs(unit(rng)), height = 1.0 + 2.0 * std::abs(unit(rng));
  const double bend = 0.8 * unit(rng), twist = 0.3 * unit(rng), noise = 0.01 * std::abs(unit(rng));
  QuadMeshDesign d;
  const int V = (nu + 1) * (nv + 1);
  d.mesh.resize(V, 3);
  d.unfolding = Eigen::MatrixX3d::Zero(V, 3);
  for (int j = 0; j <= nv; ++j)
    for (int i = 0; i <= nu; ++i) {
      const double x = width * i / nu, y = height * j / nv;
      const int v = j * (nu + 1) + i;
      d.unfolding.row(v) << x, y, 0.0;
      // Roll the sheet about the y axis (an isometry) and disturb it.
      const double angle = bend * x / width * M_PI, r = bend == 0.0 ? 0.0 : width / (bend * M_PI);
      const Eigen::Vector3d rolled = std::abs(bend) < 1e-6 ? Eigen::Vector3d(x, y, 0.0)
                                                           : Eigen::Vector3d(r * std::sin(angle), y, r * (1.0 - std::cos(angle)));
      d.mesh.row(v) = (rolled + Eigen::Vector3d(noise * unit(rng), noise * unit(rng), twist * x * y / (width * height))).transpose();
    }
  for (int j = 0; j < nv; ++j)
    for (int i = 0; i < nu; ++i) {
      const int a = j * (nu + 1) + i;
      if ((i + 2 * j) % 7 == 3) {  // some quads as two triangles
        d.faces.push_back({a, a + 1, a + nu + 2, -1});
        d.faces.push_back({a, a + nu + 2, a + nu + 1, -1});
      } else {
        d.faces.push_back({a, a + 1, a + nu + 2, a + nu + 1});
      }
    }
  const int variable = static_cast<int>(rng() % 3);
  d.variable = variable == 0 ? VariableMeshes::Mesh : variable == 1 ? VariableMeshes::Both : VariableMeshes::Unfolding;
  if (d.variable != VariableMeshes::Unfolding && rng() % 2 == 0) {
    const int corner = static_cast<int>(rng() % 2) * nu;
    const Eigen::Vector3d p = d.mesh.row(corner);
    d.handles.push_back({{MeshSide::Mesh, corner}, p + 0.3 * Eigen::Vector3d(unit(rng), unit(rng), unit(rng)), 1.0});
  }
  if (rng() % 3 == 0) d.glue.push_back({MeshSide::Mesh, 0, nu});  // the bottom edge's ends
  if (rng() % 2 == 0) d.fixed.push_back({MeshSide::Mesh, V - 1});
  return d;
}

TEST(QuadMeshProperty, ARandomProblemSolvesToFiniteUnfoldedGeometryWithoutWorseningTheIsometry) {
  std::mt19937 rng(2026);
  int improved = 0;
  for (int trial = 0; trial < 200; ++trial) {
    const QuadMeshDesign d = randomDesign(rng);
    QuadMeshModel model(d);
    const double before = model.quality().lengthError;
    engine::SolverOptions o;
    o.maxIterations = 30;
    const QuadMeshSolveSummary s = model.solve(o);
    const QuadMeshQuality q = model.quality();
    ASSERT_TRUE(model.meshVertices().allFinite()) << "trial " << trial;
    ASSERT_TRUE(model.unfoldingVertices().allFinite()) << "trial " << trial;
    EXPECT_NE(s.summary.reason, engine::TerminationReason::Diverged) << "trial " << trial;
    if (d.variable != VariableMeshes::Mesh) EXPECT_EQ(q.unfoldingFlippedFaces, 0) << "trial " << trial;
    if (d.glue.empty() && d.handles.empty()) EXPECT_LE(q.lengthError, before + 1e-3) << "trial " << trial;
    if (q.lengthError < before) ++improved;
  }
  EXPECT_GE(improved, 150) << "most random problems get closer to an isometry";
}

}  // namespace
}  // namespace devsurf::models::quad_mesh
