#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>

namespace devsurf::engine {

/// One structural nonzero of a term's Jacobian: residual row (local to the term) and the index of
/// the variable in x it differentiates by.
struct JacobianEntry {
  int row = 0;
  int variable = 0;
};

/// A block of residuals with its Jacobian (Ceres `CostFunction`, ShapeOp `Constraint`).
///
/// A term declares its rows and the fixed structure of its Jacobian once (`jacobianStructure`);
/// every evaluation then writes residual values and Jacobian values into storage the assembler
/// preallocated, in the order of that structure. Terms never apply weights: the assembler does,
/// so weights can change between iterations. A term must not list the same (row, variable) twice.
class Term {
 public:
  virtual ~Term() = default;

  /// Instance name used in summaries and reports, e.g. "developability", "fairness a".
  const std::string& name() const { return name_; }

  /// Number of residual rows.
  virtual int numResiduals() const = 0;

  /// Appends the structural nonzeros to `entries` (rows local to this term). Called once per
  /// topology; the order fixes the layout of the `jacobian` array in evaluate().
  virtual void jacobianStructure(std::vector<JacobianEntry>& entries) const = 0;

  /// Refreshes constants that are held fixed during one iteration (row scales, foot points of
  /// tangent-distance terms) from the current iterate. Called once per iteration before
  /// evaluate(). The default does nothing.
  virtual void linearizeAt(const Eigen::VectorXd& x) {}

  /// Whether evaluate() depends on x alone: linearizeAt() is the default one, and no state that
  /// another term or the caller changes during a solve enters it (a handle's target may move
  /// between iterations, so handles say no). NormalEquations then keeps the Jacobian of such a
  /// term from a residual evaluation and gives it to the next assemble() at the same x: the
  /// evaluation that judges a step is also the next iteration's (NormalEquations::residuals).
  /// Default false.
  virtual bool evaluatesFromXAlone() const { return false; }

  /// Writes numResiduals() residuals and, unless `jacobian` is null, one value per structural
  /// entry in jacobianStructure() order.
  /// @param[in]  x          all variables
  /// @param[out] residuals  numResiduals() values
  /// @param[out] jacobian   nullptr for a residual-only evaluation
  virtual void evaluate(const Eigen::VectorXd& x, double* residuals, double* jacobian) const = 0;

 protected:
  explicit Term(std::string name) : name_(std::move(name)) {}

 private:
  std::string name_;
};

}  // namespace devsurf::engine
