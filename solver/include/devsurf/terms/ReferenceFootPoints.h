#pragma once

#include <cstdint>
#include <memory>
#include <vector>

#include <Eigen/Core>

#include "devsurf/spatial/TriangleMeshProximity.h"

namespace devsurf::terms {

/// The closest points on a reference triangle mesh Φ of a set of points of x, shared by the
/// proximity terms that renew their foot points at the same points (004_… §2.3.2: E_prox,1 and
/// E_prox,2 on the vertices of one mesh M). Each term's linearizeAt() asks for the feet at x; the
/// closest-point queries run once per x, not once per term, and give what a query per term gave.
///
/// Not thread-safe: the engine linearizes its terms on one thread.
class ReferenceFootPoints {
 public:
  /// @param[in] reference     Φ (shared, immutable)
  /// @param[in] pointOffsets  index in x of each point's x coordinate (y at +1, z at +2)
  /// @throws std::invalid_argument on a null reference or a negative offset
  ReferenceFootPoints(std::shared_ptr<const spatial::TriangleMeshProximity> reference,
                      std::vector<int> pointOffsets);

  /// The closest point on Φ of every point at x, in pointOffsets() order. Queried again only when
  /// some point differs (bitwise) from the points of the last queries.
  /// @param[in] x  the unknowns; every offset + 2 < x.size()
  const std::vector<spatial::ClosestPoint>& at(const Eigen::VectorXd& x);

  const std::vector<int>& pointOffsets() const { return offsets_; }
  int numPoints() const { return static_cast<int>(offsets_.size()); }
  /// Closest-point queries run so far (one per point each time the points moved).
  std::int64_t queryCount() const { return queries_; }

 private:
  std::shared_ptr<const spatial::TriangleMeshProximity> reference_;
  std::vector<int> offsets_;
  std::vector<Eigen::Vector3d> queried_;  ///< the points of the last queries
  std::vector<spatial::ClosestPoint> feet_;
  bool valid_ = false;
  std::int64_t queries_ = 0;
};

}  // namespace devsurf::terms
