#include "devsurf/terms/StripReferenceTangencyTerm.h"

#include <stdexcept>


namespace devsurf::terms {

StripReferenceTangencyTerm::StripReferenceTangencyTerm(std::string name, std::shared_ptr<StripFootPoints> feet,
                                                       Eigen::MatrixX3d normals)
    : Term(std::move(name)), feet_(std::move(feet)), normals_(std::move(normals)) {
  const std::string who = "StripReferenceTangencyTerm";
  if (!feet_) throw std::invalid_argument(who + ": no foot points");
  if (normals_.rows() != feet_->count())
    throw std::invalid_argument(who + ": expected one normal per reference point");
  if (!normals_.allFinite() || (normals_.rowwise().norm().array() < 1e-12).any())
    throw std::invalid_argument(who + ": normals must be finite and non-zero");
  normals_.rowwise().normalize();
}

void StripReferenceTangencyTerm::jacobianStructure(std::vector<engine::JacobianEntry>& entries) const {
  const int n = feet_->controlPoints();
  for (int j = 0; j < feet_->count(); ++j) {
    for (int i = 0; i < n; ++i)
      for (int c = 0; c < 3; ++c) {
        entries.push_back({2 * j, feet_->offsetA() + 3 * i + c});
        entries.push_back({2 * j, feet_->offsetB() + 3 * i + c});
      }
    for (int i = 0; i < n; ++i)
      for (int c = 0; c < 3; ++c) entries.push_back({2 * j + 1, feet_->offsetA() + 3 * i + c});
  }
}

void StripReferenceTangencyTerm::linearizeAt(const Eigen::VectorXd& x) { feet_->update(x); }

namespace {

/// ⟨m, d⟩/|d| and its gradient by d, (m − r d̂)/|d|; zero where d vanishes.
double unitComponent(const Eigen::Vector3d& m, const Eigen::Vector3d& d, Eigen::Vector3d& gradient) {
  const double length = d.norm();
  if (!(length > 1e-12)) {
    gradient.setZero();
    return 0.0;
  }
  const Eigen::Vector3d unit = d / length;
  const double r = m.dot(unit);
  gradient = (m - r * unit) / length;
  return r;
}

}  // namespace

void StripReferenceTangencyTerm::evaluate(const Eigen::VectorXd& x, double* residuals, double* jacobian) const {
  const int n = feet_->controlPoints();
  for (int j = 0; j < feet_->count(); ++j) {
    const Eigen::Vector3d m = normals_.row(j).transpose();
    Eigen::Vector3d gRuling, gTangent;
    residuals[2 * j] = unitComponent(m, feet_->a(x, j) - feet_->b(x, j), gRuling);
    residuals[2 * j + 1] = unitComponent(m, feet_->da(x, j), gTangent);
    if (!jacobian) continue;
    const double* R = feet_->basis(j);
    const double* dR = feet_->basisDerivative(j);
    for (int i = 0; i < n; ++i)
      for (int c = 0; c < 3; ++c) {
        *jacobian++ = R[i] * gRuling[c];
        *jacobian++ = -R[i] * gRuling[c];
      }
    for (int i = 0; i < n; ++i)
      for (int c = 0; c < 3; ++c) *jacobian++ = dR[i] * gTangent[c];
  }
}

}  // namespace devsurf::terms
