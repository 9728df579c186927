#include "devsurf/terms/TriangleOrientationTerm.h"

#include "devsurf/terms/Hinge.h"

#include <cmath>
#include <stdexcept>

namespace devsurf::terms {

TriangleOrientationTerm::TriangleOrientationTerm(std::string name, int offset, std::vector<std::array<int, 3>> triangles,
                                                 std::vector<double> minArea, int stride)
    : Term(std::move(name)), offset_(offset), stride_(stride) {
  if (stride < 2) throw std::invalid_argument("TriangleOrientationTerm: stride must be ≥ 2");
  if (triangles.size() != minArea.size())
    throw std::invalid_argument("TriangleOrientationTerm: one minimum area per triangle");
  for (std::size_t t = 0; t < triangles.size(); ++t) {
    const auto& tri = triangles[t];
    if (tri[0] == tri[1] || tri[1] == tri[2] || tri[0] == tri[2])
      throw std::invalid_argument("TriangleOrientationTerm: a triangle uses one vertex twice");
    if (!(minArea[t] > 0.0) || !std::isfinite(minArea[t])) continue;
    triangles_.push_back(tri);
    inverseMin_.push_back(1.0 / minArea[t]);
  }
}

void TriangleOrientationTerm::jacobianStructure(std::vector<engine::JacobianEntry>& entries) const {
  for (int t = 0; t < numResiduals(); ++t)
    for (int v : triangles_[t])
      for (int c = 0; c < 2; ++c) entries.push_back({t, offset_ + stride_ * v + c});
}

void TriangleOrientationTerm::evaluate(const Eigen::VectorXd& x, double* residuals, double* jacobian) const {
  for (int t = 0; t < numResiduals(); ++t) {
    const auto& tri = triangles_[t];
    const Eigen::Vector2d p0 = x.segment<2>(offset_ + stride_ * tri[0]), p1 = x.segment<2>(offset_ + stride_ * tri[1]),
                          p2 = x.segment<2>(offset_ + stride_ * tri[2]);
    const double area = 0.5 * ((p1.x() - p0.x()) * (p2.y() - p0.y()) - (p2.x() - p0.x()) * (p1.y() - p0.y()));
    const double g = 1.0 - area * inverseMin_[t];
    residuals[t] = hingeResidual(g);
    if (jacobian) {
      // ∂A/∂p0 = ½(y1 − y2, x2 − x1), ∂A/∂p1 = ½(y2 − y0, x0 − x2), ∂A/∂p2 = ½(y0 − y1, x1 − x0).
      const double s = -0.5 * hingeSlope(g) * inverseMin_[t];
      double* out = jacobian + 6 * t;
      out[0] = s * (p1.y() - p2.y());
      out[1] = s * (p2.x() - p1.x());
      out[2] = s * (p2.y() - p0.y());
      out[3] = s * (p0.x() - p2.x());
      out[4] = s * (p0.y() - p1.y());
      out[5] = s * (p1.x() - p0.x());
    }
  }
}

}  // namespace devsurf::terms
