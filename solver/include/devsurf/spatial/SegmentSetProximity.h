#pragma once

#include <memory>

#include <Eigen/Core>

namespace devsurf::spatial {

/// The point of a segment set closest to a query point.
struct ClosestSegmentPoint {
  Eigen::Vector3d point;  ///< on the set
  int segment = -1;       ///< row of the segment list holding it
};

/// Closest-point queries on a fixed set of line segments (e.g. the borders between a mesh's
/// patches in its map to the plane): CGAL's AABB tree over the segments, built once. Queries are
/// const and may run concurrently; CGAL stays inside the implementation.
class SegmentSetProximity {
 public:
  /// @param[in] from, to  s×3 end points, finite; segment k runs from from.row(k) to to.row(k)
  /// @throws std::invalid_argument on no segments, counts that differ, a non-finite coordinate or
  ///         a segment of zero length (the message names it)
  SegmentSetProximity(const Eigen::MatrixX3d& from, const Eigen::MatrixX3d& to);
  ~SegmentSetProximity();
  SegmentSetProximity(SegmentSetProximity&&) noexcept;
  SegmentSetProximity& operator=(SegmentSetProximity&&) noexcept;
  SegmentSetProximity(const SegmentSetProximity&) = delete;
  SegmentSetProximity& operator=(const SegmentSetProximity&) = delete;

  ClosestSegmentPoint closest(const Eigen::Vector3d& q) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace devsurf::spatial
