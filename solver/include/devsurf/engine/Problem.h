#pragma once

#include <memory>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "devsurf/engine/Term.h"
#include "devsurf/engine/VariableLayout.h"

namespace devsurf::engine {

/// Whether a term is a constraint to satisfy (hard) or an energy that guides (soft).
enum class Strength { Hard, Soft };

/// How the solver's schedule scales a term's weight.
enum class WeightSchedule {
  Constant,  ///< weight as given
  Fairness,  ///< weight × ε_fair · decay^k (the decaying fairness energy of 000_… eq. 6)
};

/// A term registered in a problem, with the weight the assembler applies to its rows.
struct TermSlot {
  std::unique_ptr<Term> term;
  double weight = 1.0;
  Strength strength = Strength::Hard;
  WeightSchedule schedule = WeightSchedule::Constant;
  /// A user target (a handle) that step control may weaken when pulling toward it would tear the
  /// hard rows (StepControlOptions). Its weight in the summary stays the nominal one.
  bool relaxable = false;
  /// A relaxable term that projection steps keep when asked (SolverOptions::
  /// holdTargetsInProjection): a design intent rather than a pointer, such as the fold slider's
  /// fold-angle targets — without them a fold's release unfolds a curved fold whose hard rows the
  /// discretization meets only approximately (90° → 45° on two cubic creases).
  bool heldInProjection = false;
};

/// Variables and terms: everything guided projection needs to know about a model.
///
/// The variable vector `x` and the term weights may change freely between solves; adding
/// blocks or terms or changing which variables are fixed changes the topology and requires a new
/// solver (GuidedProjectionSolver analyzes the topology once, in its constructor).
class Problem {
 public:
  VariableLayout& layout() { return layout_; }
  const VariableLayout& layout() const { return layout_; }

  /// Adds a block and grows x (new entries are zero). Returns the block id.
  int addBlock(const std::string& name, int size);

  Eigen::VectorXd& x() { return x_; }
  const Eigen::VectorXd& x() const { return x_; }
  /// The scalars of one block, as a view into x.
  Eigen::Map<Eigen::VectorXd> blockValues(int block);
  Eigen::Map<const Eigen::VectorXd> blockValues(int block) const;

  /// Registers a term; returns its id.
  int addTerm(std::unique_ptr<Term> term, double weight, Strength strength,
              WeightSchedule schedule = WeightSchedule::Constant);
  int numTerms() const { return static_cast<int>(terms_.size()); }
  TermSlot& term(int id) { return terms_.at(id); }
  const TermSlot& term(int id) const { return terms_.at(id); }
  void setWeight(int id, double weight) { terms_.at(id).weight = weight; }

  /// Total residual rows of all terms.
  int numResiduals() const;

 private:
  VariableLayout layout_;
  Eigen::VectorXd x_;
  std::vector<TermSlot> terms_;
};

}  // namespace devsurf::engine
