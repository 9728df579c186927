#include "devsurf/terms/ControlPolygonFairnessTerm.h"

#include <stdexcept>

namespace devsurf::terms {

ControlPolygonFairnessTerm::ControlPolygonFairnessTerm(std::string name, int offset, int numPoints,
                                                       int dimension, bool closed)
    : Term(std::move(name)),
      offset_(offset),
      numPoints_(numPoints),
      dimension_(dimension),
      closed_(closed) {
  if (dimension < 1) throw std::invalid_argument("ControlPolygonFairnessTerm: dimension < 1");
  if (closed && numPoints < 3)
    throw std::invalid_argument("ControlPolygonFairnessTerm: a closed polygon needs 3 points");
}

int ControlPolygonFairnessTerm::rowsPerCoordinate() const {
  if (closed_) return numPoints_;
  return numPoints_ >= 3 ? numPoints_ - 2 : 0;
}

void ControlPolygonFairnessTerm::stencil(int s, int& prev, int& mid, int& next) const {
  if (closed_) {
    mid = s;
    prev = (s + numPoints_ - 1) % numPoints_;
    next = (s + 1) % numPoints_;
  } else {
    prev = s;
    mid = s + 1;
    next = s + 2;
  }
}

void ControlPolygonFairnessTerm::jacobianStructure(
    std::vector<engine::JacobianEntry>& entries) const {
  for (int s = 0; s < rowsPerCoordinate(); ++s) {
    int p, m, n;
    stencil(s, p, m, n);
    for (int c = 0; c < dimension_; ++c) {
      const int row = s * dimension_ + c;
      entries.push_back({row, offset_ + p * dimension_ + c});
      entries.push_back({row, offset_ + m * dimension_ + c});
      entries.push_back({row, offset_ + n * dimension_ + c});
    }
  }
}

void ControlPolygonFairnessTerm::evaluate(const Eigen::VectorXd& x, double* residuals,
                                          double* jacobian) const {
  for (int s = 0; s < rowsPerCoordinate(); ++s) {
    int p, m, n;
    stencil(s, p, m, n);
    for (int c = 0; c < dimension_; ++c) {
      const int row = s * dimension_ + c;
      residuals[row] = x[offset_ + p * dimension_ + c] - 2.0 * x[offset_ + m * dimension_ + c] +
                       x[offset_ + n * dimension_ + c];
      if (jacobian) {
        jacobian[3 * row] = 1.0;
        jacobian[3 * row + 1] = -2.0;
        jacobian[3 * row + 2] = 1.0;
      }
    }
  }
}

}  // namespace devsurf::terms
