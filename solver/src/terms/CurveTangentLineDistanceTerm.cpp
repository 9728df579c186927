#include "devsurf/terms/CurveTangentLineDistanceTerm.h"

#include <algorithm>
#include <limits>
#include <stdexcept>

#include <Eigen/Geometry>

namespace devsurf::terms {

namespace {

/// Two unit vectors completing the unit vector t to an orthonormal frame.
std::array<Eigen::Vector3d, 2> orthonormalComplement(const Eigen::Vector3d& t) {
  const Eigen::Vector3d helper = std::abs(t.x()) < 0.6 ? Eigen::Vector3d::UnitX() : Eigen::Vector3d::UnitY();
  const Eigen::Vector3d e1 = t.cross(helper).normalized();
  return {e1, t.cross(e1)};
}

}  // namespace

CurveTangentLineDistanceTerm::CurveTangentLineDistanceTerm(std::string name, LinearPoints samples,
                                                           std::vector<Eigen::Vector3d> polyline, bool pinEnds)
    : Term(std::move(name)), samples_(std::move(samples)), points_(std::move(polyline)), pinEnds_(pinEnds) {
  if (samples_.rows() == 0) throw std::invalid_argument("CurveTangentLineDistanceTerm: no samples");
  if (points_.size() < 2) throw std::invalid_argument("CurveTangentLineDistanceTerm: too few polyline points");
  for (const Eigen::Vector3d& p : points_)
    if (!p.allFinite()) throw std::invalid_argument("CurveTangentLineDistanceTerm: non-finite polyline point");
  for (std::size_t s = 0; s + 1 < points_.size(); ++s) {
    const Eigen::Vector3d d = points_[s + 1] - points_[s];
    const double length = d.norm();
    if (!(length > 0.0)) throw std::invalid_argument("CurveTangentLineDistanceTerm: zero-length segment");
    directions_.push_back(d / length);
  }
  // Constants until the first linearization: the polyline's start and its first direction.
  feet_.assign(static_cast<std::size_t>(samples_.rows()), points_.front());
  across_.assign(static_cast<std::size_t>(samples_.rows()), orthonormalComplement(directions_.front()));
}

void CurveTangentLineDistanceTerm::project(const Eigen::Vector3d& p, Eigen::Vector3d& foot,
                                           Eigen::Vector3d& tangent) const {
  double best = std::numeric_limits<double>::infinity(), bestT = 0.0;
  std::size_t bestSegment = 0;
  for (std::size_t s = 0; s + 1 < points_.size(); ++s) {
    const Eigen::Vector3d d = points_[s + 1] - points_[s];
    const double t = std::clamp((p - points_[s]).dot(d) / d.squaredNorm(), 0.0, 1.0);
    const double dist2 = (points_[s] + t * d - p).squaredNorm();
    if (dist2 < best) {
      best = dist2;
      bestSegment = s;
      bestT = t;
    }
  }
  const std::size_t s = bestSegment;
  foot = points_[s] + bestT * (points_[s + 1] - points_[s]);
  tangent = directions_[s];
  std::size_t other = s;
  if (bestT == 0.0 && s > 0) other = s - 1;
  if (bestT == 1.0 && s + 2 < points_.size()) other = s + 1;
  if (other != s) {
    const Eigen::Vector3d sum = directions_[s] + directions_[other];
    // A polyline folding back onto itself (a cusp) has no bisector: keep the segment's direction.
    if (sum.norm() > 1e-12) tangent = sum.normalized();
  }
}

void CurveTangentLineDistanceTerm::jacobianStructure(std::vector<engine::JacobianEntry>& entries) const {
  int row = 0;
  for (int k = 0; k < samples_.rows(); ++k)
    for (int c = 0; c < 2; ++c) samples_.appendStructure(k, row++, entries);
  if (pinEnds_)
    for (const int k : {0, samples_.rows() - 1})
      for (int c = 0; c < 3; ++c) samples_.appendStructure(k, row++, entries);
}

void CurveTangentLineDistanceTerm::linearizeAt(const Eigen::VectorXd& x) {
  for (int k = 0; k < samples_.rows(); ++k) {
    Eigen::Vector3d tangent;
    project(samples_.point(x, k), feet_[static_cast<std::size_t>(k)], tangent);
    across_[static_cast<std::size_t>(k)] = orthonormalComplement(tangent);
  }
}

void CurveTangentLineDistanceTerm::evaluate(const Eigen::VectorXd& x, double* residuals, double* jacobian) const {
  double* r = residuals;
  double* J = jacobian;
  for (int k = 0; k < samples_.rows(); ++k) {
    const Eigen::Vector3d gap = samples_.point(x, k) - feet_[static_cast<std::size_t>(k)];
    for (const Eigen::Vector3d& e : across_[static_cast<std::size_t>(k)]) {
      *r++ = gap.dot(e);
      if (J) J = samples_.writeJacobian(k, e, 1.0, J);
    }
  }
  if (!pinEnds_) return;
  const int last = samples_.rows() - 1;
  for (const int k : {0, last}) {
    const Eigen::Vector3d gap = samples_.point(x, k) - (k == 0 ? points_.front() : points_.back());
    for (int c = 0; c < 3; ++c) {
      *r++ = gap[c];
      if (J) J = samples_.writeJacobian(k, Eigen::Vector3d::Unit(c), 1.0, J);
    }
  }
}

}  // namespace devsurf::terms
