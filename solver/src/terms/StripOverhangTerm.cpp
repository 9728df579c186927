#include "devsurf/terms/StripOverhangTerm.h"

#include <cassert>
#include <cmath>
#include <stdexcept>
#include <utility>

#include "devsurf/spatial/MatrixRowsKdTree.h"
#include "devsurf/spline/Basis.h"

namespace devsurf::terms {

struct StripOverhangTerm::Index {
  explicit Index(const Eigen::MatrixX3d& points)
      : rows{points}, tree(3, rows, nanoflann::KDTreeSingleIndexAdaptorParams(16)) {}
  spatial::MatrixRows rows;
  spatial::MatrixRowsKdTree tree;
};

StripOverhangTerm::StripOverhangTerm(std::string name, const spline::KnotVector& knots, Eigen::VectorXd weights,
                                     int offsetA, int offsetB, Eigen::MatrixX3d points, double reach, int samplesU,
                                     int samplesV)
    : Term(std::move(name)), n_(knots.numControlPoints()), offsetA_(offsetA), offsetB_(offsetB), reach_(reach),
      points_(std::move(points)) {
  if (points_.rows() == 0 || !points_.allFinite())
    throw std::invalid_argument("StripOverhangTerm: the reference points must be finite and not empty");
  if (!(std::isfinite(reach_) && reach_ > 0.0)) throw std::invalid_argument("StripOverhangTerm: reach must be > 0");
  if (samplesU < 2 || samplesV < 2) throw std::invalid_argument("StripOverhangTerm: at least 2 × 2 samples");
  if (weights.size() != 0 && (weights.size() != n_ || !(weights.array() > 0.0).all()))
    throw std::invalid_argument("StripOverhangTerm: one positive weight per control point, or none");
  index_ = std::make_unique<Index>(points_);
  const double u0 = knots.domainBegin(), u1 = knots.domainEnd();
  const bool closed = knots.kind() == spline::KnotKind::Periodic;
  support_ = knots.degree() + 1;
  const int count = samplesU * samplesV;
  v_.reserve(static_cast<std::size_t>(count));
  supportIndex_.reserve(static_cast<std::size_t>(count * support_));
  basis_.reserve(static_cast<std::size_t>(count * support_));
  for (int i = 0; i < samplesU; ++i) {
    // A closed strip's last sample would repeat its first.
    const double u = u0 + (u1 - u0) * i / (closed ? samplesU : samplesU - 1);
    const spline::BasisValues bv = spline::basisFunctions(knots, u, 0);
    assert(static_cast<int>(bv.controlIndex.size()) == support_ && "a span has degree + 1 basis functions");
    double W = 0.0;
    for (int c = 0; c < support_; ++c)
      W += (weights.size() ? weights[bv.controlIndex[static_cast<std::size_t>(c)]] : 1.0) * bv.values(0, c);
    for (int j = 0; j < samplesV; ++j) {
      for (int c = 0; c < support_; ++c) {
        const int control = bv.controlIndex[static_cast<std::size_t>(c)];
        supportIndex_.push_back(control);
        basis_.push_back((weights.size() ? weights[control] : 1.0) * bv.values(0, c) / W);
      }
      v_.push_back(static_cast<double>(j) / (samplesV - 1));
    }
  }
  nearest_ = Eigen::MatrixX3d::Zero(count, 3);
}

StripOverhangTerm::~StripOverhangTerm() = default;

void StripOverhangTerm::jacobianStructure(std::vector<engine::JacobianEntry>& entries) const {
  for (int k = 0; k < samples(); ++k)
    for (int c = 0; c < 3; ++c)
      for (int t = 0; t < support_; ++t) {
        const int i = supportIndex_[static_cast<std::size_t>(k * support_ + t)];
        for (int d = 0; d < 3; ++d) {
          entries.push_back({3 * k + c, offsetA_ + 3 * i + d});
          entries.push_back({3 * k + c, offsetB_ + 3 * i + d});
        }
      }
}

Eigen::Vector3d StripOverhangTerm::samplePoint(const Eigen::VectorXd& x, int k) const {
  Eigen::Vector3d a = Eigen::Vector3d::Zero(), b = Eigen::Vector3d::Zero();
  for (int t = 0; t < support_; ++t) {
    const std::size_t slot = static_cast<std::size_t>(k * support_ + t);
    const int i = supportIndex_[slot];
    a += basis_[slot] * x.segment<3>(offsetA_ + 3 * i);
    b += basis_[slot] * x.segment<3>(offsetB_ + 3 * i);
  }
  const double v = v_[static_cast<std::size_t>(k)];
  return (1.0 - v) * a + v * b;
}

void StripOverhangTerm::linearizeAt(const Eigen::VectorXd& x) {
  for (int k = 0; k < samples(); ++k) {
    const Eigen::Vector3d s = samplePoint(x, k);
    std::size_t found = 0;
    double squared = 0.0;
    index_->tree.knnSearch(s.data(), 1, &found, &squared);
    nearest_.row(k) = points_.row(static_cast<Eigen::Index>(found));
  }
}

void StripOverhangTerm::evaluate(const Eigen::VectorXd& x, double* residuals, double* jacobian) const {
  for (int k = 0; k < samples(); ++k) {
    const Eigen::Vector3d d = samplePoint(x, k) - nearest_.row(k).transpose();
    const double length = d.norm();
    // r = d (1 − ρ/|d|) beyond the reach; dr/ds = (1 − ρ/|d|) I + ρ d dᵀ/|d|³.
    Eigen::Matrix3d ds = Eigen::Matrix3d::Zero();
    Eigen::Vector3d r = Eigen::Vector3d::Zero();
    if (length > reach_) {
      r = d * (1.0 - reach_ / length);
      ds = (1.0 - reach_ / length) * Eigen::Matrix3d::Identity() + reach_ / (length * length * length) * d * d.transpose();
    }
    for (int c = 0; c < 3; ++c) residuals[3 * k + c] = r[c];
    if (!jacobian) continue;
    const double v = v_[static_cast<std::size_t>(k)];
    for (int c = 0; c < 3; ++c)
      for (int t = 0; t < support_; ++t) {
        const double r = basis_[static_cast<std::size_t>(k * support_ + t)];
        for (int e = 0; e < 3; ++e) {
          *jacobian++ = ds(c, e) * (1.0 - v) * r;
          *jacobian++ = ds(c, e) * v * r;
        }
      }
  }
}

}  // namespace devsurf::terms
