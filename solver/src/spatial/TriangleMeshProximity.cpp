#include "devsurf/spatial/TriangleMeshProximity.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include <CGAL/AABB_traits.h>
#include <CGAL/AABB_tree.h>
#include <CGAL/AABB_triangle_primitive.h>
#include <CGAL/Simple_cartesian.h>

namespace devsurf::spatial {
namespace {

using Kernel = CGAL::Simple_cartesian<double>;
using Point = Kernel::Point_3;
using Triangle = Kernel::Triangle_3;
using TriangleIterator = std::vector<Triangle>::const_iterator;
using TrianglePrimitive = CGAL::AABB_triangle_primitive<Kernel, TriangleIterator>;
using TriangleTree = CGAL::AABB_tree<CGAL::AABB_traits<Kernel, TrianglePrimitive>>;

}  // namespace

struct TriangleMeshProximity::Impl {
  std::vector<Triangle> triangles;  // the tree's primitives point into this (never resized)
  std::vector<Eigen::Vector3d> normals;
  TriangleTree tree;
};

TriangleMeshProximity::TriangleMeshProximity(const Eigen::MatrixX3d& V, const Eigen::MatrixX3i& T)
    : impl_(std::make_unique<Impl>()) {
  const std::string who = "TriangleMeshProximity";
  if (T.rows() == 0) throw std::invalid_argument(who + ": no triangles");
  if (!V.allFinite()) throw std::invalid_argument(who + ": a vertex coordinate is not finite");
  const Eigen::Index vertexCount = V.rows();
  impl_->triangles.reserve(T.rows());
  impl_->normals.reserve(T.rows());
  for (Eigen::Index t = 0; t < T.rows(); ++t) {
    const std::string name = who + ": triangle " + std::to_string(t);
    for (int c = 0; c < 3; ++c)
      if (T(t, c) < 0 || T(t, c) >= vertexCount)
        throw std::invalid_argument(name + " has vertex index " + std::to_string(T(t, c)) +
                                    " out of range [0, " + std::to_string(vertexCount) + ")");
    if (T(t, 0) == T(t, 1) || T(t, 1) == T(t, 2) || T(t, 0) == T(t, 2))
      throw std::invalid_argument(name + " repeats a vertex");
    const Eigen::Vector3d a = V.row(T(t, 0)), b = V.row(T(t, 1)), c = V.row(T(t, 2));
    const Eigen::Vector3d cross = (b - a).cross(c - a);
    const double longest =
        std::max({(b - a).squaredNorm(), (c - b).squaredNorm(), (a - c).squaredNorm()});
    if (!(0.5 * cross.norm() > 1e-12 * longest))
      throw std::invalid_argument(name + " is degenerate (zero area)");
    impl_->normals.push_back(cross.normalized());
    impl_->triangles.emplace_back(Point(a.x(), a.y(), a.z()), Point(b.x(), b.y(), b.z()),
                                  Point(c.x(), c.y(), c.z()));
  }
  impl_->tree.insert(impl_->triangles.cbegin(), impl_->triangles.cend());
  impl_->tree.build();
  // Built now, not lazily on the first query, so concurrent const queries are safe.
  impl_->tree.accelerate_distance_queries();
}

TriangleMeshProximity::~TriangleMeshProximity() = default;
TriangleMeshProximity::TriangleMeshProximity(TriangleMeshProximity&&) noexcept = default;
TriangleMeshProximity& TriangleMeshProximity::operator=(TriangleMeshProximity&&) noexcept =
    default;

ClosestPoint TriangleMeshProximity::closest(const Eigen::Vector3d& q) const {
  const auto [point, id] = impl_->tree.closest_point_and_primitive(Point(q.x(), q.y(), q.z()));
  ClosestPoint result;
  result.point = Eigen::Vector3d(point.x(), point.y(), point.z());
  result.triangle = static_cast<int>(id - impl_->triangles.cbegin());
  result.normal = impl_->normals[result.triangle];
  return result;
}

int TriangleMeshProximity::triangleCount() const {
  return static_cast<int>(impl_->triangles.size());
}

}  // namespace devsurf::spatial
