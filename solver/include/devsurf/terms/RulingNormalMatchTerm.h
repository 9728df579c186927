#pragma once

#include <array>
#include <string>
#include <vector>

#include "devsurf/engine/Term.h"
#include "devsurf/terms/LinearPoints.h"

namespace devsurf::terms {

/// Smooth (tangent-plane continuous) transition between two faces (000_… §3.1), NormalMatchTerm's
/// rows with each face's unit normal taken from its geometry instead of a free normal variable:
/// for every pair k three rows (x, y, z)
///   o1_k ĝ1_k − o2_k ĝ2_k,   ĝi = (t_i × d_i) / |t_i × d_i|,
/// where t_i and d_i span face i's tangent plane where the two faces meet — across a smooth curved
/// edge a: t_i = a′ and d_i face i's ruling b − a at the parameter; at a shared ruling: t_i = a′ + b′
/// of face i there and d_i = b − a — and o_i,k = ±1 orients ĝi like face i's normal.
///
/// Why: NormalMatchTerm couples the free normals of the two faces, which keeps them (and every
/// normal of their samples) in the factorized system; with these rows a face's free normals
/// appear only in its own developability and unit rows and the assembler eliminates them per
/// sample (CompositeOptions::creaseNormals = ruling, issue 17; see CurvedFoldRulingTerm).
/// A pair whose t_i × d_i vanishes for a side (degenerate geometry, which the model's guards keep
/// away) gives rows 0 with a zero Jacobian. Non-polynomial (ĝ is normalized); the Jacobian is exact.
class RulingNormalMatchTerm final : public engine::Term {
 public:
  /// @param[in] t1, d1, t2, d2  K rows each, linear in control points; any of them may share
  ///            control points (a point's entries are merged)
  /// @param[in] orientation1, orientation2  o_1,k and o_2,k: K values, each +1 or −1
  /// @throws std::invalid_argument on mismatched row counts or an orientation other than ±1
  RulingNormalMatchTerm(std::string name, const LinearPoints& t1, const LinearPoints& d1, const LinearPoints& t2,
                        const LinearPoints& d2, std::vector<double> orientation1, std::vector<double> orientation2);

  int numResiduals() const override { return 3 * count_; }
  void jacobianStructure(std::vector<engine::JacobianEntry>& entries) const override;
  bool evaluatesFromXAlone() const override { return true; }
  void evaluate(const Eigen::VectorXd& x, double* residuals, double* jacobian) const override;

 private:
  /// One control point of a pair: x index of its x coordinate and its weights in t1, d1, t2, d2.
  struct PairPoint {
    int variable = 0;
    std::array<double, 4> weight{};
  };
  int count_ = 0;
  std::vector<int> pairStart_;  ///< K + 1 offsets into points_
  std::vector<PairPoint> points_;
  std::vector<double> orientation1_, orientation2_;
};

}  // namespace devsurf::terms
