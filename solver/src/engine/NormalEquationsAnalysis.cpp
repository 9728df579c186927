// NormalEquations: the symbolic analysis, once per pattern (the constructor) — terms' structures,
// elimination groups, the fill-reducing ordering, the pattern of S and the scatter plans that
// assemble() (NormalEquations.cpp) and eliminate() (NormalEquationsElimination.cpp) follow.
#include "devsurf/engine/NormalEquations.h"

#include <algorithm>
#include <cassert>
#include <stdexcept>
#include <string>

#include <Eigen/OrderingMethods>

#include "EliminationChunks.h"

namespace devsurf::engine {
namespace {

// Automatic elimination only takes small groups with few rows and neighbours (dense work per
// group is O(rows · (m + c)²)); declared groups (VariableLayout::setEliminable) have no limits.
constexpr int kMaxAutoGroupSize = 8;
constexpr int kMaxAutoGroupRows = 64;
constexpr int kMaxAutoNeighbours = 128;

}  // namespace

using detail::paddedStride;

NormalEquations::NormalEquations(const Problem& problem, const Deadline& deadline, VariablePart part)
    : part_(part) {
  const VariableLayout& layout = problem.layout();
  const int numVariables = layout.numVariables();
  const std::vector<int> natural = layout.freeIndex(part);  // variable → natural free column
  numFree_ = layout.numFree(part);
  const int numTerms = problem.numTerms();

  // 1. Per term: the structure, validated; free entries grouped by row with natural columns.
  plans_.resize(numTerms);
  termResidualOffset_.assign(numTerms + 1, 0);
  termJacobianOffset_.assign(numTerms + 1, 0);
  std::vector<std::vector<int>> rowStarts(numTerms), rowOrders(numTerms), entryColumns(numTerms);
  std::vector<JacobianEntry> entries;
  std::vector<int> marker(numVariables, -1);
  for (int t = 0; t < numTerms; ++t) {
    deadline.check();
    const Term& term = *problem.term(t).term;
    TermPlan& plan = plans_[t];
    entries.clear();
    term.jacobianStructure(entries);
    plan.numResiduals = term.numResiduals();
    plan.numEntries = static_cast<int>(entries.size());
    termResidualOffset_[t + 1] = termResidualOffset_[t] + plan.numResiduals;
    termJacobianOffset_[t + 1] = termJacobianOffset_[t] + plan.numEntries;

    std::vector<int>& start = rowStarts[t];
    std::vector<int>& order = rowOrders[t];
    std::vector<int>& column = entryColumns[t];
    start.assign(plan.numResiduals + 1, 0);
    for (const JacobianEntry& e : entries) {
      if (e.row < 0 || e.row >= plan.numResiduals || e.variable < 0 || e.variable >= numVariables)
        throw std::logic_error("term '" + term.name() + "': Jacobian entry out of range");
      if (natural[e.variable] >= 0) ++start[e.row + 1];
    }
    plan.numFreeEntries = 0;
    for (int r = 0; r < plan.numResiduals; ++r) plan.numFreeEntries += start[r + 1];
    for (int r = 0; r < plan.numResiduals; ++r) start[r + 1] += start[r];
    order.assign(start.back(), -1);
    column.assign(entries.size(), -1);
    std::vector<int> fill(start.begin(), start.end() - 1);
    for (int e = 0; e < plan.numEntries; ++e) {
      const int c = natural[entries[e].variable];
      column[e] = c;
      if (c >= 0) order[fill[entries[e].row]++] = e;
    }
    // A row must not list a variable twice (the scatter maps assume distinct columns per row).
    for (int r = 0; r < plan.numResiduals; ++r) {
      const int globalRow = termResidualOffset_[t] + r;
      for (int k = start[r]; k < start[r + 1]; ++k) {
        const int v = entries[order[k]].variable;
        if (marker[v] == globalRow) {
          throw std::logic_error("term '" + term.name() + "': row " + std::to_string(r) +
                                 " lists variable " + std::to_string(v) + " twice");
        }
        marker[v] = globalRow;
      }
    }
  }
  const int numRows = termResidualOffset_[numTerms];
  residual_.setZero(numRows);
  jacobian_.setZero(termJacobianOffset_[numTerms]);
  weights_.assign(numTerms, 0.0);
  // Terms whose Jacobian a residual evaluation keeps for the next assemble() (Term::evaluatesFromXAlone).
  keptTerm_.assign(static_cast<std::size_t>(numTerms), 0);
  for (int t = 0; t < numTerms; ++t)
    if (problem.term(t).term->evaluatesFromXAlone() && plans_[static_cast<std::size_t>(t)].numFreeEntries > 0) {
      keptTerm_[static_cast<std::size_t>(t)] = 1;
      anyKeptTerm_ = true;
    }
  numVariablesForKeeping_ = static_cast<int>(problem.x().size());
  setKeepEvaluations(true);

  // 2. Incidence over all terms: global row → natural columns, column → rows (ascending).
  std::vector<int> rowTerm(numRows), rowPtr(numRows + 1, 0), rowCols;
  for (int t = 0; t < numTerms; ++t) {
    for (int r = 0; r < plans_[t].numResiduals; ++r) {
      const int g = termResidualOffset_[t] + r;
      rowTerm[g] = t;
      rowPtr[g + 1] = rowPtr[g] + rowStarts[t][r + 1] - rowStarts[t][r];
    }
  }
  rowCols.resize(rowPtr[numRows]);
  for (int t = 0; t < numTerms; ++t) {
    for (int r = 0; r < plans_[t].numResiduals; ++r) {
      int* out = rowCols.data() + rowPtr[termResidualOffset_[t] + r];
      for (int k = rowStarts[t][r]; k < rowStarts[t][r + 1]; ++k)
        *out++ = entryColumns[t][rowOrders[t][k]];
    }
  }
  std::vector<int> colPtr(numFree_ + 1, 0), colRows(rowCols.size());
  for (int c : rowCols) ++colPtr[c + 1];
  for (int c = 0; c < numFree_; ++c) colPtr[c + 1] += colPtr[c];
  {
    std::vector<int> fill(colPtr.begin(), colPtr.end() - 1);
    for (int g = 0; g < numRows; ++g)
      for (int k = rowPtr[g]; k < rowPtr[g + 1]; ++k) colRows[fill[rowCols[k]]++] = g;
  }
  std::vector<int> colVariable(numFree_), colBlock(numFree_);
  for (int b = 0; b < layout.numBlocks(); ++b) {
    const VariableBlock& block = layout.block(b);
    for (int v = block.offset; v < block.offset + block.size; ++v) {
      if (natural[v] < 0) continue;
      colVariable[natural[v]] = v;
      colBlock[natural[v]] = b;
    }
  }

  // 3. Elimination groups. groupOf: natural column → group id or −1.
  std::vector<int> groupOf(numFree_, -1);
  std::vector<std::vector<int>> groupCols;  // natural columns per group, ascending
  std::vector<char> groupDeclared;
  // 3a. Declared groups (VariableLayout::setEliminable).
  for (int b = 0; b < layout.numBlocks(); ++b) {
    const VariableBlock& block = layout.block(b);
    const int size = block.eliminationGroupSize;
    if (size <= 0) continue;
    for (int first = block.offset; first < block.offset + block.size; first += size) {
      std::vector<int> cols;
      for (int v = first; v < first + size; ++v)
        if (natural[v] >= 0) cols.push_back(natural[v]);
      if (cols.empty()) continue;
      for (int c : cols) groupOf[c] = static_cast<int>(groupCols.size());
      groupCols.push_back(std::move(cols));
      groupDeclared.push_back(1);
    }
  }
  for (int g = 0; g < numRows; ++g) {
    int seen = -1;
    for (int k = rowPtr[g]; k < rowPtr[g + 1]; ++k) {
      const int group = groupOf[rowCols[k]];
      if (group < 0 || group == seen) continue;
      if (seen >= 0) {
        const int t = rowTerm[g];
        throw std::logic_error("term '" + problem.term(t).term->name() + "': row " +
                               std::to_string(g - termResidualOffset_[t]) +
                               " couples two elimination groups (VariableLayout::setEliminable)");
      }
      seen = group;
    }
  }
  // 3b. Automatic groups: columns of an auto block with identical row lists ("supervariables")
  //     whose neighbours all lie in one of their rows (eliminating them creates no fill),
  //     chosen greedily by fewest neighbours so that no row touches two groups.
  {
    auto rowsOf = [&](int c) {
      return std::make_pair(colRows.begin() + colPtr[c], colRows.begin() + colPtr[c + 1]);
    };
    std::vector<int> cand;
    for (int c = 0; c < numFree_; ++c) {
      if (groupOf[c] >= 0 || colPtr[c + 1] == colPtr[c]) continue;
      if (layout.block(colBlock[c]).eliminationGroupSize != VariableBlock::kAutoElimination) continue;
      if (colPtr[c + 1] - colPtr[c] > kMaxAutoGroupRows) continue;
      cand.push_back(c);
    }
    auto sameRows = [&](int a, int b) {
      const auto ra = rowsOf(a), rb = rowsOf(b);
      return colBlock[a] == colBlock[b] && std::equal(ra.first, ra.second, rb.first, rb.second);
    };
    std::sort(cand.begin(), cand.end(), [&](int a, int b) {
      if (colBlock[a] != colBlock[b]) return colBlock[a] < colBlock[b];
      const auto ra = rowsOf(a), rb = rowsOf(b);
      if (ra.second - ra.first != rb.second - rb.first)
        return ra.second - ra.first < rb.second - rb.first;
      const auto mis = std::mismatch(ra.first, ra.second, rb.first);
      if (mis.first != ra.second) return *mis.first < *mis.second;
      return a < b;
    });
    struct Candidate {
      int neighbours;
      std::vector<int> cols;
    };
    std::vector<Candidate> candidates;
    std::vector<int> colMark(numFree_, -1);
    for (std::size_t i = 0; i < cand.size();) {
      std::size_t j = i + 1;
      while (j < cand.size() && sameRows(cand[i], cand[j])) ++j;
      const int m = static_cast<int>(j - i);
      if (m <= kMaxAutoGroupSize) {
        // Union of the columns of the rows; the group creates no fill iff one row holds them all.
        int unionSize = 0;
        bool covered = false;
        const auto rows = rowsOf(cand[i]);
        for (auto it = rows.first; it != rows.second; ++it) {
          for (int k = rowPtr[*it]; k < rowPtr[*it + 1]; ++k) {
            if (colMark[rowCols[k]] != static_cast<int>(i)) {
              colMark[rowCols[k]] = static_cast<int>(i);
              ++unionSize;
            }
          }
        }
        for (auto it = rows.first; it != rows.second && !covered; ++it)
          covered = rowPtr[*it + 1] - rowPtr[*it] == unionSize;
        if (covered && unionSize - m <= kMaxAutoNeighbours) {
          std::vector<int> cols(cand.begin() + static_cast<long>(i), cand.begin() + static_cast<long>(j));
          std::sort(cols.begin(), cols.end());
          candidates.push_back({unionSize - m, std::move(cols)});
        }
      }
      i = j;
    }
    std::stable_sort(candidates.begin(), candidates.end(),
                     [](const Candidate& a, const Candidate& b) {
                       if (a.neighbours != b.neighbours) return a.neighbours < b.neighbours;
                       return a.cols.front() < b.cols.front();
                     });
    for (Candidate& cnd : candidates) {
      bool free = true;
      for (auto it = rowsOf(cnd.cols.front()).first; free && it != rowsOf(cnd.cols.front()).second;
           ++it)
        for (int k = rowPtr[*it]; free && k < rowPtr[*it + 1]; ++k)
          free = groupOf[rowCols[k]] < 0;
      if (!free) continue;
      for (int c : cnd.cols) groupOf[c] = static_cast<int>(groupCols.size());
      groupCols.push_back(std::move(cnd.cols));
      groupDeclared.push_back(0);
    }
  }
  const int numGroups = static_cast<int>(groupCols.size());

  // 4. Kept columns (natural order) and the rows of every group.
  std::vector<int> keptOf(numFree_, -1), keptNatural;
  for (int c = 0; c < numFree_; ++c) {
    if (groupOf[c] >= 0) continue;
    keptOf[c] = static_cast<int>(keptNatural.size());
    keptNatural.push_back(c);
  }
  numReduced_ = static_cast<int>(keptNatural.size());
  std::vector<int> rowGroup(numRows, -1);
  std::vector<std::vector<int>> groupRows(numGroups), groupKept(numGroups);
  for (int g = 0; g < numGroups; ++g) {
    for (int c : groupCols[g])
      for (int k = colPtr[c]; k < colPtr[c + 1]; ++k) groupRows[g].push_back(colRows[k]);
    std::sort(groupRows[g].begin(), groupRows[g].end());
    groupRows[g].erase(std::unique(groupRows[g].begin(), groupRows[g].end()), groupRows[g].end());
    for (int row : groupRows[g]) {
      assert(rowGroup[row] < 0 && "a row touches two elimination groups");
      rowGroup[row] = g;
      for (int k = rowPtr[row]; k < rowPtr[row + 1]; ++k)
        if (keptOf[rowCols[k]] >= 0) groupKept[g].push_back(keptOf[rowCols[k]]);
    }
    std::sort(groupKept[g].begin(), groupKept[g].end());
    groupKept[g].erase(std::unique(groupKept[g].begin(), groupKept[g].end()), groupKept[g].end());
  }
  // Processing order: groups with the same kept columns next to each other (one block each).
  std::vector<int> groupOrder(numGroups);
  for (int g = 0; g < numGroups; ++g) groupOrder[g] = g;
  std::stable_sort(groupOrder.begin(), groupOrder.end(), [&](int a, int b) {
    return groupKept[a] < groupKept[b];
  });

  // 5. Pattern of the reduced matrix over kept columns (natural order), column by column: for
  //    kept column j the kept columns i ≤ j that share a row with it (H's pattern there), or the
  //    kept columns of an automatic group whose rows hold j (such rows are not visited: the
  //    group's kept columns cover them), then the kept columns of declared groups holding j
  //    (fill). A mark per column keeps every list free of duplicates as it grows, so the work is
  //    Σ over rows of (kept entries × entries), without the duplicate lists and their sorting.
  std::vector<std::vector<int>> neighbours(numReduced_);
  deadline.check();
  std::vector<std::vector<int>> autoGroupsOf(numReduced_), declaredGroupsOf(numReduced_);
  for (std::size_t i = 0; i < groupOrder.size(); ++i) {
    const int g = groupOrder[i];
    if (!groupDeclared[g] && i > 0 && !groupDeclared[groupOrder[i - 1]] && groupKept[groupOrder[i - 1]] == groupKept[g])
      continue;  // same kept columns as the previous group
    for (int k : groupKept[g]) (groupDeclared[g] ? declaredGroupsOf : autoGroupsOf)[k].push_back(g);
  }
  long keptNonZerosOfH = 0, nnz = 0;
  {
    std::vector<int> mark(numReduced_, -1);
    for (int j = 0; j < numReduced_; ++j) {
      if (j % 4096 == 0) deadline.check();
      std::vector<int>& list = neighbours[j];
      auto add = [&list, &mark, j](int i) {
        if (i < 0 || i > j || mark[i] == j) return;
        mark[i] = j;
        list.push_back(i);
      };
      add(j);
      const int c = keptNatural[j];
      for (int q = colPtr[c]; q < colPtr[c + 1]; ++q) {
        const int row = colRows[q];
        const int g = rowGroup[row];
        if (g >= 0 && !groupDeclared[g]) continue;  // within the group's kept columns
        for (int k = rowPtr[row]; k < rowPtr[row + 1]; ++k) add(keptOf[rowCols[k]]);
      }
      for (int g : autoGroupsOf[j])
        for (int k : groupKept[g]) add(k);
      keptNonZerosOfH += static_cast<long>(list.size());
      for (int g : declaredGroupsOf[j])
        for (int k : groupKept[g]) add(k);
      std::sort(list.begin(), list.end());
      list.shrink_to_fit();
      nnz += static_cast<long>(list.size());
    }
  }

  // Structural nonzeros of the full H: kept part plus, per eliminated column u, u's diagonal,
  // the kept columns and the later columns of its own group that share a row with u.
  nonZerosFull_ = keptNonZerosOfH;
  {
    std::vector<int> mark(numFree_, -1);
    for (int g = 0; g < numGroups; ++g) {
      for (std::size_t iu = 0; iu < groupCols[g].size(); ++iu) {
        const int u = groupCols[g][iu];
        mark[u] = u;
        long count = 1;
        for (int k = colPtr[u]; k < colPtr[u + 1]; ++k) {
          const int row = colRows[k];
          for (int q = rowPtr[row]; q < rowPtr[row + 1]; ++q) {
            const int c = rowCols[q];
            if (mark[c] == u) continue;
            mark[c] = u;
            if (keptOf[c] >= 0 || (groupOf[c] == g && c > u)) ++count;
          }
        }
        nonZerosFull_ += count;
      }
    }
  }

  deadline.check();
  // 6. Fill-reducing ordering (AMD) of the reduced pattern, computed once.
  std::vector<int> oldToNew(numReduced_);
  {
    SymmetricUpper pattern(numReduced_, numReduced_);
    std::vector<Eigen::Triplet<double, int>> triplets;
    triplets.reserve(static_cast<std::size_t>(nnz));
    for (int j = 0; j < numReduced_; ++j)
      for (int i : neighbours[j]) triplets.emplace_back(i, j, 1.0);
    pattern.setFromTriplets(triplets.begin(), triplets.end());
    Eigen::PermutationMatrix<Eigen::Dynamic, Eigen::Dynamic, int> newToOld;
    if (numReduced_ > 0) {
      Eigen::AMDOrdering<int> amd;
      SymmetricUpper full = pattern.selfadjointView<Eigen::Upper>();
      amd(full, newToOld);
    }
    for (int k = 0; k < numReduced_; ++k) oldToNew[newToOld.indices()[k]] = k;
  }

  deadline.check();
  // 7. The permuted upper-triangular pattern with sorted row indices per column.
  {
    std::vector<std::vector<int>> permuted(numReduced_);
    for (int j = 0; j < numReduced_; ++j) {
      for (int i : neighbours[j]) {
        const int pi = oldToNew[i], pj = oldToNew[j];
        permuted[std::max(pi, pj)].push_back(std::min(pi, pj));
      }
      std::vector<int>().swap(neighbours[j]);
    }
    S_.resize(numReduced_, numReduced_);
    Eigen::VectorXi sizes(numReduced_);
    for (int j = 0; j < numReduced_; ++j) {
      std::sort(permuted[j].begin(), permuted[j].end());
      sizes[j] = static_cast<int>(permuted[j].size());
    }
    S_.reserve(sizes);
    for (int j = 0; j < numReduced_; ++j)
      for (int i : permuted[j]) S_.insert(i, j) = 0.0;
    S_.makeCompressed();
  }
  auto slotOf = [this](int i, int j) {
    // (i, j) in the permuted upper triangle, i ≤ j: binary search in column j.
    const int* begin = S_.innerIndexPtr() + S_.outerIndexPtr()[j];
    const int* end = S_.innerIndexPtr() + S_.outerIndexPtr()[j + 1];
    const int* it = std::lower_bound(begin, end, i);
    assert(it != end && *it == i && "pair missing from the symbolic pattern");
    return static_cast<int>(it - S_.innerIndexPtr());
  };
  diagonalSlot_.resize(numReduced_);
  for (int c = 0; c < numReduced_; ++c) diagonalSlot_[c] = slotOf(c, c);
  auto reducedColumn = [&](int naturalColumn) {
    const int k = keptOf[naturalColumn];
    return k >= 0 ? oldToNew[k] : -1;
  };

  // 8. Direct rows (no eliminated variable): entries with reduced columns and the pair slots.
  std::vector<int> sortedEntry, pairTable;
  for (int t = 0; t < numTerms; ++t) {
    deadline.check();
    TermPlan& plan = plans_[t];
    const std::vector<int>& start = rowStarts[t];
    const std::vector<int>& order = rowOrders[t];
    plan.directStart.assign(1, 0);
    for (int r = 0; r < plan.numResiduals; ++r) {
      if (rowGroup[termResidualOffset_[t] + r] >= 0) continue;
      plan.directRow.push_back(r);
      for (int k = start[r]; k < start[r + 1]; ++k) {
        plan.directEntry.push_back(order[k]);
        plan.directColumn.push_back(reducedColumn(entryColumns[t][order[k]]));
      }
      plan.directStart.push_back(static_cast<int>(plan.directEntry.size()));
    }
    // Runs of consecutive rows with the same columns in the same order (the samples of one span
    // of a crease): their products are summed densely and scattered once.
    const int numDirect = static_cast<int>(plan.directRow.size());
    plan.directRun.assign(static_cast<std::size_t>(numDirect), 0);
    long pairs = 0;
    plan.directProducts = 0;
    auto sameColumns = [&plan](int a, int b) {
      const int na = plan.directStart[a + 1] - plan.directStart[a], nb = plan.directStart[b + 1] - plan.directStart[b];
      return na == nb && std::equal(plan.directColumn.begin() + plan.directStart[a],
                                    plan.directColumn.begin() + plan.directStart[a + 1],
                                    plan.directColumn.begin() + plan.directStart[b]);
    };
    for (int i = 0; i < numDirect;) {
      int j = i + 1;
      while (j < numDirect && sameColumns(i, j)) ++j;
      plan.directRun[static_cast<std::size_t>(i)] = j - i;
      const long e = plan.directStart[i + 1] - plan.directStart[i];
      pairs += e * (e + 1) / 2;
      plan.directProducts += (j - i) * e * (e + 1) / 2;
      i = j;
    }
    plan.pairSlot.resize(static_cast<std::size_t>(pairs));
    // Per run: its columns in ascending order; for each column j, the slots of the row's columns
    // ≤ j are found in one forward pass through column j of S (they are ascending too), instead
    // of a binary search per pair.
    std::size_t written = 0;
    for (std::size_t i = 0; i + 1 < plan.directStart.size(); ++i) {
      if (plan.directRun[i] == 0) continue;
      const int base = plan.directStart[i], e = plan.directStart[i + 1] - base;
      const int* column = plan.directColumn.data() + base;
      sortedEntry.resize(static_cast<std::size_t>(e));
      for (int k = 0; k < e; ++k) sortedEntry[static_cast<std::size_t>(k)] = k;
      std::sort(sortedEntry.begin(), sortedEntry.end(), [column](int a, int b) { return column[a] < column[b]; });
      pairTable.resize(static_cast<std::size_t>(e) * static_cast<std::size_t>(e));
      const int* inner = S_.innerIndexPtr();
      for (int bi = 0; bi < e; ++bi) {
        const int kb = sortedEntry[static_cast<std::size_t>(bi)], j = column[kb];
        const int* end = inner + S_.outerIndexPtr()[j + 1];
        const int* it = std::lower_bound(inner + S_.outerIndexPtr()[j], end, column[sortedEntry[0]]);
        for (int ai = 0; ai <= bi; ++ai) {
          const int ka = sortedEntry[static_cast<std::size_t>(ai)], ci = column[ka];
          while (it != end && *it < ci) ++it;
          assert(it != end && *it == ci && "pair missing from the symbolic pattern");
          const int slot = static_cast<int>(it - inner);
          pairTable[static_cast<std::size_t>(ka * e + kb)] = slot;
          pairTable[static_cast<std::size_t>(kb * e + ka)] = slot;
        }
      }
      for (int ka = 0; ka < e; ++ka)
        for (int kb = ka; kb < e; ++kb) plan.pairSlot[written++] = pairTable[static_cast<std::size_t>(ka * e + kb)];
    }
  }

  std::size_t longestDirectRow = 0;
  for (const TermPlan& plan : plans_)
    for (std::size_t i = 0; i + 1 < plan.directStart.size(); ++i)
      longestDirectRow = std::max(longestDirectRow,
                                  static_cast<std::size_t>(plan.directStart[i + 1] - plan.directStart[i]));
  longestDirectRow_ = static_cast<int>(longestDirectRow);
  rowValues_.assign(longestDirectRow * (longestDirectRow + 1), 0.0);  // a row, then a dense run sum
  for (const TermPlan& plan : plans_) directProducts_ += plan.directProducts;

  deadline.check();
  // 9. Elimination blocks and groups in processing order.
  int maxRows = 0, maxSize = 0, maxKept = 0, maxBlockRows = 0;
  std::vector<int> localColumn(numFree_, -1);
  std::vector<int> own, kept;
  for (std::size_t i = 0; i < groupOrder.size();) {
    std::size_t j = i + 1;
    while (j < groupOrder.size() && groupKept[groupOrder[j]] == groupKept[groupOrder[i]]) ++j;
    EliminationBlock block;
    block.groupBegin = static_cast<int>(groups_.size());
    block.keptOffset = static_cast<int>(blockColumn_.size());
    block.slotOffset = static_cast<int>(blockSlot_.size());
    // The block's kept columns in ascending reduced order, so pair (a ≤ b) is slot (col a, col b).
    std::vector<int> cols;
    for (int k : groupKept[groupOrder[i]]) cols.push_back(oldToNew[k]);
    std::sort(cols.begin(), cols.end());
    const int c = static_cast<int>(cols.size());
    block.numKept = c;
    blockColumn_.insert(blockColumn_.end(), cols.begin(), cols.end());
    const int ld = paddedStride(c);
    for (int b = 0; b < c; ++b)  // column by column: ascending slots within a column of S
      for (int a = 0; a <= b; ++a) blockSlot_.push_back(slotOf(cols[a], cols[b]));
    for (int k : groupKept[groupOrder[i]]) {  // kept column → its position in the block
      const auto it = std::lower_bound(cols.begin(), cols.end(), oldToNew[k]);
      localColumn[keptNatural[k]] = static_cast<int>(it - cols.begin());
    }
    for (std::size_t q = i; q < j; ++q) {
      const int g = groupOrder[q];
      EliminationGroup group;
      const int m = static_cast<int>(groupCols[g].size());
      group.size = m;
      group.varOffset = static_cast<int>(groupVariable_.size());
      group.factorOffset = static_cast<int>(factors_.size());
      group.rowOffset = static_cast<int>(groupRowTerm_.size());
      group.keptRowOffset = block.numKeptRows;
      for (int a = 0; a < m; ++a) {
        const int col = groupCols[g][a];
        localColumn[col] = a;
        groupVariable_.push_back(colVariable[col]);
        groupRegularization_.push_back(layout.block(colBlock[col]).regularizationScale);
      }
      factors_.resize(factors_.size() + static_cast<std::size_t>(m * m + m + m * ld), 0.0);
      // Rows with kept entries first, then rows on the group's own scalars only.
      std::vector<int> rows;
      for (int pass = 0; pass < 2; ++pass) {
        for (int row : groupRows[g]) {
          bool hasKept = false;
          for (int k = rowPtr[row]; k < rowPtr[row + 1] && !hasKept; ++k)
            hasKept = keptOf[rowCols[k]] >= 0;
          if (hasKept == (pass == 0)) rows.push_back(row);
        }
        if (pass == 0) group.numKeptRows = static_cast<int>(rows.size());
      }
      group.numRows = static_cast<int>(rows.size());
      for (int lr = 0; lr < group.numRows; ++lr) {
        const int row = rows[lr];
        const int t = rowTerm[row];
        const int r = row - termResidualOffset_[t];
        groupRowTerm_.push_back(t);
        groupRowResidual_.push_back(row);
        own.clear();
        kept.clear();
        for (int k = rowStarts[t][r]; k < rowStarts[t][r + 1]; ++k) {
          const int e = rowOrders[t][k];
          const int col = entryColumns[t][e];
          (keptOf[col] >= 0 ? kept : own).push_back(e);
        }
        groupRowStart_.push_back(static_cast<int>(groupEntrySource_.size()));
        for (int e : own) {
          groupEntrySource_.push_back(termJacobianOffset_[t] + e);
          groupEntryDest_.push_back(lr * m + localColumn[entryColumns[t][e]]);
        }
        groupRowSplit_.push_back(static_cast<int>(groupEntrySource_.size()));
        for (int e : kept) {
          groupEntrySource_.push_back(termJacobianOffset_[t] + e);
          groupEntryDest_.push_back((group.keptRowOffset + lr) * ld +
                                    localColumn[entryColumns[t][e]]);
        }
      }
      block.numKeptRows += group.numKeptRows;
      maxRows = std::max(maxRows, group.numRows);
      maxSize = std::max(maxSize, m);
      groups_.push_back(group);
    }
    maxKept = std::max(maxKept, ld);
    maxBlockRows = std::max(maxBlockRows, block.numKeptRows);
    block.groupEnd = static_cast<int>(groups_.size());
    blocks_.push_back(block);
    i = j;
  }
  groupRowStart_.push_back(static_cast<int>(groupEntrySource_.size()));
  jn_.assign(static_cast<std::size_t>(maxRows * maxSize), 0.0);
  localResidual_.assign(static_cast<std::size_t>(maxRows), 0.0);
  v_.assign(static_cast<std::size_t>(maxRows * maxSize), 0.0);
  pr_.assign(static_cast<std::size_t>(maxRows), 0.0);
  jstack_.assign(static_cast<std::size_t>(maxBlockRows) * static_cast<std::size_t>(maxKept), 0.0);
  ystack_.assign(jstack_.size(), 0.0);
  blockMatrix_.assign(static_cast<std::size_t>(maxKept) * static_cast<std::size_t>(maxKept), 0.0);
  blockRhs_.assign(static_cast<std::size_t>(maxKept), 0.0);
  work_.assign(static_cast<std::size_t>(2 * maxSize), 0.0);

  keptVariable_.assign(numReduced_, -1);
  regularizationScale_.assign(numReduced_, 1.0);
  for (int k = 0; k < numReduced_; ++k) {
    const int col = keptNatural[k];
    keptVariable_[oldToNew[k]] = colVariable[col];
    regularizationScale_[oldToNew[k]] = layout.block(colBlock[col]).regularizationScale;
  }
  rhs_.setZero(numReduced_);
}

}  // namespace devsurf::engine
