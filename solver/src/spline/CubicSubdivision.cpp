#include "devsurf/spline/CubicSubdivision.h"

#include <cassert>
#include <stdexcept>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <unsupported/Eigen/KroneckerProduct>

namespace devsurf::spline {

int cubicSubdividedCount(int count, int rounds) {
  if (count < 4) throw std::invalid_argument("cubic subdivision: needs at least 4 control points, got " + std::to_string(count));
  if (rounds < 0) throw std::invalid_argument("cubic subdivision: rounds must be ≥ 0, got " + std::to_string(rounds));
  long long n = count;
  for (int k = 0; k < rounds; ++k) {
    n = 2 * n - 3;
    if (n > (1LL << 30)) throw std::invalid_argument("cubic subdivision: " + std::to_string(rounds) + " rounds of " +
                                                     std::to_string(count) + " points are too many");
  }
  return static_cast<int>(n);
}

Eigen::SparseMatrix<double> cubicSubdivisionMatrix(int count) {
  const int spans = cubicSubdividedCount(count, 0) - 3;
  // Knot insertion (Boehm) on the identity: row i of `rows` holds the coefficients of control
  // point i in terms of the original ones. Knots of the clamped uniform cubic on [0, spans].
  std::vector<double> knots(4, 0.0);
  for (int s = 1; s < spans; ++s) knots.push_back(s);
  knots.insert(knots.end(), 4, static_cast<double>(spans));
  Eigen::MatrixXd rows = Eigen::MatrixXd::Identity(count, count);
  for (int s = 0; s < spans; ++s) {
    const double u = s + 0.5;
    int k = 3;  // span index: knots[k] ≤ u < knots[k + 1]
    while (!(knots[k] <= u && u < knots[k + 1])) ++k;
    const Eigen::Index n = rows.rows();
    Eigen::MatrixXd inserted(n + 1, count);
    for (Eigen::Index i = 0; i <= n; ++i) {
      if (i <= k - 3) {
        inserted.row(i) = rows.row(i);
      } else if (i >= k + 1) {
        inserted.row(i) = rows.row(i - 1);
      } else {
        const double a = (u - knots[i]) / (knots[i + 3] - knots[i]);
        inserted.row(i) = (1.0 - a) * rows.row(i - 1) + a * rows.row(i);
      }
    }
    rows = std::move(inserted);
    knots.insert(knots.begin() + k + 1, u);
  }
  assert(rows.rows() == 2 * count - 3 && "one new point per span");
  Eigen::SparseMatrix<double> alpha = rows.sparseView(1.0, 1e-14);
  alpha.makeCompressed();
  return alpha;
}

Eigen::SparseMatrix<double> cubicGridSubdivisionMatrix(int rows, int columns, int rounds) {
  cubicSubdividedCount(rows, rounds);  // validates
  cubicSubdividedCount(columns, rounds);
  Eigen::SparseMatrix<double> total(rows * columns, rows * columns);
  total.setIdentity();
  int r = rows, c = columns;
  for (int k = 0; k < rounds; ++k) {
    // Index r·columns + c: the row operator acts within a row (along c), the column operator
    // across rows (along r); A_rows ⊗ A_columns does both.
    const Eigen::SparseMatrix<double> round =
        Eigen::kroneckerProduct(cubicSubdivisionMatrix(r), cubicSubdivisionMatrix(c)).eval();
    total = (round * total).pruned();
    r = 2 * r - 3;
    c = 2 * c - 3;
  }
  total.makeCompressed();
  return total;
}

}  // namespace devsurf::spline
