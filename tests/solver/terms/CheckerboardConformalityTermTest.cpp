// CheckerboardConformalityTerm (004_… eq. 2) and ConformalFactorTerm (E_λ).

#include <gtest/gtest.h>

#include "support/TermTesting.h"

#include <stdexcept>

#include <Eigen/Geometry>

#include "devsurf/terms/CheckerboardConformalityTerm.h"
#include "devsurf/terms/ConformalFactorTerm.h"

namespace devsurf::terms {
namespace {

using devsurf::testing::expectJacobianMatches;
using devsurf::testing::expectNoDuplicateEntries;
using devsurf::testing::randomVector;
using devsurf::testing::residuals;

const std::vector<std::array<int, 4>> kFaces = {{0, 1, 2, 3}, {1, 4, 2, -1}, {2, 4, 5, 3}};

TEST(CheckerboardConformalityTerm, JacobianMatchesFiniteDifferencesIncludingTheFactors) {
  // Factors first, then M and M′ interleaved.
  std::vector<int> mesh, unfolding;
  for (int i = 0; i < 6; ++i) {
    mesh.push_back(3 + 6 * i);
    unfolding.push_back(3 + 6 * i + 3);
  }
  CheckerboardConformalityTerm term("conformality", kFaces, mesh, unfolding, 0);
  EXPECT_EQ(term.numResiduals(), 9);
  expectNoDuplicateEntries(term);
  expectJacobianMatches(term, randomVector(39, 1311));
}

TEST(CheckerboardConformalityTerm, VanishesForAScaledRotatedCopyWithTheSquaredScaleAsFactor) {
  Eigen::VectorXd x = randomVector(39, 1312);
  const Eigen::Matrix3d R = Eigen::AngleAxisd(-1.1, Eigen::Vector3d::UnitY()).toRotationMatrix();
  for (int i = 0; i < 6; ++i) x.segment<3>(18 + 3 * i) = 2.0 * R * x.segment<3>(3 * i);
  x.tail<3>().setConstant(4.0);
  std::vector<int> mesh, unfolding;
  for (int i = 0; i < 6; ++i) {
    mesh.push_back(3 * i);
    unfolding.push_back(18 + 3 * i);
  }
  CheckerboardConformalityTerm term("conformality", kFaces, mesh, unfolding, 36);
  EXPECT_LT(residuals(term, x).cwiseAbs().maxCoeff(), 1e-13);
  x[37] = 3.0;  // the triangle's factor
  const Eigen::VectorXd r = residuals(term, x);
  EXPECT_LT(r.head<3>().cwiseAbs().maxCoeff(), 1e-13);
  EXPECT_GT(r.segment<3>(3).cwiseAbs().minCoeff(), 1e-3);
}

TEST(CheckerboardConformalityTerm, ScalesTheSquaresDiagonalsByTheFactor) {
  // M: unit square (‖d0‖² = ‖d1‖² = 2, ⟨d0, d1⟩ = 0); M′: 2 × 1 rectangle (5, 5, −3); λ = 2.
  // Triangle [0, 1, 2] with λ = 3: edges 3·(1, 1, 2) against (4, 1, 5).
  Eigen::VectorXd x(26);
  x << 0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0,  //
      0, 0, 0, 2, 0, 0, 2, 1, 0, 0, 1, 0,   //
      2, 3;
  CheckerboardConformalityTerm term("conformality", {{0, 1, 2, 3}, {0, 1, 2, -1}},
                                    {0, 3, 6, 9}, {12, 15, 18, 21}, 24);
  Eigen::VectorXd expected(6);
  expected << -1, -1, 3, -1, 2, 1;
  EXPECT_EQ(residuals(term, x), expected);
}

TEST(CheckerboardConformalityTerm, RejectsFactorsOverlappingVertices) {
  using F = std::vector<std::array<int, 4>>;
  const std::vector<int> mesh = {0, 3, 6, 9}, unfolding = {12, 15, 18, 21};
  EXPECT_NO_THROW(CheckerboardConformalityTerm("c", F{{0, 1, 2, 3}, {0, 1, 2, -1}}, mesh,
                                               unfolding, 24));
  EXPECT_THROW(CheckerboardConformalityTerm("c", F{{0, 1, 2, 3}, {0, 1, 2, -1}}, mesh,
                                            unfolding, 23),
               std::invalid_argument);
  EXPECT_THROW(CheckerboardConformalityTerm("c", F{{0, 1, 2, 3}}, mesh, unfolding, -1),
               std::invalid_argument);
  EXPECT_THROW(CheckerboardConformalityTerm("c", F{{0, 1, 2, 3}}, mesh, {12, 15, 18}, 24),
               std::invalid_argument);
  EXPECT_THROW(CheckerboardConformalityTerm("c", F{{0, 1, 3, 3}}, mesh, unfolding, 24),
               std::invalid_argument);
}

TEST(ConformalFactorTerm, MeasuresTheFactorsDeviationFromOne) {
  ConformalFactorTerm term("factor", 2, 3);
  EXPECT_EQ(term.numResiduals(), 3);
  Eigen::VectorXd x(6);
  x << 9, 9, 1.0, 0.5, 4.0, 9;
  Eigen::VectorXd expected(3);
  expected << 0.0, -0.5, 3.0;
  EXPECT_EQ(residuals(term, x), expected);
  expectNoDuplicateEntries(term);
  expectJacobianMatches(term, randomVector(6, 1313));
  EXPECT_EQ(ConformalFactorTerm("factor", 0, 0).numResiduals(), 0);
  EXPECT_THROW(ConformalFactorTerm("f", -1, 3), std::invalid_argument);
  EXPECT_THROW(ConformalFactorTerm("f", 0, -1), std::invalid_argument);
}

}  // namespace
}  // namespace devsurf::terms
