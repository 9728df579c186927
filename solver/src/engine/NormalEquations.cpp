// NormalEquations: assembly of JᵀW²J and JᵀW²r (the terms evaluated, their rows accumulated),
// and residual-only evaluations. The analysis is in NormalEquationsAnalysis.cpp, the groups'
// elimination and the back-substitution in NormalEquationsElimination.cpp.
#include "devsurf/engine/NormalEquations.h"
#include "devsurf/engine/VectorClones.h"

#include <chrono>
#include <algorithm>
#include <cassert>
#include <cmath>
#include <cstring>
#include <system_error>
#include <thread>

namespace devsurf::engine {

void NormalEquations::setKeepEvaluations(bool keep) {
  keptValid_ = false;
  keepEvaluations_ = keep && anyKeptTerm_;
  if (!keepEvaluations_) {  // the buffers go with the switch (the alternating side never keeps)
    keptJacobian_.resize(0);
    keptX_.resize(0);
  } else if (keptJacobian_.size() != jacobian_.size()) {
    keptJacobian_.setZero(jacobian_.size());
    keptX_.setZero(numVariablesForKeeping_);
  }
}

void NormalEquations::setAssemblyThreads(int threads, long minProducts) {
  const int wanted = threads >= 2 && directProducts_ >= minProducts && plans_.size() >= 2 ? 2 : 1;
  if (wanted == assemblyThreads_) return;
  assemblyThreads_ = wanted;
  if (wanted == 1) return;
  // Split the terms into two runs of about equal products (deterministic: the partition depends
  // on the pattern only), and size the second thread's copies once.
  long seen = 0;
  splitTerm_ = static_cast<int>(plans_.size());
  for (std::size_t t = 0; t < plans_.size(); ++t) {
    seen += plans_[t].directProducts;
    if (2 * seen >= directProducts_) {
      splitTerm_ = static_cast<int>(t) + 1;
      break;
    }
  }
  workerMatrix_.assign(static_cast<std::size_t>(S_.nonZeros()), 0.0);
  workerRhs_.assign(static_cast<std::size_t>(rhs_.size()), 0.0);
  workerRow_.assign(rowValues_.size(), 0.0);
}

DEVSURF_VECTOR_CLONES
void NormalEquations::accumulateDirectRows(int firstTerm, int endTerm, double* H, double* rhs, double* jr) const {
  double* dense = jr + longestDirectRow_;  // n×n, row-major upper triangle used
  for (int t = firstTerm; t < endTerm; ++t) {
    const TermPlan& plan = plans_[t];
    const double* r = residual_.data() + termResidualOffset_[t];
    const double* J = jacobian_.data() + termJacobianOffset_[t];
    const double w2 = weights_[t] * weights_[t];
    const int* slot = plan.pairSlot.data();
    const int* entry = plan.directEntry.data();
    const int* column = plan.directColumn.data();
    const int numDirect = static_cast<int>(plan.directRow.size());
    for (int i = 0; i < numDirect;) {
      const int run = plan.directRun[static_cast<std::size_t>(i)];
      const int n = plan.directStart[i + 1] - plan.directStart[i];
      const int pairs = n * (n + 1) / 2;
      if (run == 1) {
        const double ri = r[plan.directRow[i]];
        const int begin = plan.directStart[i];
        bool zero = true;
        for (int k = 0; k < n; ++k) {
          jr[k] = J[entry[begin + k]];  // the row's values, contiguous
          zero = zero && jr[k] == 0.0;
        }
        ++i;
        if (zero) {  // an inactive row (a hinge guard at rest): nothing to add
          slot += pairs;
          continue;
        }
        for (int a = 0; a < n; ++a) {
          const double wja = w2 * jr[a];
          rhs[column[begin + a]] -= wja * ri;
          for (int b = a; b < n; ++b) H[*slot++] += wja * jr[b];
        }
        continue;
      }
      // A run of rows with the same columns: Σ w² j jᵀ densely, then one scatter.
      bool any = false;
      for (int row = i; row < i + run; ++row) {
        const double ri = r[plan.directRow[row]];
        const int begin = plan.directStart[row];
        bool zero = true;
        for (int k = 0; k < n; ++k) {
          jr[k] = J[entry[begin + k]];
          zero = zero && jr[k] == 0.0;
        }
        if (zero) continue;
        if (!any) std::fill(dense, dense + static_cast<std::ptrdiff_t>(n) * n, 0.0);
        any = true;
        for (int a = 0; a < n; ++a) {
          const double wja = w2 * jr[a];
          rhs[column[begin + a]] -= wja * ri;
          double* d = dense + static_cast<std::ptrdiff_t>(a) * n;
          for (int b = a; b < n; ++b) d[b] += wja * jr[b];
        }
      }
      i += run;
      if (!any) {
        slot += pairs;
        continue;
      }
      for (int a = 0; a < n; ++a) {
        const double* d = dense + static_cast<std::ptrdiff_t>(a) * n;
        for (int b = a; b < n; ++b) H[*slot++] += d[b];
      }
    }
  }
}

void NormalEquations::assemble(Problem& problem, const std::vector<double>& termWeights,
                               double regularization, std::vector<double>& termResiduals,
                               double relaxableLimit) {
  assert(static_cast<int>(termWeights.size()) == problem.numTerms() && "one weight per term");
  double* H = S_.valuePtr();
  std::fill(H, H + S_.nonZeros(), 0.0);
  rhs_.setZero();
  termResiduals.assign(problem.numTerms(), 0.0);
  std::copy(termWeights.begin(), termWeights.end(), weights_.begin());
  eps2_ = regularization * regularization;
  const Eigen::VectorXd& x = problem.x();
  double* rhs = rhs_.data();

  // The terms that evaluate from x alone were evaluated, Jacobian included, by the last
  // residuals() call if it was at this x: their residuals are in residual_ and their Jacobians in
  // keptJacobian_, which becomes jacobian_ (the other terms are evaluated into it below).
  const bool reuse = keptValid_ && keptX_.size() == x.size() &&
                     std::memcmp(x.data(), keptX_.data(), sizeof(double) * static_cast<std::size_t>(x.size())) == 0;
  keptValid_ = false;
  reusedTerms_ = 0;
  if (reuse) jacobian_.swap(keptJacobian_);

  // Every term evaluated (one thread: terms may share state, a foot-point set say), then the
  // products of the rows accumulated, in two runs of terms when a second thread is worth it.
  for (int t = 0; t < problem.numTerms(); ++t) {
    Term& term = *problem.term(t).term;
    const TermPlan& plan = plans_[t];
    if (part_ != VariablePart::All && plan.numFreeEntries == 0) continue;  // constant here
    double* r = residual_.data() + termResidualOffset_[t];
    double* J = jacobian_.data() + termJacobianOffset_[t];
    if (reuse && keptTerm_[static_cast<std::size_t>(t)]) {
      ++reusedTerms_;  // residuals and Jacobian at x already in place (linearizeAt is a no-op)
    } else {
      term.linearizeAt(x);
      term.evaluate(x, r, J);
    }
    const double w2 = termWeights[t] * termWeights[t];
    double energy = 0.0;
    for (int row = 0; row < plan.numResiduals; ++row) energy += r[row] * r[row];
    if (problem.term(t).relaxable && energy > relaxableLimit * relaxableLimit) {
      const double shorten = relaxableLimit / std::sqrt(energy);
      for (int row = 0; row < plan.numResiduals; ++row) r[row] *= shorten;
      energy = relaxableLimit * relaxableLimit;
    }
    termResiduals[t] = w2 * energy;
  }
  const int numTerms = problem.numTerms();
  if (assemblyThreads_ > 1 && splitTerm_ < numTerms) {
    std::fill(workerMatrix_.begin(), workerMatrix_.end(), 0.0);
    std::fill(workerRhs_.begin(), workerRhs_.end(), 0.0);
    std::thread second;
    try {
      second = std::thread([this, numTerms]() {
        accumulateDirectRows(splitTerm_, numTerms, workerMatrix_.data(), workerRhs_.data(), workerRow_.data());
      });
    } catch (const std::system_error&) {
      // No thread to be had (a process at its limit): the same runs, one after the other.
      accumulateDirectRows(splitTerm_, numTerms, workerMatrix_.data(), workerRhs_.data(), workerRow_.data());
    }
    accumulateDirectRows(0, splitTerm_, H, rhs, rowValues_.data());
    if (second.joinable()) {
      const auto waitFrom = std::chrono::steady_clock::now();
      second.join();
      assemblyWaitMs_ += std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - waitFrom).count();
    }
    const Eigen::Index nnz = S_.nonZeros();
    for (Eigen::Index k = 0; k < nnz; ++k) H[k] += workerMatrix_[static_cast<std::size_t>(k)];
    for (Eigen::Index k = 0; k < rhs_.size(); ++k) rhs[k] += workerRhs_[static_cast<std::size_t>(k)];
  } else {
    accumulateDirectRows(0, numTerms, H, rhs, rowValues_.data());
  }
  for (int c = 0; c < numReduced_; ++c) H[diagonalSlot_[c]] += eps2_ * regularizationScale_[c];
}

void NormalEquations::residuals(const Problem& problem, const Eigen::VectorXd& x,
                                const std::vector<double>& termWeights,
                                std::vector<double>& termResiduals, std::vector<double>* termMaxAbs) {
  keptValid_ = false;  // until every term is evaluated (a term may throw)
  termResiduals.assign(problem.numTerms(), 0.0);
  if (termMaxAbs) termMaxAbs->assign(problem.numTerms(), 0.0);
  const bool keep = keepEvaluations_ && anyKeptTerm_ && x.size() == keptX_.size();
  for (int t = 0; t < problem.numTerms(); ++t) {
    double energy = 0.0, largest = 0.0;
    double* keptJacobian = keep && keptTerm_[static_cast<std::size_t>(t)]
                               ? keptJacobian_.data() + termJacobianOffset_[t]
                               : nullptr;
    evaluateResidual(problem, t, x, energy, largest, keptJacobian);
    termResiduals[t] = termWeights[t] * termWeights[t] * energy;
    if (termMaxAbs) (*termMaxAbs)[t] = largest;
  }
  keptValid_ = keep;
  if (keep) keptX_ = x;  // same size: no allocation
}

void NormalEquations::partResiduals(const Problem& problem, const Eigen::VectorXd& x,
                                    const std::vector<double>& termWeights, std::vector<double>& termResiduals,
                                    std::vector<double>& termMaxAbs) {
  assert(termResiduals.size() == static_cast<std::size_t>(problem.numTerms()) &&
         termMaxAbs.size() == termResiduals.size() && "per-term vectors of the solve");
  for (int t = 0; t < problem.numTerms(); ++t) {
    if (!touchesPart(t)) continue;
    double energy = 0.0, largest = 0.0;
    keptValid_ = false;  // residual_ no longer holds one evaluation at one x
    evaluateResidual(problem, t, x, energy, largest);
    termResiduals[static_cast<std::size_t>(t)] = termWeights[t] * termWeights[t] * energy;
    termMaxAbs[static_cast<std::size_t>(t)] = largest;
  }
}

void NormalEquations::evaluateResidual(const Problem& problem, int t, const Eigen::VectorXd& x, double& energy,
                                       double& largest, double* jacobian) {
  double* r = residual_.data() + termResidualOffset_[t];
  problem.term(t).term->evaluate(x, r, jacobian);
  // In locals: through the references every row would store and reload them (they may alias r).
  double sum = 0.0, big = 0.0;
  const int rows = plans_[t].numResiduals;
  for (int row = 0; row < rows; ++row) {
    sum += r[row] * r[row];
    big = std::max(big, std::abs(r[row]));
    if (std::isnan(r[row])) big = r[row];
  }
  energy = sum;
  largest = big;
}

}  // namespace devsurf::engine
