// LinearPointMapTerm (the refined mesh S^k(M) of 004_… Algorithm 2 tied to its control mesh M).

#include <gtest/gtest.h>

#include "support/TermTesting.h"

#include <stdexcept>

#include "devsurf/spline/CubicSubdivision.h"
#include "devsurf/terms/LinearPointMapTerm.h"

namespace devsurf::terms {
namespace {

using devsurf::testing::expectJacobianMatches;
using devsurf::testing::expectNoDuplicateEntries;
using devsurf::testing::randomVector;
using devsurf::testing::residuals;
using RowMap = Eigen::SparseMatrix<double, Eigen::RowMajor>;

TEST(LinearPointMapTerm, JacobianMatchesFiniteDifferences) {
  // One round of eq. 8 on a polygon of 5 points: 7 mapped points after the 5 sources.
  const RowMap map = spline::cubicSubdivisionMatrix(5);
  std::vector<int> sources, mapped;
  for (int j = 0; j < 5; ++j) sources.push_back(3 * j);
  for (int i = 0; i < 7; ++i) mapped.push_back(15 + 3 * i);
  LinearPointMapTerm term("subdivision", map, mapped, sources);
  EXPECT_EQ(term.numResiduals(), 21);
  expectNoDuplicateEntries(term);
  expectJacobianMatches(term, randomVector(36, 2020));
}

TEST(LinearPointMapTerm, VanishesExactlyOnTheSubdividedPolygon) {
  const RowMap map = spline::cubicSubdivisionMatrix(6);
  Eigen::MatrixXd control(6, 3);
  control << 0, 0, 0, 1, 2, 0, 2, 2, 1, 3, 0, 1, 4, -1, 0, 5, 1, 2;
  const Eigen::MatrixXd refined = Eigen::SparseMatrix<double>(map) * control;
  Eigen::VectorXd x(3 * (6 + 9));
  std::vector<int> sources, mapped;
  for (int j = 0; j < 6; ++j) {
    sources.push_back(3 * j);
    x.segment<3>(3 * j) = control.row(j).transpose();
  }
  for (int i = 0; i < 9; ++i) {
    mapped.push_back(18 + 3 * i);
    x.segment<3>(18 + 3 * i) = refined.row(i).transpose();
  }
  LinearPointMapTerm term("subdivision", map, mapped, sources);
  EXPECT_LT(residuals(term, x).cwiseAbs().maxCoeff(), 1e-15);
  x[18 + 3 * 4 + 1] += 0.25;  // mapped point 4, y
  const Eigen::VectorXd r = residuals(term, x);
  EXPECT_NEAR(r[3 * 4 + 1], 0.25, 1e-15);
  EXPECT_NEAR(r.norm(), 0.25, 1e-15);
}

TEST(LinearPointMapTerm, RejectsInvalidInput) {
  const RowMap map = spline::cubicSubdivisionMatrix(4);  // 5 × 4
  const std::vector<int> sources{0, 3, 6, 9}, mapped{12, 15, 18, 21, 24};
  EXPECT_THROW(LinearPointMapTerm("m", map, {12, 15, 18, 21}, sources), std::invalid_argument);
  EXPECT_THROW(LinearPointMapTerm("m", map, mapped, {0, 3, 6}), std::invalid_argument);
  EXPECT_THROW(LinearPointMapTerm("m", map, {12, 15, 18, 21, 10}, sources), std::invalid_argument);  // overlap
  EXPECT_THROW(LinearPointMapTerm("m", map, mapped, {-3, 3, 6, 9}), std::invalid_argument);
  RowMap bad = map;
  bad.coeffRef(0, 0) = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(LinearPointMapTerm("m", bad, mapped, sources), std::invalid_argument);
}

}  // namespace
}  // namespace devsurf::terms
