#pragma once

#include <array>
#include <string>
#include <vector>

#include "devsurf/engine/Term.h"

namespace devsurf::terms {

/// Periodicity of a development cut open along a seam (000_… §6 Fig. 14): a vertex on the seam
/// has two images v̄ and v̄′ in the development (one per side), and for every such pair two rows
///   v̄′ − v̄ − T,
/// with T the period (two variables shared by all pairs). The development then closes up on a
/// cylinder of circumference |T|. Linear.
class DevelopmentPeriodTerm final : public engine::Term {
 public:
  /// @param[in] pairs         per seam vertex {index in x of v̄, index in x of v̄′} (x̄ at o, ȳ at o+1)
  /// @param[in] periodOffset  index in x of T (T_x at o, T_y at o+1)
  /// @throws std::invalid_argument if a pair uses the same variables twice or overlaps T
  DevelopmentPeriodTerm(std::string name, std::vector<std::array<int, 2>> pairs, int periodOffset);

  int numResiduals() const override { return 2 * static_cast<int>(pairs_.size()); }
  void jacobianStructure(std::vector<engine::JacobianEntry>& entries) const override;
  bool evaluatesFromXAlone() const override { return true; }
  void evaluate(const Eigen::VectorXd& x, double* residuals, double* jacobian) const override;

 private:
  std::vector<std::array<int, 2>> pairs_;
  int period_;
};

}  // namespace devsurf::terms
