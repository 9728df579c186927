#include "devsurf/engine/VariableLayout.h"

#include <gtest/gtest.h>

#include "devsurf/engine/Normalization.h"

namespace devsurf::engine {
namespace {

TEST(VariableLayout, BlocksAreContiguousAndNamed) {
  VariableLayout layout;
  EXPECT_EQ(layout.addBlock("curve a", 6), 0);
  EXPECT_EQ(layout.addBlock("normals", 9), 1);
  EXPECT_EQ(layout.block(1).offset, 6);
  EXPECT_EQ(layout.blockId("normals"), 1);
  EXPECT_EQ(layout.numVariables(), 15);
  EXPECT_THROW(layout.addBlock("normals", 3), std::invalid_argument);
  EXPECT_THROW(layout.blockId("nothing"), std::out_of_range);
}

TEST(VariableLayout, EliminationGroupSizeIsValidated) {
  VariableLayout layout;
  const int normals = layout.addBlock("normals", 9);
  EXPECT_EQ(layout.block(normals).eliminationGroupSize, VariableBlock::kAutoElimination);
  layout.setEliminable(normals, 3);
  EXPECT_EQ(layout.block(normals).eliminationGroupSize, 3);
  layout.setEliminable(normals, 0);
  EXPECT_EQ(layout.block(normals).eliminationGroupSize, 0);
  EXPECT_THROW(layout.setEliminable(normals, 2), std::invalid_argument);   // 9 % 2 ≠ 0
  EXPECT_THROW(layout.setEliminable(normals, -2), std::invalid_argument);
  EXPECT_THROW(layout.setEliminable(3, 1), std::out_of_range);
}

TEST(VariableLayout, FixedScalarsGetNoColumn) {
  VariableLayout layout;
  const int a = layout.addBlock("a", 6);
  layout.addBlock("b", 3);
  layout.setFixed(a, 3, 3);
  const std::vector<int> index = layout.freeIndex();
  EXPECT_EQ(layout.numFree(), 6);
  EXPECT_EQ(index[2], 2);
  EXPECT_EQ(index[3], -1);
  EXPECT_EQ(index[5], -1);
  EXPECT_EQ(index[6], 3);
  layout.setFixed(a, 3, 3, false);
  EXPECT_EQ(layout.numFree(), 9);
  EXPECT_THROW(layout.setFixed(a, 4, 3), std::out_of_range);
}

TEST(Normalization, MapsTheBoundingBoxToUnitDiagonalAndBack) {
  Eigen::MatrixX3d p(3, 3);
  p << 0, 0, 0, 4, 0, 0, 4, 3, 0;
  const Normalization n = Normalization::fromPoints(p);
  EXPECT_DOUBLE_EQ(n.scale, 5.0);
  Eigen::MatrixX3d q = p;
  n.normalizeRows(q);
  EXPECT_NEAR((q.colwise().maxCoeff() - q.colwise().minCoeff()).norm(), 1.0, 1e-15);
  EXPECT_LT((n.centre - Eigen::Vector3d(2.0, 1.5, 0.0)).norm(), 1e-15);
  EXPECT_LT((q.row(2) - Eigen::RowVector3d(0.4, 0.3, 0.0)).norm(), 1e-15);
  n.denormalizeRows(q);
  EXPECT_LT((q - p).norm(), 1e-15);
}

}  // namespace
}  // namespace devsurf::engine
