#pragma once

#include <limits>
#include <vector>

#include <Eigen/Core>

#include "devsurf/engine/LinearSolver.h"
#include "devsurf/engine/Deadline.h"
#include "devsurf/engine/Problem.h"

namespace devsurf::engine {

/// The normal equations of one guided-projection step on a fixed sparsity pattern:
/// H = Σ_terms w_t² J_tᵀJ_t + ε_reg² D and g = Σ_terms w_t² J_tᵀ r_t over the free variables
/// (D: per-block regularization scales), solved as H δ = −g.
///
/// The constructor does all per-topology work (Tang et al. 2016 §3.2 on a fixed pattern):
/// collects every term's Jacobian structure, drops fixed variables, chooses the variables to
/// eliminate (below), computes a fill-reducing (AMD) ordering of the rest, builds the
/// upper-triangular pattern of the reduced matrix in that ordering and the maps from Jacobian
/// entries to its slots. Per iteration nothing allocates and only numbers are filled in.
///
/// Schur elimination (the bundle-adjustment trick). Free variables split into *kept* ones and
/// *elimination groups*: small sets of variables no residual row couples with another group, so
/// H restricted to them is block diagonal. For the strip these are the normals (one 3×3 block per
/// evaluation parameter, coupled only to the 8 control points of its span). Per group the
/// assembler forms the dense weighted Jacobian of the group's rows [J_n J_c] (group columns,
/// kept columns), factors A_nn = J_nᵀJ_n + ε²D_n = LLᵀ and adds J_cᵀ(I − V Vᵀ)J_c with
/// V = J_n L⁻ᵀ (= H_cc − H_cn H_nn⁻¹ H_nc for these rows) to the reduced matrix S; groups with the
/// same kept columns are accumulated densely before one scatter. The linear solver factors only S
/// (for the strip 9 015 instead of 40 515 unknowns, no fill); `applyStep` back-substitutes
/// δ_n = −A_nn⁻¹ J_nᵀ(r + J_c δ_c). Which variables are eliminated: see
/// VariableLayout::setEliminable (default: groups of scalars sharing all their rows whose
/// elimination creates no fill-in). Without groups S = H and the path is the plain one.
///
/// Per iteration: assemble() → eliminate() → factor matrix() / solve with rhs() → applyStep().
class NormalEquations {
 public:
  /// @throws std::logic_error if a term lists a variable twice in one row, an entry is out of
  ///         range, or a row couples two declared elimination groups; DeadlineExceeded once
  ///         `deadline` has passed (checked between the phases and in the loops over rows).
  /// @param[in] part  the free scalars this system solves for (VariableLayout::setAlternating):
  ///            the others are held as if fixed. For a part other than All, terms with no entry
  ///            on the part are neither evaluated nor linearized by assemble() (they are constant
  ///            in this system); see touchesPart().
  explicit NormalEquations(const Problem& problem, const Deadline& deadline = {},
                           VariablePart part = VariablePart::All);

  /// Evaluates every term at x (after linearizeAt) and fills the part of the reduced system that
  /// involves no eliminated variable; eliminate() completes it.
  /// @param[in] termWeights  effective weight per term id (schedule applied)
  /// @param[in] regularization  ε_reg (Tikhonov, added to the diagonal as ε_reg² · block scale)
  /// @param[out] termResiduals  per term id: Σ (w r)² at x (the shortened residuals, see below)
  /// @param[in] relaxableLimit  the residual vector of every relaxable term (TermSlot::relaxable) is
  ///            shortened to at most this norm before it enters the system (a handle's target
  ///            brought to within that distance): the step control's pull limit
  void assemble(Problem& problem, const std::vector<double>& termWeights, double regularization,
                std::vector<double>& termResiduals,
                double relaxableLimit = std::numeric_limits<double>::infinity());

  /// Accumulates the rows' products on a second thread when `threads` ≥ 2 and one assembly has at
  /// least kParallelAssemblyProducts of them (issue 17: the machine's two cores): the terms are
  /// split once into two runs of about equal products, the second run accumulated into its own
  /// copy of S and rhs, added after. The partition depends on the pattern only, so every run gives
  /// the same numbers (they differ from one thread's in the last bits: another order of sums).
  /// Terms are still evaluated on the calling thread (they may share state). Default: one thread.
  /// @param[in] minProducts  the threshold (tests lower it to split small systems)
  void setAssemblyThreads(int threads, long minProducts = kParallelAssemblyProducts);
  /// 1 or 2: what setAssemblyThreads chose.
  int assemblyThreads() const { return assemblyThreads_; }
  /// Wall time the calling thread has waited for the second assembly thread so far (ms, summed
  /// over every assembly): with it, a budget on the calling thread's CPU clock still counts the
  /// time an assembly on two threads takes (SolverOptions::budgetClock).
  double assemblyWaitMs() const { return assemblyWaitMs_; }
  /// Products per assembly (Σ over direct rows of n(n+1)/2) from which a second thread pays for
  /// itself (starting and joining a thread, summing a copy of S: well under a millisecond).
  static constexpr long kParallelAssemblyProducts = 2'000'000;

  /// Eliminates every elimination group (block Gaussian elimination of H, the first stage of its
  /// factorization) into matrix() and rhs(), using the Jacobian of the last assemble(). Returns
  /// false if a group's diagonal block is not numerically positive definite (then H is not).
  /// A no-op (true) without groups.
  bool eliminate();

  /// Residual evaluation: per term id Σ (w r)² at x (no linearizeAt). The terms that evaluate
  /// from x alone (Term::evaluatesFromXAlone) also write their Jacobians, into a buffer of their
  /// own: when the next assemble() is at the same x — the step this evaluation judged was taken —
  /// it takes their residuals and Jacobians instead of evaluating them again (one evaluation of
  /// them per iteration, not two; the same numbers bit for bit). A later call at another x,
  /// partResiduals(), correctionRhs() or assemble() itself replaces or drops what was kept.
  /// @param[out] termMaxAbs  optional: per term id the largest |r| of its rows (unweighted)
  void residuals(const Problem& problem, const Eigen::VectorXd& x,
                 const std::vector<double>& termWeights, std::vector<double>& termResiduals,
                 std::vector<double>* termMaxAbs = nullptr);

  /// Drops the evaluation residuals() kept: the problem changed in a way x does not show (a
  /// handle's target, a term's data). GuidedProjectionSolver::solve calls it first.
  void forgetKeptEvaluation() { keptValid_ = false; }
  /// Whether residuals() keeps Jacobians for the next assemble() (default true; tests compare).
  /// Forgets what was kept; off, the buffers are released (a system whose steps residuals() never
  /// judges, the alternating side's, turns it off).
  void setKeepEvaluations(bool keep);
  /// Terms the last assemble() took from residuals() instead of evaluating them.
  int reusedTerms() const { return reusedTerms_; }

  /// The right-hand side of a correction step (SolverOptions::correctionSteps) after a step
  /// (assemble(), eliminate(), a solve, applyStep()): the hard rows evaluated again at x (no
  /// linearizeAt: the per-iteration scales of the terms stay those of the last assemble()), the
  /// other rows' residuals taken as 0, and rhs() = the reduced −Σ w² Jᵀ r with the Jacobian,
  /// weights and group factors of that step. matrix() δ = rhs(), solved with the step's
  /// factorization and applied by applyStep() (which back-substitutes the groups with these
  /// residuals), moves x back onto the hard rows along the step's linearization — the soft rows
  /// (fairness, handles) and ε_reg resist the move as they weigh in the step, but do not pull.
  void correctionRhs(const Problem& problem, const Eigen::VectorXd& x);

  /// Whether term `t` has an entry on a free scalar of this system's part (every term with free
  /// entries, for VariablePart::All).
  bool touchesPart(int t) const { return plans_[static_cast<std::size_t>(t)].numFreeEntries > 0; }

  /// residuals() for the terms that touch this system's part only: their entries of
  /// termResiduals (and termMaxAbs) are replaced, the others' kept (the other terms are constant
  /// in a step of this system).
  void partResiduals(const Problem& problem, const Eigen::VectorXd& x, const std::vector<double>& termWeights,
                     std::vector<double>& termResiduals, std::vector<double>& termMaxAbs);

  /// Upper triangle of the reduced matrix S in the solver ordering (after eliminate()).
  const SymmetricUpper& matrix() const { return S_; }
  /// Right-hand side of S δ_c = rhs in the solver ordering (after eliminate()).
  const Eigen::VectorXd& rhs() const { return rhs_; }
  /// Free (not fixed) scalars: kept plus eliminated.
  int numFree() const { return numFree_; }
  /// Size of matrix(): the free scalars that are not eliminated.
  int numReduced() const { return numReduced_; }
  int numEliminated() const { return numFree_ - numReduced_; }
  int numEliminationGroups() const { return static_cast<int>(groups_.size()); }
  /// Structural upper-triangular nonzeros of the full normal matrix H over all free scalars
  /// (what a solver without elimination would store).
  long nonZeros() const { return nonZerosFull_; }
  /// Stored upper-triangular nonzeros of matrix().
  long reducedNonZeros() const { return static_cast<long>(S_.nonZeros()); }
  /// Adds the step to the free variables of x: the kept ones from `delta` (solution of
  /// matrix() δ = rhs(), solver ordering), the eliminated ones by back-substitution with the
  /// Jacobian of the last assemble()/eliminate(). Returns ‖δ‖² over all free scalars.
  double applyStep(const Eigen::VectorXd& delta, Eigen::VectorXd& x);

 private:
  struct TermPlan {
    int numResiduals = 0;
    int numEntries = 0;
    int numFreeEntries = 0;            ///< entries on free scalars of this system's part
    // Rows that touch no eliminated variable, as CSR over their free entries.
    std::vector<int> directRow;        ///< residual row of each direct row
    std::vector<int> directStart;      ///< entries of direct row i: [directStart[i], directStart[i+1])
    std::vector<int> directEntry;      ///< entry id (index into this term's Jacobian values)
    std::vector<int> directColumn;     ///< reduced column of that entry
    /// Per direct row: L ≥ 1 at the first of L consecutive rows with the same columns in the same
    /// order (the samples of one span: their products are summed densely and scattered once), 0
    /// at the others of the run.
    std::vector<int> directRun;
    std::vector<int> pairSlot;         ///< per run, per pair (a ≤ b in row order): slot in S
    long directProducts = 0;           ///< the products one assembly adds (every row's)
  };
  /// A run of groups with the same kept columns: their kept Jacobian rows are stacked and the
  /// update of S is one dense product, scattered once.
  struct EliminationBlock {
    int groupBegin = 0, groupEnd = 0;
    int numKept = 0;      ///< c: kept columns the groups couple to
    int numKeptRows = 0;  ///< K: Σ over the groups of their rows with kept entries
    int keptOffset = 0;   ///< into blockColumn_ (c reduced columns, ascending)
    int slotOffset = 0;   ///< into blockSlot_ (c(c+1)/2 slots, pairs a ≤ b row by row)
  };
  struct EliminationGroup {
    int size = 0;          ///< m eliminated scalars
    int numRows = 0;       ///< rows touching the group; those with kept entries come first
    int numKeptRows = 0;   ///< rows with at least one kept entry
    int rowOffset = 0;     ///< into groupRow*_ arrays
    int keptRowOffset = 0; ///< first of its kept rows in the block's stacked rows
    int varOffset = 0;     ///< into groupVariable_ / groupRegularization_
    int factorOffset = 0;  ///< into factors_: L (m×m, row-major lower), t = L⁻¹J_nᵀr (m),
                           ///< U = L⁻¹J_nᵀJ_c (m×c, row-major)
  };

  /// Eliminates one group into the block's stacked rows Jc / Y and rhs_block; M = group size
  /// when known at compile time (0: any). False if A_nn is not positive definite.
  template <int M>
  bool eliminateGroup(const EliminationGroup& g, int ld, double* Jc, double* Y, double* rb);
  /// The weighted rows of one group from the last assemble(): J_n (numRows × m) into jn_, w r into
  /// localResidual_, its kept entries into the block's stacked rows Jc.
  void gatherGroupRows(const EliminationGroup& g, int m, double* Jc);
  /// correctionRhs() for one group: its t from the correction's residuals with the step's factor,
  /// and its part of the block's right-hand side rb.
  void correctGroup(const EliminationGroup& g, int ld, double* Jc, double* rb);

  std::vector<TermPlan> plans_;
  std::vector<int> termResidualOffset_;  ///< term → first index in residual_
  std::vector<int> termJacobianOffset_;  ///< term → first index in jacobian_
  Eigen::VectorXd residual_;             ///< all terms' residuals of the last evaluation
  Eigen::VectorXd jacobian_;             ///< all terms' Jacobian values of the last assemble()
  std::vector<double> weights_;          ///< term weights of the last assemble()
  double eps2_ = 0.0;                    ///< ε_reg² of the last assemble()

  std::vector<int> keptVariable_; ///< reduced column → variable (index in x)
  std::vector<int> diagonalSlot_; ///< reduced column → slot of its diagonal entry
  std::vector<double> regularizationScale_;  ///< reduced column → multiplier of ε_reg²
  int numFree_ = 0;
  int numReduced_ = 0;
  long nonZerosFull_ = 0;
  SymmetricUpper S_;
  Eigen::VectorXd rhs_;

  // Elimination groups, in processing order.
  std::vector<EliminationBlock> blocks_;
  std::vector<EliminationGroup> groups_;
  std::vector<int> blockColumn_;
  std::vector<int> blockSlot_;
  std::vector<int> groupRowTerm_;        ///< per group row: term id (its weight)
  std::vector<int> groupRowResidual_;    ///< per group row: index into residual_
  /// Per group row: its entries on the group's own scalars are [start, split), its entries on
  /// kept columns [split, next start) (last row: a sentinel start).
  std::vector<int> groupRowStart_, groupRowSplit_;
  std::vector<int> groupEntrySource_;    ///< index into jacobian_
  /// Own-scalar entry: index into the group's J_n (numRows × m, row-major); kept entry: index
  /// into the block's stacked J_c rows (K × c, row-major).
  std::vector<int> groupEntryDest_;
  std::vector<int> groupVariable_;       ///< per eliminated scalar: index in x
  std::vector<double> groupRegularization_;  ///< per eliminated scalar: multiplier of ε_reg²
  std::vector<double> factors_;
  // Scratch, sized for the largest group/block at construction.
  std::vector<double> rowValues_;  ///< one direct row's Jacobian values, then a run's dense sum
  int longestDirectRow_ = 0;
  /// Adds w²JᵀJ and −w²Jᵀr of the direct rows of terms [firstTerm, endTerm) (from the last
  /// evaluation) into H (S's value array) and rhs; jr: scratch for one row and one run's sum
  /// (rowValues_'s size).
  void accumulateDirectRows(int firstTerm, int endTerm, double* H, double* rhs, double* jr) const;
  long directProducts_ = 0;          ///< Σ over all terms of TermPlan::directProducts
  VariablePart part_ = VariablePart::All;
  /// Evaluates the term at x into residual_ (and its Jacobian into `jacobian` unless null); per
  /// term Σ r² and the largest |r|.
  void evaluateResidual(const Problem& problem, int t, const Eigen::VectorXd& x, double& energy,
                        double& largest, double* jacobian = nullptr);
  // residuals()'s kept evaluation (see there).
  std::vector<char> keptTerm_;     ///< per term: evaluates from x alone and has free entries here
  bool anyKeptTerm_ = false;
  bool keepEvaluations_ = true;
  bool keptValid_ = false;         ///< residual_ and keptJacobian_ hold the kept terms at keptX_
  Eigen::VectorXd keptJacobian_;   ///< the kept terms' Jacobians (jacobian_'s layout)
  Eigen::VectorXd keptX_;
  int reusedTerms_ = 0;
  int numVariablesForKeeping_ = 0;  ///< size of x (keptX_'s when keeping)
  int assemblyThreads_ = 1;
  int splitTerm_ = 0;                ///< the second thread accumulates terms [splitTerm_, end)
  double assemblyWaitMs_ = 0.0;      ///< see assemblyWaitMs()
  std::vector<double> workerMatrix_, workerRhs_, workerRow_;  ///< the second thread's copies
  std::vector<double> jn_, localResidual_, v_, pr_, jstack_, ystack_, blockMatrix_, blockRhs_,
      work_;
};

}  // namespace devsurf::engine
