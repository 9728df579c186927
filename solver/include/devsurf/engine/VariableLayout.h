#pragma once

#include <string>
#include <vector>

namespace devsurf::engine {

/// A named, contiguous range of the variable vector x.
struct VariableBlock {
  std::string name;  ///< e.g. "curve a", "normals"
  int offset = 0;    ///< first index in x
  int size = 0;      ///< number of scalars
  /// Multiplies the Tikhonov weight ε_reg² of this block's scalars. Auxiliary variables that the
  /// geometry determines (normals) use a small scale so a step prefers rotating them over moving
  /// the geometry; see docs/architecture.md "Regularization of auxiliary variables".
  double regularizationScale = 1.0;
  static constexpr int kAutoElimination = -1;
  /// Schur elimination of this block's scalars before factorization (see NormalEquations):
  /// kAutoElimination (default) lets the assembler decide, 0 never eliminates, g > 0 eliminates
  /// every consecutive group of g scalars (see VariableLayout::setEliminable).
  int eliminationGroupSize = kAutoElimination;
  /// Solved apart from the other blocks, in turns (VariableLayout::setAlternating).
  bool alternating = false;
};

/// Which free scalars a linear system solves for: all of them, or one side of the alternation
/// (VariableLayout::setAlternating).
enum class VariablePart {
  All,          ///< every free scalar (one system, the plain method)
  Main,         ///< the free scalars of blocks that do not alternate
  Alternating,  ///< the free scalars of alternating blocks
};

/// All unknowns of a problem as named blocks in one vector x (Ceres parameter blocks).
///
/// Any scalar may be held fixed — a whole block or a range inside it (a single control point).
/// Fixed scalars leave the linear system: `freeIndex()` maps every scalar of x to its column in
/// the reduced system, or −1 when fixed.
class VariableLayout {
 public:
  /// Appends a block of `size` scalars; returns its id. Names must be unique.
  /// @throws std::invalid_argument on a duplicate name or negative size.
  int addBlock(const std::string& name, int size);

  int numBlocks() const { return static_cast<int>(blocks_.size()); }
  const VariableBlock& block(int id) const { return blocks_.at(id); }
  /// @throws std::out_of_range if there is no block of that name.
  int blockId(const std::string& name) const;
  /// Total number of scalars in x (fixed ones included).
  int numVariables() const { return static_cast<int>(fixed_.size()); }

  /// Sets the block's multiplier of ε_reg² (≥ 0).
  void setRegularizationScale(int block, double scale);

  /// Declares how the assembler may eliminate the block's free scalars from the linear system
  /// before factorization (exact block Gaussian elimination / Schur complement, the
  /// bundle-adjustment trick; the step is back-substituted for them after the solve):
  /// - groupSize > 0: every consecutive group of `groupSize` scalars (0..g−1, g..2g−1, …) is
  ///   eliminated as one dense block. No residual row may couple two different groups of
  ///   eliminated scalars (of this or any other block); the solver's constructor throws
  ///   std::logic_error if one does. Use it for auxiliary per-element variables (normals, …).
  /// - groupSize = 0: never eliminate this block's scalars.
  /// - VariableBlock::kAutoElimination (the default): the assembler eliminates small groups of
  ///   scalars that appear in exactly the same rows when that creates no fill-in.
  /// @throws std::invalid_argument if groupSize < −1 or does not divide the block size.
  void setEliminable(int block, int groupSize);

  /// Marks a block as solved apart (block Gauss–Seidel): each guided-projection iteration takes
  /// its step on the other blocks with this one held, then a step on the alternating blocks with
  /// the others held, each in its own, smaller linear system (GuidedProjectionSolver). For a
  /// composite's development (issue 17), whose 2D vertices are coupled to the surface only by the
  /// isometry rows: factorizing the two systems apart costs a fraction of the one coupled system.
  void setAlternating(int block, bool alternating = true);
  /// True if some block alternates and has a free scalar.
  bool hasAlternation() const;

  /// Holds the scalars [first, first+count) of `block` fixed (or frees them).
  void setFixed(int block, int first, int count, bool fixed = true);
  /// Holds a whole block fixed (or frees it).
  void setBlockFixed(int block, bool fixed = true);
  bool isFixed(int variable) const { return fixed_[variable] != 0; }

  /// Column of every scalar in the reduced system, −1 for fixed ones (and, for a part, for the
  /// scalars of the other part).
  std::vector<int> freeIndex(VariablePart part = VariablePart::All) const;
  int numFree(VariablePart part = VariablePart::All) const;

 private:
  std::vector<VariableBlock> blocks_;
  /// Whether the free scalar `variable` belongs to `part`.
  bool inPart(int variable, VariablePart part) const;

  std::vector<char> fixed_;
  std::vector<int> blockOf_;  ///< variable → block id
};

}  // namespace devsurf::engine
