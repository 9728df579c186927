#include "devsurf/terms/TangentDistanceTerm.h"

#include <algorithm>
#include <limits>
#include <stdexcept>

namespace devsurf::terms {

TangentDistanceTerm::TangentDistanceTerm(std::string name, std::vector<int> developedOffsets,
                                         std::vector<Eigen::Vector2d> polyline, bool closed)
    : Term(std::move(name)),
      offsets_(std::move(developedOffsets)),
      points_(std::move(polyline)),
      closed_(closed) {
  if (points_.size() < (closed_ ? 3u : 2u))
    throw std::invalid_argument("TangentDistanceTerm: too few polyline points");
  for (int s = 0; s < numSegments(); ++s) {
    const Eigen::Vector2d d = points_[(s + 1) % points_.size()] - points_[s];
    const double length = d.norm();
    if (!(length > 0.0)) throw std::invalid_argument("TangentDistanceTerm: zero-length segment");
    segmentNormals_.emplace_back(d.y() / length, -d.x() / length);
  }
  // Initial constants: the vertices' own positions are unknown here; linearizeAt() sets them.
  feet_.assign(offsets_.size(), Eigen::Vector2d::Zero());
  normals_.assign(offsets_.size(), Eigen::Vector2d::UnitX());
}

int TangentDistanceTerm::numSegments() const {
  const int n = static_cast<int>(points_.size());
  return closed_ ? n : n - 1;
}

void TangentDistanceTerm::project(const Eigen::Vector2d& p, Eigen::Vector2d& foot,
                                  Eigen::Vector2d& normal) const {
  const int n = static_cast<int>(points_.size());
  double best = std::numeric_limits<double>::infinity();
  int bestSegment = 0;
  double bestT = 0.0;
  for (int s = 0; s < numSegments(); ++s) {
    const Eigen::Vector2d& a = points_[s];
    const Eigen::Vector2d d = points_[(s + 1) % n] - a;
    const double t = std::clamp((p - a).dot(d) / d.squaredNorm(), 0.0, 1.0);
    const double dist2 = (a + t * d - p).squaredNorm();
    if (dist2 < best) {
      best = dist2;
      bestSegment = s;
      bestT = t;
    }
  }
  const int s = bestSegment;
  foot = points_[s] + bestT * (points_[(s + 1) % n] - points_[s]);
  // Which polyline vertex the foot point sits on, if any, and its other segment.
  int other = -1;
  if (bestT == 0.0 && (closed_ || s > 0)) other = (s - 1 + numSegments()) % numSegments();
  if (bestT == 1.0 && (closed_ || s + 1 < numSegments())) other = (s + 1) % numSegments();
  normal = segmentNormals_[s];
  if (other >= 0) {
    const Eigen::Vector2d sum = segmentNormals_[s] + segmentNormals_[other];
    // A polyline folding back onto itself (a cusp) has no bisector: keep the segment's normal.
    if (sum.norm() > 1e-12) normal = sum.normalized();
  }
}

void TangentDistanceTerm::jacobianStructure(std::vector<engine::JacobianEntry>& entries) const {
  for (int i = 0; i < numResiduals(); ++i)
    for (int c = 0; c < 2; ++c) entries.push_back({i, offsets_[i] + c});
}

void TangentDistanceTerm::linearizeAt(const Eigen::VectorXd& x) {
  for (int i = 0; i < numResiduals(); ++i)
    project(x.segment<2>(offsets_[i]), feet_[i], normals_[i]);
}

void TangentDistanceTerm::evaluate(const Eigen::VectorXd& x, double* residuals,
                                   double* jacobian) const {
  for (int i = 0; i < numResiduals(); ++i) {
    residuals[i] = (x.segment<2>(offsets_[i]) - feet_[i]).dot(normals_[i]);
    if (jacobian) {
      jacobian[2 * i] = normals_[i].x();
      jacobian[2 * i + 1] = normals_[i].y();
    }
  }
}

}  // namespace devsurf::terms
