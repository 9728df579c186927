#include "devsurf/terms/NormalSplineUnitTerm.h"

#include <utility>

namespace devsurf::terms {

NormalSplineUnitTerm::NormalSplineUnitTerm(std::string name, LinearPoints normals)
    : Term(std::move(name)), normals_(std::move(normals)) {}

void NormalSplineUnitTerm::jacobianStructure(std::vector<engine::JacobianEntry>& entries) const {
  for (int k = 0; k < numResiduals(); ++k) normals_.appendStructure(k, k, entries);
}

void NormalSplineUnitTerm::evaluate(const Eigen::VectorXd& x, double* residuals, double* jacobian) const {
  double* out = jacobian;
  for (int k = 0; k < numResiduals(); ++k) {
    const Eigen::Vector3d n = normals_.point(x, k);
    residuals[k] = n.squaredNorm() - 1.0;
    if (jacobian) out = normals_.writeJacobian(k, n, 2.0, out);  // ∂⟨n, n⟩ = 2⟨n, ∂n⟩
  }
}

}  // namespace devsurf::terms
