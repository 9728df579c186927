#include "devsurf/engine/NormalEquations.h"

#include <algorithm>
#include <cassert>
#include <stdexcept>
#include <string>

#include <Eigen/OrderingMethods>

namespace devsurf::engine {

NormalEquations::NormalEquations(const Problem& problem) {
  const VariableLayout& layout = problem.layout();
  const int numVariables = layout.numVariables();
  const std::vector<int> natural = layout.freeIndex();  // variable → natural free column
  numFree_ = layout.numFree();

  // 1. Per term: entries grouped by row, free entries only, with natural columns.
  plans_.resize(problem.numTerms());
  residualBuffers_.resize(problem.numTerms());
  jacobianBuffers_.resize(problem.numTerms());
  std::vector<JacobianEntry> entries;
  std::vector<int> marker(numVariables, -1);
  for (int t = 0; t < problem.numTerms(); ++t) {
    const Term& term = *problem.term(t).term;
    TermPlan& plan = plans_[t];
    entries.clear();
    term.jacobianStructure(entries);
    plan.numResiduals = term.numResiduals();
    plan.numEntries = static_cast<int>(entries.size());
    residualBuffers_[t].setZero(plan.numResiduals);
    jacobianBuffers_[t].setZero(plan.numEntries);

    std::vector<int> count(plan.numResiduals + 1, 0);
    for (const JacobianEntry& e : entries) {
      if (e.row < 0 || e.row >= plan.numResiduals || e.variable < 0 || e.variable >= numVariables)
        throw std::logic_error("term '" + term.name() + "': Jacobian entry out of range");
      if (natural[e.variable] >= 0) ++count[e.row + 1];
    }
    for (int r = 0; r < plan.numResiduals; ++r) count[r + 1] += count[r];
    plan.rowStart = count;
    plan.order.assign(count.back(), -1);
    plan.column.assign(entries.size(), -1);
    std::vector<int> fill(count.begin(), count.end() - 1);
    for (int e = 0; e < plan.numEntries; ++e) {
      const int c = natural[entries[e].variable];
      plan.column[e] = c;
      if (c >= 0) plan.order[fill[entries[e].row]++] = e;
    }
    // A row must not list a variable twice (the scatter map assumes distinct columns per row).
    for (int r = 0; r < plan.numResiduals; ++r) {
      for (int k = plan.rowStart[r]; k < plan.rowStart[r + 1]; ++k) {
        const int v = entries[plan.order[k]].variable;
        if (marker[v] == r + t * 0x100000) {
          throw std::logic_error("term '" + term.name() + "': row " + std::to_string(r) +
                                 " lists variable " + std::to_string(v) + " twice");
        }
        marker[v] = r + t * 0x100000;
      }
      for (int k = plan.rowStart[r]; k < plan.rowStart[r + 1]; ++k)
        marker[entries[plan.order[k]].variable] = -1;
    }
  }

  // 2. Symbolic pattern of JᵀJ + I (upper triangle, natural columns): column j lists the rows
  //    i ≤ j coupled through some residual row. Built with per-column neighbour lists.
  std::vector<std::vector<int>> neighbours(numFree_);
  for (int c = 0; c < numFree_; ++c) neighbours[c].push_back(c);
  for (const TermPlan& plan : plans_) {
    for (int r = 0; r < plan.numResiduals; ++r) {
      for (int ka = plan.rowStart[r]; ka < plan.rowStart[r + 1]; ++ka) {
        const int ca = plan.column[plan.order[ka]];
        for (int kb = ka + 1; kb < plan.rowStart[r + 1]; ++kb) {
          const int cb = plan.column[plan.order[kb]];
          neighbours[std::max(ca, cb)].push_back(std::min(ca, cb));
        }
      }
    }
  }
  long nnz = 0;
  for (std::vector<int>& list : neighbours) {
    std::sort(list.begin(), list.end());
    list.erase(std::unique(list.begin(), list.end()), list.end());
    list.shrink_to_fit();
    nnz += static_cast<long>(list.size());
  }

  // 3. Fill-reducing ordering (AMD) on the symmetric pattern, computed once.
  SymmetricUpper pattern(numFree_, numFree_);
  {
    std::vector<Eigen::Triplet<double, int>> triplets;
    triplets.reserve(static_cast<std::size_t>(nnz));
    for (int j = 0; j < numFree_; ++j)
      for (int i : neighbours[j]) triplets.emplace_back(i, j, 1.0);
    pattern.setFromTriplets(triplets.begin(), triplets.end());
  }
  Eigen::PermutationMatrix<Eigen::Dynamic, Eigen::Dynamic, int> newToOld;
  if (numFree_ > 0) {
    Eigen::AMDOrdering<int> amd;
    SymmetricUpper full = pattern.selfadjointView<Eigen::Upper>();
    amd(full, newToOld);
  }
  std::vector<int> oldToNew(numFree_);
  for (int k = 0; k < numFree_; ++k) oldToNew[newToOld.indices()[k]] = k;

  // 4. The permuted upper-triangular pattern of H with sorted row indices per column.
  std::vector<std::vector<int>> permuted(numFree_);
  for (int j = 0; j < numFree_; ++j) {
    for (int i : neighbours[j]) {
      const int pi = oldToNew[i], pj = oldToNew[j];
      permuted[std::max(pi, pj)].push_back(std::min(pi, pj));
    }
    std::vector<int>().swap(neighbours[j]);
  }
  H_.resize(numFree_, numFree_);
  {
    Eigen::VectorXi sizes(numFree_);
    for (int j = 0; j < numFree_; ++j) {
      std::sort(permuted[j].begin(), permuted[j].end());
      sizes[j] = static_cast<int>(permuted[j].size());
    }
    H_.reserve(sizes);
    for (int j = 0; j < numFree_; ++j)
      for (int i : permuted[j]) H_.insert(i, j) = 0.0;
    H_.makeCompressed();
  }
  auto slotOf = [this](int i, int j) {
    // (i, j) in the permuted upper triangle, i ≤ j: binary search in column j.
    const int* begin = H_.innerIndexPtr() + H_.outerIndexPtr()[j];
    const int* end = H_.innerIndexPtr() + H_.outerIndexPtr()[j + 1];
    const int* it = std::lower_bound(begin, end, i);
    assert(it != end && *it == i && "pair missing from the symbolic pattern");
    return static_cast<int>(it - H_.innerIndexPtr());
  };
  diagonalSlot_.resize(numFree_);
  for (int c = 0; c < numFree_; ++c) diagonalSlot_[c] = slotOf(c, c);

  // 5. Scatter map: every pair (a ≤ b) of free entries in a row gets its slot in H.
  for (TermPlan& plan : plans_) {
    for (int& c : plan.column)
      if (c >= 0) c = oldToNew[c];
    long pairs = 0;
    for (int r = 0; r < plan.numResiduals; ++r) {
      const long e = plan.rowStart[r + 1] - plan.rowStart[r];
      pairs += e * (e + 1) / 2;
    }
    plan.pairSlot.resize(static_cast<std::size_t>(pairs));
    long s = 0;
    for (int r = 0; r < plan.numResiduals; ++r) {
      for (int ka = plan.rowStart[r]; ka < plan.rowStart[r + 1]; ++ka) {
        const int ca = plan.column[plan.order[ka]];
        for (int kb = ka; kb < plan.rowStart[r + 1]; ++kb) {
          const int cb = plan.column[plan.order[kb]];
          plan.pairSlot[s++] = slotOf(std::min(ca, cb), std::max(ca, cb));
        }
      }
    }
  }

  freeIndex_.assign(numVariables, -1);
  regularizationScale_.assign(numFree_, 1.0);
  for (int b = 0; b < layout.numBlocks(); ++b) {
    const VariableBlock& block = layout.block(b);
    for (int v = block.offset; v < block.offset + block.size; ++v) {
      if (natural[v] < 0) continue;
      freeIndex_[v] = oldToNew[natural[v]];
      regularizationScale_[freeIndex_[v]] = block.regularizationScale;
    }
  }
  rhs_.setZero(numFree_);
}

void NormalEquations::assemble(Problem& problem, const std::vector<double>& termWeights,
                               double regularization, std::vector<double>& termResiduals) {
  assert(static_cast<int>(termWeights.size()) == problem.numTerms() && "one weight per term");
  double* H = H_.valuePtr();
  std::fill(H, H + H_.nonZeros(), 0.0);
  rhs_.setZero();
  termResiduals.assign(problem.numTerms(), 0.0);
  const Eigen::VectorXd& x = problem.x();

  for (int t = 0; t < problem.numTerms(); ++t) {
    Term& term = *problem.term(t).term;
    TermPlan& plan = plans_[t];
    double* r = residualBuffers_[t].data();
    double* J = jacobianBuffers_[t].data();
    term.linearizeAt(x);
    term.evaluate(x, r, J);
    const double w2 = termWeights[t] * termWeights[t];
    double energy = 0.0;
    const int* slot = plan.pairSlot.data();
    const int* order = plan.order.data();
    const int* column = plan.column.data();
    for (int row = 0; row < plan.numResiduals; ++row) {
      const double ri = r[row];
      energy += ri * ri;
      const int begin = plan.rowStart[row], end = plan.rowStart[row + 1];
      for (int ka = begin; ka < end; ++ka) {
        const int a = order[ka];
        const double wja = w2 * J[a];
        rhs_[column[a]] -= wja * ri;
        for (int kb = ka; kb < end; ++kb) H[*slot++] += wja * J[order[kb]];
      }
    }
    termResiduals[t] = w2 * energy;
  }
  const double eps2 = regularization * regularization;
  for (int c = 0; c < numFree_; ++c) H[diagonalSlot_[c]] += eps2 * regularizationScale_[c];
}

void NormalEquations::residuals(const Problem& problem, const Eigen::VectorXd& x,
                                const std::vector<double>& termWeights,
                                std::vector<double>& termResiduals) {
  termResiduals.assign(problem.numTerms(), 0.0);
  for (int t = 0; t < problem.numTerms(); ++t) {
    double* r = residualBuffers_[t].data();
    problem.term(t).term->evaluate(x, r, nullptr);
    const double w2 = termWeights[t] * termWeights[t];
    termResiduals[t] = w2 * residualBuffers_[t].squaredNorm();
  }
}

void NormalEquations::applyStep(const Eigen::VectorXd& delta, Eigen::VectorXd& x) const {
  for (std::size_t v = 0; v < freeIndex_.size(); ++v)
    if (freeIndex_[v] >= 0) x[static_cast<Eigen::Index>(v)] += delta[freeIndex_[v]];
}

}  // namespace devsurf::engine
