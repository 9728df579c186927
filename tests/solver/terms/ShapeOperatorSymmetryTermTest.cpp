// ShapeOperatorSymmetryTerm (004_… §2.2.1 eq. 5: orthogonal principal directions).

#include <gtest/gtest.h>

#include "support/TermTesting.h"

#include <array>
#include <stdexcept>
#include <vector>

#include <Eigen/Geometry>

#include "devsurf/terms/ShapeOperatorSymmetryTerm.h"

namespace devsurf::terms {
namespace {

using devsurf::testing::expectJacobianMatches;
using devsurf::testing::expectNoDuplicateEntries;
using devsurf::testing::randomVector;
using devsurf::testing::residuals;

std::vector<int> shapeOperatorOffsets(int count, int first) {
  std::vector<int> offsets(count);
  for (int i = 0; i < count; ++i) offsets[i] = first + 3 * i;
  return offsets;
}

TEST(ShapeOperatorSymmetryTerm, JacobianMatchesFiniteDifferencesAndTrianglesHaveNoRow) {
  const std::vector<std::array<int, 4>> faces = {{0, 1, 2, 3}, {3, 2, 4, -1}, {1, 4, 2, 0}};
  ShapeOperatorSymmetryTerm term("symmetry", faces, shapeOperatorOffsets(5, 0), shapeOperatorOffsets(5, 15));
  EXPECT_EQ(term.numResiduals(), 2);
  expectNoDuplicateEntries(term);
  for (unsigned seed : {21u, 22u, 23u}) expectJacobianMatches(term, randomVector(30, seed));
}

TEST(ShapeOperatorSymmetryTerm, VanishesForASymmetricNormalMapAndMeasuresTheSkewPart) {
  // Unit square, then normals n0 = n1 = 0, n2 = (1, 0, 0), n3 = (0, 2, 0):
  // ⟨n3 − n1, v2 − v0⟩ − ⟨v3 − v1, n2 − n0⟩ = ⟨(0,2,0), (1,1,0)⟩ − ⟨(−1,1,0), (1,0,0)⟩ = 2 + 1.
  Eigen::VectorXd x(24);
  x << 0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0,  //
      0, 0, 0, 0, 0, 0, 1, 0, 0, 0, 2, 0;
  ShapeOperatorSymmetryTerm term("symmetry", {{0, 1, 2, 3}}, shapeOperatorOffsets(4, 0),
                                 shapeOperatorOffsets(4, 12));
  EXPECT_DOUBLE_EQ(residuals(term, x)[0], 3.0);

  // n_i = A v_i + b: the row is ⟨A d1, d0⟩ − ⟨d1, A d0⟩ = d1ᵀ (Aᵀ − A) d0, zero for symmetric A.
  const Eigen::VectorXd random = randomVector(24, 24);
  Eigen::Matrix3d A;
  A << 0.3, -0.2, 0.5, -0.2, 1.1, 0.4, 0.5, 0.4, -0.7;
  const Eigen::Vector3d b(0.1, 0.2, 0.3);
  Eigen::VectorXd y = random;
  for (int i = 0; i < 4; ++i) y.segment<3>(12 + 3 * i) = A * y.segment<3>(3 * i) + b;
  EXPECT_LT(std::abs(residuals(term, y)[0]), 1e-14);
  // Skew part: A = [ω]× gives d1ᵀ(−2[ω]×)d0 = −2⟨d1, ω × d0⟩.
  const Eigen::Vector3d omega(0.4, -0.3, 0.8);
  for (int i = 0; i < 4; ++i) y.segment<3>(12 + 3 * i) = omega.cross(y.segment<3>(3 * i));
  const Eigen::Vector3d d0 = y.segment<3>(6) - y.segment<3>(0);
  const Eigen::Vector3d d1 = y.segment<3>(9) - y.segment<3>(3);
  EXPECT_NEAR(residuals(term, y)[0], -2.0 * d1.dot(omega.cross(d0)), 1e-14);
}

TEST(ShapeOperatorSymmetryTerm, RefusesBadIndicesAndOverlappingVariables) {
  EXPECT_THROW(
      ShapeOperatorSymmetryTerm("s", {{0, 1, 2, 7}}, shapeOperatorOffsets(4, 0), shapeOperatorOffsets(4, 12)),
      std::invalid_argument);
  EXPECT_THROW(
      ShapeOperatorSymmetryTerm("s", {{0, 2, 2, 3}}, shapeOperatorOffsets(4, 0), shapeOperatorOffsets(4, 12)),
      std::invalid_argument);
  EXPECT_THROW(
      ShapeOperatorSymmetryTerm("s", {{0, 1, 2, 3}}, shapeOperatorOffsets(4, 0), shapeOperatorOffsets(4, 3)),
      std::invalid_argument);
}

}  // namespace
}  // namespace devsurf::terms
