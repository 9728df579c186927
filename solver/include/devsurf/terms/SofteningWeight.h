#pragma once

#include <array>
#include <stdexcept>
#include <vector>

namespace devsurf::terms {

/// Breakpoints 0 ≤ ξ1 ≤ ξ2 ≤ ξ3 ≤ ξ4 ≤ 1 of the softening multiplier (003_… §5.5, Fig. 5.1).
using SofteningBreakpoints = std::array<double, 4>;

/// Piecewise-linear multiplier w(u) that softens developability and crease rows near the ruling
/// boundaries of a face (003_… §5.5, Fig. 5.1), at a normalized parameter u ∈ [0, 1]:
///   w = 0 on [0, ξ1],  rises linearly to 1 on [ξ1, ξ2],  w = 1 on [ξ2, ξ3],
///   falls linearly to 0 on [ξ3, ξ4],  w = 0 on [ξ4, 1].
/// A jump (ξ1 = ξ2 or ξ3 = ξ4) takes the value 1 at the breakpoint; ξ = (0, 0, 1, 1) gives w ≡ 1.
/// \note The result is a constant row multiplier fixed per topology (e.g. CurvedFoldTerm's
///       rowMultipliers), not a term weight: the assembler still applies the term's weight on top.
///       Fig. 5.1 itself is not in our copy of the thesis; the trapezoid 0–1–0 is our reading of
///       "lower the weights … near the boundaries … additional trimming of the surfaces".
/// @throws std::invalid_argument if the breakpoints are not ordered inside [0, 1]
inline double softeningWeight(double u, const SofteningBreakpoints& xi) {
  if (!(0.0 <= xi[0] && xi[0] <= xi[1] && xi[1] <= xi[2] && xi[2] <= xi[3] && xi[3] <= 1.0))
    throw std::invalid_argument("softeningWeight: need 0 <= xi1 <= xi2 <= xi3 <= xi4 <= 1");
  if (u >= xi[1] && u <= xi[2]) return 1.0;
  if (u < xi[1]) return u <= xi[0] ? 0.0 : (u - xi[0]) / (xi[1] - xi[0]);
  return u >= xi[3] ? 0.0 : (xi[3] - u) / (xi[3] - xi[2]);
}

/// softeningWeight at every parameter of `params`, normalized by the curve's domain
/// [domainBegin, domainEnd] first: u ↦ (u − domainBegin)/(domainEnd − domainBegin).
/// @throws std::invalid_argument for an empty domain or unordered breakpoints
inline std::vector<double> softeningWeights(const std::vector<double>& params,
                                            const SofteningBreakpoints& xi,
                                            double domainBegin = 0.0, double domainEnd = 1.0) {
  if (!(domainEnd > domainBegin))
    throw std::invalid_argument("softeningWeights: empty parameter domain");
  std::vector<double> w;
  w.reserve(params.size());
  for (double u : params)
    w.push_back(softeningWeight((u - domainBegin) / (domainEnd - domainBegin), xi));
  return w;
}

}  // namespace devsurf::terms
