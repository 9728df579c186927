// NormalEquations: the block elimination of the groups (Schur complement into S), the
// correction right-hand side through it, and the back-substitution of a step.
#include "devsurf/engine/NormalEquations.h"
#include "devsurf/engine/VectorClones.h"

#include <algorithm>
#include <cassert>
#include <cmath>

#include "EliminationChunks.h"

namespace devsurf::engine {
using detail::kChunk;
using detail::paddedStride;

namespace {

/// V = J_n L⁻ᵀ (row by row: L vᵀ = J_n[row]ᵀ) and t = Vᵀ w r = L⁻¹ J_nᵀ w r for one elimination
/// group: L m×m row-major lower with inv = 1 / diag L, J_n nr×m row-major, rl = w r (nr); M = m
/// when known at compile time (0: any).
template <int M>
void groupRowsThroughFactor(int mAny, int nr, const double* L, const double* inv, const double* Jn, const double* rl,
                            double* V, double* tn) {
  const int m = M > 0 ? M : mAny;
  for (int a = 0; a < m; ++a) tn[a] = 0.0;
  for (int lr = 0; lr < nr; ++lr) {
    double* v = V + lr * m;
    for (int a = 0; a < m; ++a) {
      double s = Jn[lr * m + a];
      for (int k = 0; k < a; ++k) s -= L[a * m + k] * v[k];
      v[a] = s * inv[a];
      tn[a] += v[a] * rl[lr];
    }
  }
}


/// S[a][b] = Σ_k Jc[k][a] Y[k][b] for a ≤ b (row-major, stride ld, K rows). Two rows of S and
/// one chunk of columns at a time are accumulated in registers; entries left of the diagonal in
/// a chunk are computed too and ignored.
void blockProductUpper(const double* Jc, const double* Y, double* S, int c, int ld, int K) {
  int a = 0;
  for (; a + 1 < c; a += 2) {
    for (int b0 = a / kChunk * kChunk; b0 < c; b0 += kChunk) {
      double acc0[kChunk] = {}, acc1[kChunk] = {};
      for (int k = 0; k < K; ++k) {
        const double v0 = Jc[k * ld + a], v1 = Jc[k * ld + a + 1];
        const double* y = Y + k * ld + b0;
        for (int q = 0; q < kChunk; ++q) {
          acc0[q] += v0 * y[q];
          acc1[q] += v1 * y[q];
        }
      }
      for (int q = 0; q < kChunk; ++q) {
        S[a * ld + b0 + q] = acc0[q];
        S[(a + 1) * ld + b0 + q] = acc1[q];
      }
    }
  }
  if (a < c) {
    for (int b0 = a / kChunk * kChunk; b0 < c; b0 += kChunk) {
      double acc[kChunk] = {};
      for (int k = 0; k < K; ++k) {
        const double v = Jc[k * ld + a];
        const double* y = Y + k * ld + b0;
        for (int q = 0; q < kChunk; ++q) acc[q] += v * y[q];
      }
      for (int q = 0; q < kChunk; ++q) S[a * ld + b0 + q] = acc[q];
    }
  }
}

}  // namespace

DEVSURF_VECTOR_CLONES
void NormalEquations::gatherGroupRows(const EliminationGroup& g, int m, double* Jc) {
  const double* J = jacobian_.data();
  const int* source = groupEntrySource_.data();
  const int* dest = groupEntryDest_.data();
  double* Jn = jn_.data();
  double* rl = localResidual_.data();
  std::fill(Jn, Jn + g.numRows * m, 0.0);
  for (int lr = 0; lr < g.numRows; ++lr) {
    const int row = g.rowOffset + lr;
    const double w = weights_[groupRowTerm_[row]];
    rl[lr] = w * residual_[groupRowResidual_[row]];
    for (int k = groupRowStart_[row]; k < groupRowSplit_[row]; ++k) Jn[dest[k]] = w * J[source[k]];
    for (int k = groupRowSplit_[row]; k < groupRowStart_[row + 1]; ++k) Jc[dest[k]] = w * J[source[k]];
  }
}

template <int M>
DEVSURF_VECTOR_CLONES bool NormalEquations::eliminateGroup(const EliminationGroup& g, int ld, double* Jc, double* Y,
                                     double* rb) {
  const int m = M > 0 ? M : g.size;
  const int nr = g.numRows, nk = g.numKeptRows;
  double* Jn = jn_.data();
  double* rl = localResidual_.data();
  double* V = v_.data();
  double* pr = pr_.data();
  double* inv = work_.data();
  gatherGroupRows(g, m, Jc);
  // A_nn = J_nᵀJ_n + ε²D_n = LLᵀ (row-major lower triangle; inv = 1 / diag L).
  double* L = factors_.data() + g.factorOffset;
  double* tn = L + m * m;
  double* U = tn + m;
  for (int a = 0; a < m; ++a) {
    for (int b = 0; b <= a; ++b) {
      double s = 0.0;
      for (int lr = 0; lr < nr; ++lr) s += Jn[lr * m + a] * Jn[lr * m + b];
      L[a * m + b] = s;
    }
    L[a * m + a] += eps2_ * groupRegularization_[g.varOffset + a];
  }
  for (int a = 0; a < m; ++a) {
    for (int b = 0; b < a; ++b) {
      double s = L[a * m + b];
      for (int k = 0; k < b; ++k) s -= L[a * m + k] * L[b * m + k];
      L[a * m + b] = s * inv[b];
    }
    double d = L[a * m + a];
    for (int k = 0; k < a; ++k) d -= L[a * m + k] * L[a * m + k];
    if (!(d > 0.0) || !std::isfinite(d)) return false;
    L[a * m + a] = std::sqrt(d);
    inv[a] = 1.0 / L[a * m + a];
  }
  groupRowsThroughFactor<M>(m, nr, L, inv, Jn, rl, V, tn);
  if (ld == 0) return true;
  for (int i = 0; i < nk; ++i) {  // P w r on the kept rows: w r − V t
    double p = rl[i];
    for (int a = 0; a < m; ++a) p -= V[i * m + a] * tn[a];
    pr[i] = p;
  }
  // Chunk by chunk of kept columns: U = Vᵀ J_c = L⁻¹ J_nᵀ J_c (m × ld, kept for the
  // back-substitution), Y = J_c − V U = (I − V Vᵀ) J_c, rhs_block −= J_cᵀ P w r.
  const double* jc = Jc + g.keptRowOffset * ld;
  double* y = Y + g.keptRowOffset * ld;
  for (int b0 = 0; b0 < ld; b0 += kChunk) {
    double acc[kChunk];
    for (int a = 0; a < m; ++a) {
      for (int q = 0; q < kChunk; ++q) acc[q] = 0.0;
      for (int i = 0; i < nk; ++i) {
        const double via = V[i * m + a];
        const double* ji = jc + i * ld + b0;
        for (int q = 0; q < kChunk; ++q) acc[q] += via * ji[q];
      }
      for (int q = 0; q < kChunk; ++q) U[a * ld + b0 + q] = acc[q];
    }
    for (int q = 0; q < kChunk; ++q) acc[q] = 0.0;
    for (int i = 0; i < nk; ++i) {
      const double* ji = jc + i * ld + b0;
      double yi[kChunk];
      for (int q = 0; q < kChunk; ++q) yi[q] = ji[q];
      for (int a = 0; a < m; ++a) {
        const double via = V[i * m + a];
        const double* u = U + a * ld + b0;
        for (int q = 0; q < kChunk; ++q) yi[q] -= via * u[q];
      }
      for (int q = 0; q < kChunk; ++q) y[i * ld + b0 + q] = yi[q];
      const double p = pr[i];
      for (int q = 0; q < kChunk; ++q) acc[q] += ji[q] * p;
    }
    for (int q = 0; q < kChunk; ++q) rb[b0 + q] -= acc[q];
  }
  return true;
}

DEVSURF_VECTOR_CLONES
bool NormalEquations::eliminate() {
  double* H = S_.valuePtr();
  double* rhs = rhs_.data();
  double* Sb = blockMatrix_.data();
  double* rb = blockRhs_.data();
  for (const EliminationBlock& block : blocks_) {
    const int c = block.numKept, K = block.numKeptRows, ld = paddedStride(c);
    double* Jc = jstack_.data();  // K × ld: the kept Jacobian rows of all groups of the block
    double* Y = ystack_.data();   // K × ld: (I − V Vᵀ) J_c per group
    std::fill(Jc, Jc + K * ld, 0.0);
    std::fill(rb, rb + ld, 0.0);
    for (int gi = block.groupBegin; gi < block.groupEnd; ++gi) {
      const EliminationGroup& g = groups_[gi];
      bool ok;
      switch (g.size) {  // the common small sizes with compile-time loop bounds
        case 1: ok = eliminateGroup<1>(g, ld, Jc, Y, rb); break;
        case 2: ok = eliminateGroup<2>(g, ld, Jc, Y, rb); break;
        case 3: ok = eliminateGroup<3>(g, ld, Jc, Y, rb); break;
        case 4: ok = eliminateGroup<4>(g, ld, Jc, Y, rb); break;
        default: ok = eliminateGroup<0>(g, ld, Jc, Y, rb); break;
      }
      if (!ok) return false;
    }
    if (c == 0) continue;
    // S_block = J_cᵀ Y over the stacked rows (upper triangle), scattered into S column by column.
    blockProductUpper(Jc, Y, Sb, c, ld, K);
    const int* slot = blockSlot_.data() + block.slotOffset;
    const int* cols = blockColumn_.data() + block.keptOffset;
    for (int b = 0; b < c; ++b) {
      for (int a = 0; a <= b; ++a) H[*slot++] += Sb[a * ld + b];
      rhs[cols[b]] += rb[b];
    }
  }
  return true;
}

void NormalEquations::correctGroup(const EliminationGroup& g, int ld, double* Jc, double* rb) {
  const int m = g.size, nr = g.numRows, nk = g.numKeptRows;
  double* Jn = jn_.data();
  double* rl = localResidual_.data();
  double* V = v_.data();
  double* pr = pr_.data();
  // The rows as eliminateGroup gathered them (the Jacobian of the last assemble()), with the
  // residuals of the correction.
  gatherGroupRows(g, m, Jc);
  // V = J_n L⁻ᵀ with the step's factor L, and t = L⁻¹ J_nᵀ w r replaced by the correction's (what
  // applyStep back-substitutes with).
  const double* L = factors_.data() + g.factorOffset;
  double* tn = factors_.data() + g.factorOffset + m * m;
  double* inv = work_.data();
  for (int a = 0; a < m; ++a) inv[a] = 1.0 / L[a * m + a];
  groupRowsThroughFactor<0>(m, nr, L, inv, Jn, rl, V, tn);
  // rhs_block −= J_cᵀ (w r − V t) over the group's kept rows.
  const double* jc = Jc + g.keptRowOffset * ld;
  for (int i = 0; i < nk; ++i) {
    double p = rl[i];
    for (int a = 0; a < m; ++a) p -= V[i * m + a] * tn[a];
    pr[i] = p;
    for (int b = 0; b < ld; ++b) rb[b] -= jc[i * ld + b] * p;
  }
}

void NormalEquations::correctionRhs(const Problem& problem, const Eigen::VectorXd& x) {
  keptValid_ = false;  // residual_ is overwritten below
  rhs_.setZero();
  double* rhs = rhs_.data();
  for (int t = 0; t < problem.numTerms(); ++t) {
    const TermPlan& plan = plans_[t];
    double* r = residual_.data() + termResidualOffset_[t];
    if (problem.term(t).strength != Strength::Hard) {  // held by the matrix, not pulling
      std::fill(r, r + plan.numResiduals, 0.0);
      continue;
    }
    if (plan.numFreeEntries == 0) continue;  // no row of this system
    problem.term(t).term->evaluate(x, r, nullptr);
    // −w² Jᵀ r over the term's direct rows, as accumulateDirectRows adds it.
    const double* J = jacobian_.data() + termJacobianOffset_[t];
    const double w2 = weights_[t] * weights_[t];
    const int numDirect = static_cast<int>(plan.directRow.size());
    for (int i = 0; i < numDirect; ++i) {
      const double wri = w2 * r[plan.directRow[i]];
      for (int k = plan.directStart[i]; k < plan.directStart[i + 1]; ++k)
        rhs[plan.directColumn[k]] -= J[plan.directEntry[k]] * wri;
    }
  }
  // The rows of the elimination groups, through each group's factor as eliminate() does.
  double* rb = blockRhs_.data();
  for (const EliminationBlock& block : blocks_) {
    const int c = block.numKept, K = block.numKeptRows, ld = paddedStride(c);
    double* Jc = jstack_.data();
    std::fill(Jc, Jc + K * ld, 0.0);
    std::fill(rb, rb + ld, 0.0);
    for (int gi = block.groupBegin; gi < block.groupEnd; ++gi) correctGroup(groups_[gi], ld, Jc, rb);
    const int* cols = blockColumn_.data() + block.keptOffset;
    for (int b = 0; b < c; ++b) rhs[cols[b]] += rb[b];
  }
}

double NormalEquations::applyStep(const Eigen::VectorXd& delta, Eigen::VectorXd& x) {
  for (int c = 0; c < numReduced_; ++c) x[keptVariable_[c]] += delta[c];
  double normSquared = delta.squaredNorm();
  // Back-substitution per group: δ_n = −L⁻ᵀ(t + U δ_c).
  double* dc = blockRhs_.data();
  double* z = work_.data();
  for (const EliminationBlock& block : blocks_) {
    const int c = block.numKept, ld = paddedStride(c);
    const int* cols = blockColumn_.data() + block.keptOffset;
    for (int a = 0; a < c; ++a) dc[a] = delta[cols[a]];
    for (int a = c; a < ld; ++a) dc[a] = 0.0;
    for (int gi = block.groupBegin; gi < block.groupEnd; ++gi) {
      const EliminationGroup& g = groups_[gi];
      const int m = g.size;
      const double* L = factors_.data() + g.factorOffset;
      const double* tn = L + m * m;
      const double* U = tn + m;
      for (int a = 0; a < m; ++a) {  // z = t + U δ_c, in chunks (independent partial sums)
        const double* u = U + a * ld;
        double acc[kChunk] = {};
        for (int b0 = 0; b0 < ld; b0 += kChunk)
          for (int q = 0; q < kChunk; ++q) acc[q] += u[b0 + q] * dc[b0 + q];
        double s = tn[a];
        for (int q = 0; q < kChunk; ++q) s += acc[q];
        z[a] = s;
      }
      double* dn = z + m;
      for (int a = m - 1; a >= 0; --a) {
        double s = z[a];
        for (int k = a + 1; k < m; ++k) s -= L[k * m + a] * dn[k];
        dn[a] = s / L[a * m + a];
        x[groupVariable_[g.varOffset + a]] -= dn[a];
        normSquared += dn[a] * dn[a];
      }
    }
  }
  return normSquared;
}

}  // namespace devsurf::engine
