#include "devsurf/terms/ReferenceFootPoints.h"

#include <cassert>
#include <cstring>
#include <stdexcept>
#include <string>

namespace devsurf::terms {

ReferenceFootPoints::ReferenceFootPoints(std::shared_ptr<const spatial::TriangleMeshProximity> reference,
                                         std::vector<int> pointOffsets)
    : reference_(std::move(reference)), offsets_(std::move(pointOffsets)) {
  if (!reference_) throw std::invalid_argument("ReferenceFootPoints: no reference mesh");
  for (std::size_t i = 0; i < offsets_.size(); ++i)
    if (offsets_[i] < 0)
      throw std::invalid_argument("ReferenceFootPoints: point " + std::to_string(i) + " has a negative offset");
  queried_.assign(offsets_.size(), Eigen::Vector3d::Zero());
  feet_.resize(offsets_.size());
}

const std::vector<spatial::ClosestPoint>& ReferenceFootPoints::at(const Eigen::VectorXd& x) {
  bool same = valid_;
  for (std::size_t i = 0; i < offsets_.size() && same; ++i) {
    assert(offsets_[i] + 2 < x.size() && "a point's coordinates lie in x");
    same = std::memcmp(x.data() + offsets_[i], queried_[i].data(), 3 * sizeof(double)) == 0;
  }
  if (same) return feet_;
  valid_ = false;  // stays false if a query throws partway
  for (std::size_t i = 0; i < offsets_.size(); ++i) {
    queried_[i] = x.segment<3>(offsets_[i]);
    feet_[i] = reference_->closest(queried_[i]);
  }
  queries_ += static_cast<std::int64_t>(offsets_.size());
  valid_ = true;
  return feet_;
}

}  // namespace devsurf::terms
