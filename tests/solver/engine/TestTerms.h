#pragma once

// Small terms used only by the engine tests.

#include <cmath>
#include <utility>
#include <memory>
#include <vector>

#include <Eigen/Core>

#include "devsurf/engine/Problem.h"
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

/// Rows r_i = ⟨Σ_j W_i(·, j) x_{p_ij}, n_i⟩ − c_i: a 3-vector depending linearly on some scalars,
/// dotted with a free 3-vector n_i = x[normal_i .. normal_i + 2] (the shape of the strip's
/// developability rows ⟨b − a, n⟩).
class DotTerm final : public Term {
 public:
  struct Row {
    std::vector<int> scalars;  ///< p_i: indices in x
    Eigen::Matrix3Xd weights;  ///< W_i: 3 × scalars.size()
    int normal = 0;            ///< index of n_i's first scalar
    double target = 0.0;       ///< c_i
  };
  DotTerm(std::string name, std::vector<Row> rows) : Term(std::move(name)), rows_(std::move(rows)) {}
  int numResiduals() const override { return static_cast<int>(rows_.size()); }
  void jacobianStructure(std::vector<JacobianEntry>& e) const override {
    for (int i = 0; i < numResiduals(); ++i) {
      for (int p : rows_[i].scalars) e.push_back({i, p});
      for (int c = 0; c < 3; ++c) e.push_back({i, rows_[i].normal + c});
    }
  }
  void evaluate(const Eigen::VectorXd& x, double* r, double* J) const override {
    for (const Row& row : rows_) {
      Eigen::Vector3d v = Eigen::Vector3d::Zero();
      for (std::size_t j = 0; j < row.scalars.size(); ++j) v += row.weights.col(j) * x[row.scalars[j]];
      const Eigen::Vector3d n = x.segment<3>(row.normal);
      *r++ = v.dot(n) - row.target;
      if (!J) continue;
      for (std::size_t j = 0; j < row.scalars.size(); ++j) *J++ = row.weights.col(j).dot(n);
      for (int c = 0; c < 3; ++c) *J++ = v[c];
    }
  }

 private:
  std::vector<Row> rows_;
};

/// r_i = |x[o_i .. o_i + 2]|² − 1 (unit length of a 3-vector).
class SquaredNormTerm final : public Term {
 public:
  SquaredNormTerm(std::string name, std::vector<int> offsets)
      : Term(std::move(name)), offsets_(std::move(offsets)) {}
  int numResiduals() const override { return static_cast<int>(offsets_.size()); }
  void jacobianStructure(std::vector<JacobianEntry>& e) const override {
    for (int i = 0; i < numResiduals(); ++i)
      for (int c = 0; c < 3; ++c) e.push_back({i, offsets_[i] + c});
  }
  void evaluate(const Eigen::VectorXd& x, double* r, double* J) const override {
    for (int o : offsets_) {
      const Eigen::Vector3d n = x.segment<3>(o);
      *r++ = n.squaredNorm() - 1.0;
      if (J)
        for (int c = 0; c < 3; ++c) *J++ = 2.0 * n[c];
    }
  }

 private:
  std::vector<int> offsets_;
};

/// Sparse linear rows r_i = Σ_k a_ik x_{j_ik} − b_i.
class SparseLinearTerm final : public Term {
 public:
  struct Row {
    std::vector<std::pair<int, double>> coefficients;  ///< (index in x, a_ik)
    double target = 0.0;
  };
  SparseLinearTerm(std::string name, std::vector<Row> rows)
      : Term(std::move(name)), rows_(std::move(rows)) {}
  int numResiduals() const override { return static_cast<int>(rows_.size()); }
  void jacobianStructure(std::vector<JacobianEntry>& e) const override {
    for (int i = 0; i < numResiduals(); ++i)
      for (const auto& [j, a] : rows_[i].coefficients) e.push_back({i, j});
  }
  void evaluate(const Eigen::VectorXd& x, double* r, double* J) const override {
    for (const Row& row : rows_) {
      double s = -row.target;
      for (const auto& [j, a] : row.coefficients) {
        s += a * x[j];
        if (J) *J++ = a;
      }
      *r++ = s;
    }
  }

 private:
  std::vector<Row> rows_;
};

/// SparseLinearTerm that counts its evaluations (with and without a Jacobian) and linearizations.
class CountingTerm final : public Term {
 public:
  CountingTerm(std::string name, std::vector<SparseLinearTerm::Row> rows)
      : Term(name), rows_(std::move(name), std::move(rows)) {}
  int numResiduals() const override { return rows_.numResiduals(); }
  void jacobianStructure(std::vector<JacobianEntry>& e) const override { rows_.jacobianStructure(e); }
  void linearizeAt(const Eigen::VectorXd&) override { ++linearizations; }
  void evaluate(const Eigen::VectorXd& x, double* r, double* J) const override {
    ++evaluations;
    rows_.evaluate(x, r, J);
  }
  mutable int evaluations = 0;
  int linearizations = 0;

 private:
  SparseLinearTerm rows_;
};

/// Another term, forwarded, declared to evaluate from x alone (or not), with its evaluations
/// counted: with a Jacobian and residual-only.
class ForwardingTerm final : public Term {
 public:
  ForwardingTerm(std::unique_ptr<Term> inner, bool fromXAlone)
      : Term(inner->name()), inner_(std::move(inner)), fromXAlone_(fromXAlone) {}
  int numResiduals() const override { return inner_->numResiduals(); }
  void jacobianStructure(std::vector<JacobianEntry>& e) const override { inner_->jacobianStructure(e); }
  void linearizeAt(const Eigen::VectorXd& x) override { inner_->linearizeAt(x); }
  bool evaluatesFromXAlone() const override { return fromXAlone_; }
  void evaluate(const Eigen::VectorXd& x, double* r, double* J) const override {
    ++(J ? withJacobian : residualOnly);
    inner_->evaluate(x, r, J);
  }
  mutable int withJacobian = 0, residualOnly = 0;

 private:
  std::unique_ptr<Term> inner_;
  bool fromXAlone_;
};

/// Wraps every term of the problem in a ForwardingTerm; `fromXAlone(t)` says what term t declares.
template <class Predicate>
std::vector<ForwardingTerm*> forwardTerms(Problem& problem, Predicate fromXAlone) {
  std::vector<ForwardingTerm*> out;
  for (int t = 0; t < problem.numTerms(); ++t) {
    auto wrapper = std::make_unique<ForwardingTerm>(std::move(problem.term(t).term), fromXAlone(t));
    out.push_back(wrapper.get());
    problem.term(t).term = std::move(wrapper);
  }
  return out;
}

/// A point (x_i, x_{i+1}) held on the horizontal line y = c as a tangent-distance row is: the
/// foot point is a constant of the iteration, taken in linearizeAt(); r = (p − foot) · (0, 1).
/// Before any linearizeAt() the foot is (0, 0), as a new terms::TangentDistanceTerm's is.
class LineFootTerm final : public Term {
 public:
  LineFootTerm(std::string name, int i, double c) : Term(std::move(name)), i_(i), c_(c) {}
  int numResiduals() const override { return 1; }
  void jacobianStructure(std::vector<JacobianEntry>& e) const override { e.push_back({0, i_ + 1}); }
  void linearizeAt(const Eigen::VectorXd& x) override { foot_ = Eigen::Vector2d(x[i_], c_); }
  void evaluate(const Eigen::VectorXd& x, double* r, double* J) const override {
    r[0] = x[i_ + 1] - foot_.y();
    if (J) J[0] = 1.0;
  }

 private:
  int i_;
  double c_;
  Eigen::Vector2d foot_ = Eigen::Vector2d::Zero();
};

}  // namespace devsurf::engine::testing
