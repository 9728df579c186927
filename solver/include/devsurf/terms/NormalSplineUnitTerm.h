#pragma once

#include <string>

#include "devsurf/engine/Term.h"
#include "devsurf/terms/LinearPoints.h"

namespace devsurf::terms {

/// Unit length of the normals a normal spline gives where the equations use them (000_… §2.2):
/// one row ⟨n_k, n_k⟩ − 1 per evaluated normal n_k = Σ_j W(k, j) c_j. The crease rows (eq. 7/8)
/// compare two faces' normals and need them equally long; unit control points alone do not make
/// the normals between them unit (a composite's normal splines held so drifted to |n| = 0.9957).
class NormalSplineUnitTerm final : public engine::Term {
 public:
  /// @param[in] normals  the evaluated normals as linear points of the spline's control points
  NormalSplineUnitTerm(std::string name, LinearPoints normals);

  int numResiduals() const override { return normals_.rows(); }
  void jacobianStructure(std::vector<engine::JacobianEntry>& entries) const override;
  bool evaluatesFromXAlone() const override { return true; }
  void evaluate(const Eigen::VectorXd& x, double* residuals, double* jacobian) const override;

 private:
  LinearPoints normals_;
};

}  // namespace devsurf::terms
