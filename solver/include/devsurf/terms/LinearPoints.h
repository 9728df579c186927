#pragma once

#include <vector>

#include <Eigen/Core>

#include "devsurf/engine/Term.h"
#include "devsurf/spline/Basis.h"

namespace devsurf::terms {

/// Points (or vectors) that depend linearly on a block of 3D control points in x:
/// p_k = Σ_j W(k, j) · x[offset + 3j .. offset + 3j + 2].
///
/// With W = N^{(l)} (an evaluation matrix) this is the l-th derivative of a spline curve at the
/// k-th parameter; with W = I it is the k-th of a list of free vectors (normals per parameter).
struct LinearPoints {
  spline::EvaluationMatrix weights;  ///< rows = points, columns = control points
  int offset = 0;                    ///< index in x of control point 0, coordinate x

  /// Free vectors: W = I (count×count).
  static LinearPoints identity(int count, int offset);
  int rows() const { return static_cast<int>(weights.rows()); }
  Eigen::Vector3d point(const Eigen::VectorXd& x, int k) const {
    // Inline: every term evaluates its points through here, several per residual row.
    Eigen::Vector3d p = Eigen::Vector3d::Zero();
    for (spline::EvaluationMatrix::InnerIterator it(weights, k); it; ++it)
      p += it.value() * x.segment<3>(offset + 3 * static_cast<int>(it.col()));
    return p;
  }
  /// Appends one Jacobian entry per (nonzero control point j of point k, coordinate c) to
  /// residual row `row`, in the order writeJacobian() uses.
  void appendStructure(int k, int row, std::vector<engine::JacobianEntry>& out) const;
  /// Writes ∂⟨p_k, v⟩/∂x for all entries appendStructure(k, …) declared: scale · W(k,j) · v_c.
  /// Returns the pointer past the last value written.
  double* writeJacobian(int k, const Eigen::Vector3d& v, double scale, double* out) const {
    for (spline::EvaluationMatrix::InnerIterator it(weights, k); it; ++it) {
      const double w = scale * it.value();
      *out++ = w * v[0];
      *out++ = w * v[1];
      *out++ = w * v[2];
    }
    return out;
  }
};

/// Row scale 1/|v| of 003_… §5.2.1, or 1 where |v| vanishes (a cone's apex curve has b′ ≡ 0 and
/// its row is identically zero).
inline double inverseLengthOrOne(const Eigen::Vector3d& v) {
  const double n = v.norm();
  return n > 1e-12 ? 1.0 / n : 1.0;
}

/// True if a term's Jacobian structure lists some (row, variable) twice (the assembler forbids
/// it; happens when two point sets of one row share control points).
bool hasDuplicateEntries(const engine::Term& term);

}  // namespace devsurf::terms
