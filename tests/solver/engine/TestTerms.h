#pragma once

// Small terms used only by the engine tests.

#include <cmath>
#include <vector>

#include "devsurf/engine/Term.h"

namespace devsurf::engine::testing {

/// Linear rows r_i = Σ_j A(i, j) x_j − b_i over all variables (dense structure).
class LinearRowsTerm final : public Term {
 public:
  LinearRowsTerm(std::string name, Eigen::MatrixXd A, Eigen::VectorXd b)
      : Term(std::move(name)), A_(std::move(A)), b_(std::move(b)) {}
  int numResiduals() const override { return static_cast<int>(A_.rows()); }
  void jacobianStructure(std::vector<JacobianEntry>& entries) const override {
    for (int i = 0; i < A_.rows(); ++i)
      for (int j = 0; j < A_.cols(); ++j) entries.push_back({i, j});
  }
  void evaluate(const Eigen::VectorXd& x, double* r, double* J) const override {
    const Eigen::VectorXd res = A_ * x - b_;
    for (int i = 0; i < A_.rows(); ++i) {
      r[i] = res[i];
      if (J)
        for (int j = 0; j < A_.cols(); ++j) J[i * A_.cols() + j] = A_(i, j);
    }
  }

 private:
  Eigen::MatrixXd A_;
  Eigen::VectorXd b_;
};

/// r = x_0 · x_1 − c (a quadratic, like every constraint of the papers).
class ProductTerm final : public Term {
 public:
  ProductTerm(std::string name, int i, int j, double c) : Term(std::move(name)), i_(i), j_(j), c_(c) {}
  int numResiduals() const override { return 1; }
  void jacobianStructure(std::vector<JacobianEntry>& e) const override {
    e.push_back({0, i_});
    e.push_back({0, j_});
  }
  void evaluate(const Eigen::VectorXd& x, double* r, double* J) const override {
    r[0] = x[i_] * x[j_] - c_;
    if (J) {
      J[0] = x[j_];
      J[1] = x[i_];
    }
  }

 private:
  int i_, j_;
  double c_;
};

/// Same as ProductTerm but with a deliberately wrong derivative (for the checker's own test).
class WrongProductTerm final : public Term {
 public:
  explicit WrongProductTerm(std::string name) : Term(std::move(name)) {}
  int numResiduals() const override { return 1; }
  void jacobianStructure(std::vector<JacobianEntry>& e) const override { e.push_back({0, 0}); }
  void evaluate(const Eigen::VectorXd& x, double* r, double* J) const override {
    r[0] = x[0] * x[1];
    if (J) J[0] = 2.0 * x[1];  // wrong, and ∂/∂x_1 is missing from the structure
  }
};

/// r = sqrt(x_0) - 1: produces NaN for negative x_0 (divergence handling).
class SqrtTerm final : public Term {
 public:
  explicit SqrtTerm(std::string name) : Term(std::move(name)) {}
  int numResiduals() const override { return 1; }
  void jacobianStructure(std::vector<JacobianEntry>& e) const override { e.push_back({0, 0}); }
  void evaluate(const Eigen::VectorXd& x, double* r, double* J) const override {
    r[0] = std::sqrt(x[0]) - 1.0;
    if (J) J[0] = 0.5 / std::sqrt(x[0]);
  }
};

}  // namespace devsurf::engine::testing
