#include "devsurf/spatial/SegmentSetProximity.h"

#include <stdexcept>
#include <string>
#include <vector>

#include <CGAL/AABB_segment_primitive.h>
#include <CGAL/AABB_traits.h>
#include <CGAL/AABB_tree.h>
#include <CGAL/Simple_cartesian.h>

namespace devsurf::spatial {
namespace {

using Kernel = CGAL::Simple_cartesian<double>;
using Point = Kernel::Point_3;
using Segment = Kernel::Segment_3;
using SegmentIterator = std::vector<Segment>::const_iterator;
using SegmentPrimitive = CGAL::AABB_segment_primitive<Kernel, SegmentIterator>;
using SegmentTree = CGAL::AABB_tree<CGAL::AABB_traits<Kernel, SegmentPrimitive>>;

}  // namespace

struct SegmentSetProximity::Impl {
  std::vector<Segment> segments;  // the tree's primitives point into this (never resized)
  SegmentTree tree;
};

SegmentSetProximity::SegmentSetProximity(const Eigen::MatrixX3d& from, const Eigen::MatrixX3d& to)
    : impl_(std::make_unique<Impl>()) {
  const std::string who = "SegmentSetProximity: ";
  if (from.rows() == 0) throw std::invalid_argument(who + "no segments");
  if (from.rows() != to.rows()) throw std::invalid_argument(who + "end point counts differ");
  if (!from.allFinite() || !to.allFinite()) throw std::invalid_argument(who + "an end point is not finite");
  impl_->segments.reserve(from.rows());
  for (Eigen::Index k = 0; k < from.rows(); ++k) {
    if (!((from.row(k) - to.row(k)).norm() > 0.0))
      throw std::invalid_argument(who + "segment " + std::to_string(k) + " has zero length");
    impl_->segments.emplace_back(Point(from(k, 0), from(k, 1), from(k, 2)), Point(to(k, 0), to(k, 1), to(k, 2)));
  }
  impl_->tree.insert(impl_->segments.cbegin(), impl_->segments.cend());
  impl_->tree.build();
  impl_->tree.accelerate_distance_queries();
}

SegmentSetProximity::~SegmentSetProximity() = default;
SegmentSetProximity::SegmentSetProximity(SegmentSetProximity&&) noexcept = default;
SegmentSetProximity& SegmentSetProximity::operator=(SegmentSetProximity&&) noexcept = default;

ClosestSegmentPoint SegmentSetProximity::closest(const Eigen::Vector3d& q) const {
  const auto [point, id] = impl_->tree.closest_point_and_primitive(Point(q.x(), q.y(), q.z()));
  ClosestSegmentPoint result;
  result.point = Eigen::Vector3d(point.x(), point.y(), point.z());
  result.segment = static_cast<int>(id - impl_->segments.cbegin());
  return result;
}

}  // namespace devsurf::spatial
