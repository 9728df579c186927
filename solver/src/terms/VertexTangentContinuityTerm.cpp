#include "devsurf/terms/VertexTangentContinuityTerm.h"

#include <Eigen/Geometry>
#include <cstdlib>
#include <stdexcept>

namespace devsurf::terms {

VertexTangentContinuityTerm::VertexTangentContinuityTerm(std::string name, int vertexOffset, int aOffset,
                                                         int bOffset)
    : Term(std::move(name)), v_(vertexOffset), a_(aOffset), b_(bOffset) {
  if (std::abs(v_ - a_) < 3 || std::abs(v_ - b_) < 3 || std::abs(a_ - b_) < 3)
    throw std::invalid_argument("VertexTangentContinuityTerm: the three points must not share variables");
}

void VertexTangentContinuityTerm::jacobianStructure(std::vector<engine::JacobianEntry>& entries) const {
  // Row r: 9 entries, v (3), a (3), b (3), in that order.
  for (int r = 0; r < 3; ++r)
    for (int base : {v_, a_, b_})
      for (int c = 0; c < 3; ++c) entries.push_back({r, base + c});
}

void VertexTangentContinuityTerm::evaluate(const Eigen::VectorXd& x, double* residuals, double* jacobian) const {
  const Eigen::Vector3d v = x.segment<3>(v_);
  const Eigen::Vector3d p = x.segment<3>(a_) - v, q = x.segment<3>(b_) - v;
  const Eigen::Vector3d r = p.cross(q);
  for (int i = 0; i < 3; ++i) residuals[i] = r[i];
  if (!jacobian) return;
  // d(p × q) = dp × q + p × dq = −[q]× dp + [p]× dq, with dp = da − dv, dq = db − dv.
  auto skew = [](const Eigen::Vector3d& w) {
    Eigen::Matrix3d m;
    m << 0, -w.z(), w.y(), w.z(), 0, -w.x(), -w.y(), w.x(), 0;
    return m;
  };
  const Eigen::Matrix3d dA = -skew(q), dB = skew(p), dV = -(dA + dB);
  for (int row = 0; row < 3; ++row) {
    double* j = jacobian + 9 * row;
    for (int c = 0; c < 3; ++c) {
      j[c] = dV(row, c);
      j[3 + c] = dA(row, c);
      j[6 + c] = dB(row, c);
    }
  }
}

}  // namespace devsurf::terms
