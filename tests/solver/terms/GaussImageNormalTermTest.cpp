// GaussImageNormalTerm (004_… §2.2.1 eq. 3: vertex normals whose 'black' parallelograms touch the
// unit sphere in the face normal).

#include <gtest/gtest.h>

#include "support/TermTesting.h"

#include <array>
#include <cmath>
#include <stdexcept>
#include <vector>

#include "devsurf/terms/GaussImageNormalTerm.h"

namespace devsurf::terms {
namespace {

using devsurf::testing::expectJacobianMatches;
using devsurf::testing::expectNoDuplicateEntries;
using devsurf::testing::randomVector;
using devsurf::testing::residuals;

/// Offsets of V points stored one after the other from `first`.
std::vector<int> packedOffsets(int count, int first) {
  std::vector<int> offsets(count);
  for (int i = 0; i < count; ++i) offsets[i] = first + 3 * i;
  return offsets;
}

/// Unit square v0 = (0,0,0), v1 = (1,0,0), v2 = (1,1,0), v3 = (0,1,0), then normals n0 … n3.
Eigen::VectorXd squareWithNormals() {
  Eigen::VectorXd x(24);
  x << 0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0,  //
      0, 0, 1, 0.5, 0, 2, 0, 0, 3, 1, 1, -1;
  return x;
}

TEST(GaussImageNormalTerm, JacobianMatchesFiniteDifferencesForQuadsAndATriangle) {
  // Five vertices: two quads sharing an edge and a triangle; normals stored after the vertices.
  const std::vector<std::array<int, 4>> faces = {{0, 1, 2, 3}, {1, 4, 2, 0}, {3, 2, 4, -1}};
  GaussImageNormalTerm term("normals", faces, packedOffsets(5, 0), packedOffsets(5, 15));
  EXPECT_EQ(term.numResiduals(), 4 + 4 + 3);
  expectNoDuplicateEntries(term);
  for (unsigned seed : {11u, 12u, 13u}) expectJacobianMatches(term, randomVector(30, seed));

  // Interleaved storage (vertex then its normal) works alike.
  std::vector<int> mesh(5), normals(5);
  for (int i = 0; i < 5; ++i) {
    mesh[i] = 6 * i;
    normals[i] = 6 * i + 3;
  }
  GaussImageNormalTerm interleaved("normals", faces, mesh, normals);
  expectNoDuplicateEntries(interleaved);
  expectJacobianMatches(interleaved, randomVector(30, 14));
}

TEST(GaussImageNormalTerm, GivesTheDistanceOfEdgeMidpointsFromTheTangentPlaneTwice) {
  const Eigen::VectorXd x = squareWithNormals();
  // n_f = (0, 0, 1): rows ⟨n_j + n_{j+1}, e_z⟩ − 2 = (1 + 2, 2 + 3, 3 − 1, −1 + 1) − 2.
  GaussImageNormalTerm quad("normals", {{0, 1, 2, 3}}, packedOffsets(4, 0), packedOffsets(4, 12));
  const Eigen::Vector4d expected(1, 3, 0, -2);
  EXPECT_LT((residuals(quad, x) - expected).cwiseAbs().maxCoeff(), 1e-15);

  // Clockwise order: n_f = (0, 0, −1), rows over the edges 0–3, 3–2, 2–1, 1–0.
  GaussImageNormalTerm flipped("normals", {{0, 3, 2, 1}}, packedOffsets(4, 0),
                               packedOffsets(4, 12));
  const Eigen::Vector4d expectedFlipped(-2, -4, -7, -5);
  EXPECT_LT((residuals(flipped, x) - expectedFlipped).cwiseAbs().maxCoeff(), 1e-15);

  // Triangle v0 v1 v2: n_f = (1,0,0) × (1,1,0) = e_z; rows (1+2, 2+3, 3+1) − 2.
  GaussImageNormalTerm triangle("normals", {{0, 1, 2, -1}}, packedOffsets(4, 0),
                                packedOffsets(4, 12));
  EXPECT_LT((residuals(triangle, x) - Eigen::Vector3d(1, 3, 2)).cwiseAbs().maxCoeff(), 1e-15);

  // Unit normals equal to n_f satisfy eq. 3 exactly (a plane's Gauss image is one point).
  Eigen::VectorXd plane = x;
  for (int i = 0; i < 4; ++i) plane.segment<3>(12 + 3 * i) = Eigen::Vector3d(0, 0, 1);
  EXPECT_LT(residuals(quad, plane).cwiseAbs().maxCoeff(), 1e-15);
}

TEST(GaussImageNormalTerm, DegenerateFaceGivesFiniteRowsAndDerivatives) {
  Eigen::VectorXd x = squareWithNormals();
  x.segment<3>(3) = x.segment<3>(0);  // v1 = v0
  x.segment<3>(9) = x.segment<3>(6);  // v3 = v2: both diagonals along (1, 1, 0)
  GaussImageNormalTerm quad("normals", {{0, 1, 2, 3}}, packedOffsets(4, 0), packedOffsets(4, 12));
  const Eigen::VectorXd r = residuals(quad, x);
  EXPECT_TRUE(r.allFinite());
  EXPECT_EQ(r, Eigen::Vector4d::Constant(-2.0));
  std::vector<engine::JacobianEntry> entries;
  quad.jacobianStructure(entries);
  std::vector<double> jacobian(entries.size());
  Eigen::VectorXd rows(quad.numResiduals());
  quad.evaluate(x, rows.data(), jacobian.data());
  for (double value : jacobian) EXPECT_TRUE(std::isfinite(value));
}

TEST(GaussImageNormalTerm, RefusesBadIndicesAndOverlappingVariables) {
  EXPECT_THROW(GaussImageNormalTerm("n", {{0, 1, 2, 4}}, packedOffsets(4, 0), packedOffsets(4, 12)),
               std::invalid_argument);
  EXPECT_THROW(GaussImageNormalTerm("n", {{0, 1, 1, 3}}, packedOffsets(4, 0), packedOffsets(4, 12)),
               std::invalid_argument);
  EXPECT_THROW(GaussImageNormalTerm("n", {{0, 1, 2, 3}}, packedOffsets(4, 0), packedOffsets(3, 12)),
               std::invalid_argument);
  // Normals of vertices 2, 3 stored where vertices 0, 1 are.
  EXPECT_THROW(GaussImageNormalTerm("n", {{0, 1, 2, 3}}, packedOffsets(4, 0), packedOffsets(4, 6)),
               std::invalid_argument);
}

}  // namespace
}  // namespace devsurf::terms
