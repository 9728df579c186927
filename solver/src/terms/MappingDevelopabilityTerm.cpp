#include "devsurf/terms/MappingDevelopabilityTerm.h"

#include <stdexcept>

namespace devsurf::terms {

MappingDevelopabilityTerm::MappingDevelopabilityTerm(std::string name, int shapeOffset,
                                                     spline::EvaluationMatrix tailWeights,
                                                     std::vector<int> normalOffsets,
                                                     Eigen::MatrixX3d c1Points,
                                                     Eigen::MatrixX3d c1Tangents,
                                                     std::shared_ptr<const ExtendedCurve> c2)
    : Term(std::move(name)),
      shapeOffset_(shapeOffset),
      tailWeights_(std::move(tailWeights)),
      normalOffsets_(std::move(normalOffsets)),
      c1Points_(std::move(c1Points)),
      c1Tangents_(std::move(c1Tangents)),
      c2_(std::move(c2)) {
  const auto k = static_cast<Eigen::Index>(normalOffsets_.size());
  if (tailWeights_.rows() != k || c1Points_.rows() != k || c1Tangents_.rows() != k) {
    throw std::invalid_argument(
        "MappingDevelopabilityTerm: tailWeights, c1Points and c1Tangents need one row per normal");
  }
  if (!c2_) throw std::invalid_argument("MappingDevelopabilityTerm: c2 is null");
  tailWeights_.makeCompressed();
}

void MappingDevelopabilityTerm::jacobianStructure(
    std::vector<engine::JacobianEntry>& entries) const {
  for (int i = 0; i < static_cast<int>(normalOffsets_.size()); ++i) {
    for (int c = 0; c < 3; ++c) entries.push_back({3 * i, normalOffsets_[i] + c});
    for (int row = 3 * i + 1; row <= 3 * i + 2; ++row) {
      for (int c = 0; c < 3; ++c) entries.push_back({row, normalOffsets_[i] + c});
      for (spline::EvaluationMatrix::InnerIterator it(tailWeights_, i); it; ++it)
        entries.push_back({row, shapeOffset_ + static_cast<int>(it.col())});
    }
  }
}

double MappingDevelopabilityTerm::mappedParameter(const Eigen::VectorXd& x, int sample) const {
  double sigma = 0.0;
  for (spline::EvaluationMatrix::InnerIterator it(tailWeights_, sample); it; ++it) {
    const double e = x[shapeOffset_ + it.col()];
    sigma += it.value() * e * e;
  }
  return sigma;
}

void MappingDevelopabilityTerm::evaluate(const Eigen::VectorXd& x, double* residuals,
                                         double* jacobian) const {
  double* out = jacobian;
  for (int i = 0; i < static_cast<int>(normalOffsets_.size()); ++i) {
    const Eigen::Vector3d n = x.segment<3>(normalOffsets_[i]);
    const double sigma = mappedParameter(x, i);
    const CurveJet c2 = c2_->evaluate(sigma);
    const Eigen::Vector3d a1 = c1Tangents_.row(i).transpose();
    const Eigen::Vector3d ruling = c1Points_.row(i).transpose() - c2.point;
    residuals[3 * i] = n.dot(a1);
    residuals[3 * i + 1] = n.dot(c2.d1);
    residuals[3 * i + 2] = n.dot(ruling);
    if (!out) continue;
    for (int c = 0; c < 3; ++c) *out++ = a1[c];
    // d/dσ of the two σ-dependent rows; dσ/dε_k = 2 S(i,k) ε_k.
    const double dRow[2] = {n.dot(c2.d2), -n.dot(c2.d1)};
    const Eigen::Vector3d dN[2] = {c2.d1, ruling};
    for (int r = 0; r < 2; ++r) {
      for (int c = 0; c < 3; ++c) *out++ = dN[r][c];
      for (spline::EvaluationMatrix::InnerIterator it(tailWeights_, i); it; ++it)
        *out++ = dRow[r] * 2.0 * it.value() * x[shapeOffset_ + it.col()];
    }
  }
}

}  // namespace devsurf::terms
