#pragma once

#include <cstddef>

#include <Eigen/Core>
#include <nanoflann.hpp>

namespace devsurf::spatial {

/// nanoflann's dataset interface over the rows of an n×3 matrix (held by reference: the matrix
/// must outlive the tree).
struct MatrixRows {
  const Eigen::MatrixX3d& points;
  std::size_t kdtree_get_point_count() const { return static_cast<std::size_t>(points.rows()); }
  double kdtree_get_pt(std::size_t i, std::size_t dim) const {
    return points(static_cast<Eigen::Index>(i), static_cast<Eigen::Index>(dim));
  }
  template <class BoundingBox>
  bool kdtree_get_bbox(BoundingBox& /*bb*/) const {
    return false;
  }
};

/// A k-d tree over the rows of an n×3 matrix, squared Euclidean distances (Debian's
/// libnanoflann-dev). Build: `MatrixRowsKdTree tree(3, MatrixRows{points}, nanoflann::KDTreeSingleIndexAdaptorParams(16))`.
using MatrixRowsKdTree =
    nanoflann::KDTreeSingleIndexAdaptor<nanoflann::L2_Simple_Adaptor<double, MatrixRows>, MatrixRows, 3, std::size_t>;

}  // namespace devsurf::spatial
