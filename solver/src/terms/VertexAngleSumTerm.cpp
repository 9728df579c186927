#include "devsurf/terms/VertexAngleSumTerm.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include <Eigen/Geometry>

namespace devsurf::terms {
namespace {

/// ∠(a, b) = atan2(|a×b|, a·b) and, if ga/gb are non-null, its gradients
///   ∂∠/∂a = (c (b × ŵ) − s b) / (|a|²|b|²),   ∂∠/∂b = (c (ŵ × a) − s a) / (|a|²|b|²),
/// with w = a×b, s = |w|, ŵ = w/s, c = a·b (from dθ = (c ds − s dc)/(s² + c²)). The form through
/// ŵ avoids the cancellation of −b_⊥/s at small angles.
double angle(const Eigen::Vector3d& a, const Eigen::Vector3d& b, Eigen::Vector3d* ga,
             Eigen::Vector3d* gb) {
  const Eigen::Vector3d w = a.cross(b);
  const double s = w.norm(), c = a.dot(b);
  if (ga) {
    const Eigen::Vector3d wHat = s > 0.0 ? Eigen::Vector3d(w / s) : Eigen::Vector3d::Zero();
    const double denominator = a.squaredNorm() * b.squaredNorm();
    if (denominator > 0.0) {
      *ga = (c * b.cross(wHat) - s * b) / denominator;
      *gb = (c * wHat.cross(a) - s * a) / denominator;
    } else {  // an edge of zero length: the angle is undefined, take no gradient
      ga->setZero();
      gb->setZero();
    }
  }
  return std::atan2(s, c);
}

}  // namespace

VertexAngleSumTerm::VertexAngleSumTerm(std::string name, int centerOffset,
                                       std::vector<int> neighbourOffsets, Star star,
                                       double angleSum)
    : Term(std::move(name)),
      center_(centerOffset),
      neighbours_(std::move(neighbourOffsets)),
      star_(star),
      target_(angleSum) {
  if (neighbours_.size() < (star_ == Star::Closed ? 3u : 2u))
    throw std::invalid_argument("VertexAngleSumTerm: too few neighbours");
  std::vector<int> starts = neighbours_;
  starts.push_back(center_);
  std::sort(starts.begin(), starts.end());
  for (std::size_t i = 1; i < starts.size(); ++i)
    if (starts[i] - starts[i - 1] < 3)
      throw std::invalid_argument("VertexAngleSumTerm: vertices must not share variables");
}

int VertexAngleSumTerm::numAngles() const {
  const int n = static_cast<int>(neighbours_.size());
  return star_ == Star::Closed ? n : n - 1;
}

void VertexAngleSumTerm::jacobianStructure(std::vector<engine::JacobianEntry>& entries) const {
  for (int c = 0; c < 3; ++c) entries.push_back({0, center_ + c});
  for (int offset : neighbours_)
    for (int c = 0; c < 3; ++c) entries.push_back({0, offset + c});
}

double VertexAngleSumTerm::angleSum(const Eigen::VectorXd& x) const {
  const int n = static_cast<int>(neighbours_.size());
  const Eigen::Vector3d v = x.segment<3>(center_);
  double sum = 0.0;
  for (int i = 0; i < numAngles(); ++i)
    sum += angle(x.segment<3>(neighbours_[i]) - v, x.segment<3>(neighbours_[(i + 1) % n]) - v,
                 nullptr, nullptr);
  return sum;
}

void VertexAngleSumTerm::evaluate(const Eigen::VectorXd& x, double* residuals,
                                  double* jacobian) const {
  if (!jacobian) {
    residuals[0] = angleSum(x) - target_;
    return;
  }
  const int n = static_cast<int>(neighbours_.size());
  const Eigen::Vector3d v = x.segment<3>(center_);
  // jacobian[0..2]: center; jacobian[3 + 3i ..]: neighbour i.
  std::fill(jacobian, jacobian + 3 * (n + 1), 0.0);
  Eigen::Map<Eigen::Vector3d> center(jacobian);
  double sum = 0.0;
  for (int i = 0; i < numAngles(); ++i) {
    const int j = (i + 1) % n;
    Eigen::Vector3d ga, gb;
    sum += angle(x.segment<3>(neighbours_[i]) - v, x.segment<3>(neighbours_[j]) - v, &ga, &gb);
    Eigen::Map<Eigen::Vector3d>(jacobian + 3 + 3 * i) += ga;
    Eigen::Map<Eigen::Vector3d>(jacobian + 3 + 3 * j) += gb;
    center -= ga + gb;
  }
  residuals[0] = sum - target_;
}

}  // namespace devsurf::terms
