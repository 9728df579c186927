#include "devsurf/terms/StripFootPoints.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include <Eigen/Dense>

#include "devsurf/spline/Basis.h"

namespace devsurf::terms {
namespace {

/// Parameter in [0, 1] of the point of segment [p, q] closest to y.
double segmentParameter(const Eigen::Vector3d& p, const Eigen::Vector3d& q, const Eigen::Vector3d& y) {
  const Eigen::Vector3d d = q - p;
  const double len2 = d.squaredNorm();
  if (len2 <= 0.0) return 0.0;
  return std::clamp((y - p).dot(d) / len2, 0.0, 1.0);
}

}  // namespace

StripFootPoints::StripFootPoints(spline::KnotVector knots, Eigen::VectorXd weights, int offsetA, int offsetB,
                                 Eigen::MatrixX3d points)
    : knots_(std::move(knots)),
      weights_(std::move(weights)),
      n_(knots_.numControlPoints()),
      offsetA_(offsetA),
      offsetB_(offsetB),
      points_(std::move(points)) {
  if (points_.rows() == 0) throw std::invalid_argument("StripFootPoints: no reference points");
  if (!points_.allFinite()) throw std::invalid_argument("StripFootPoints: reference points must be finite");
  if (weights_.size() != 0 && weights_.size() != n_)
    throw std::invalid_argument("StripFootPoints: expected " + std::to_string(n_) + " weights");
  if (offsetA_ < 0 || offsetB_ < 0) throw std::invalid_argument("StripFootPoints: negative offset");
  const std::size_t N = static_cast<std::size_t>(points_.rows());
  u_.assign(N, knots_.domainBegin());
  v_.assign(N, 0.0);
  basis_.assign(N * static_cast<std::size_t>(n_), 0.0);
  derivative_.assign(N * static_cast<std::size_t>(n_), 0.0);
}

double StripFootPoints::wrapOrClamp(double u) const {
  const double u0 = knots_.domainBegin(), u1 = knots_.domainEnd();
  if (knots_.kind() == spline::KnotKind::Periodic) {
    const double period = u1 - u0;
    u = u0 + std::fmod(u - u0, period);
    if (u < u0) u += period;
    return u;
  }
  return std::clamp(u, u0, u1);
}

void StripFootPoints::basisAt(double u, double* r, double* dr, double* ddr) const {
  std::fill(r, r + n_, 0.0);
  std::fill(dr, dr + n_, 0.0);
  if (ddr) std::fill(ddr, ddr + n_, 0.0);
  const spline::BasisValues bv = spline::basisFunctions(knots_, u, 2);
  const int cols = static_cast<int>(bv.controlIndex.size());
  if (weights_.size() == 0) {
    for (int c = 0; c < cols; ++c) {
      r[bv.controlIndex[c]] += bv.values(0, c);
      dr[bv.controlIndex[c]] += bv.values(1, c);
      if (ddr) ddr[bv.controlIndex[c]] += bv.values(2, c);
    }
    return;
  }
  // R_i = w_i N_i / W, R_i′ = w_i (N_i′ W − N_i W′) / W²,
  // R_i″ = w_i ((N_i″ W − N_i W″) W − 2 W′ (N_i′ W − N_i W′)) / W³ with W = Σ w_k N_k.
  double W = 0.0, dW = 0.0, ddW = 0.0;
  for (int c = 0; c < cols; ++c) {
    const double w = weights_[bv.controlIndex[c]];
    W += w * bv.values(0, c);
    dW += w * bv.values(1, c);
    ddW += w * bv.values(2, c);
  }
  for (int c = 0; c < cols; ++c) {
    const double w = weights_[bv.controlIndex[c]];
    const double N = bv.values(0, c), dN = bv.values(1, c), ddN = bv.values(2, c);
    r[bv.controlIndex[c]] += w * N / W;
    dr[bv.controlIndex[c]] += w * (dN * W - N * dW) / (W * W);
    if (ddr) ddr[bv.controlIndex[c]] += w * ((ddN * W - N * ddW) * W - 2.0 * dW * (dN * W - N * dW)) / (W * W * W);
  }
}

Eigen::Vector3d StripFootPoints::combine(const Eigen::VectorXd& x, int offset, const double* w) const {
  Eigen::Vector3d p = Eigen::Vector3d::Zero();
  for (int i = 0; i < n_; ++i)
    if (w[i] != 0.0) p += w[i] * x.segment<3>(offset + 3 * i);
  return p;
}

Eigen::Vector3d StripFootPoints::surfacePoint(const Eigen::VectorXd& x, int j) const {
  return (1.0 - v(j)) * a(x, j) + v(j) * b(x, j);
}

void StripFootPoints::update(const Eigen::VectorXd& x) {
  Eigen::VectorXd control(6 * n_);
  control << x.segment(offsetA_, 3 * n_), x.segment(offsetB_, 3 * n_);
  if (projections_ > 0 && control == lastControl_) return;
  lastControl_ = control;
  ++projections_;

  // Rulings to scan.
  const bool closed = knots_.kind() == spline::KnotKind::Periodic;
  const int S = scanSamples > 1 ? scanSamples : std::max(64, 8 * n_);
  const double u0 = knots_.domainBegin(), u1 = knots_.domainEnd();
  std::vector<double> scanU(static_cast<std::size_t>(S));
  std::vector<Eigen::Vector3d> scanA(scanU.size()), scanB(scanU.size());
  std::vector<double> r(static_cast<std::size_t>(n_)), dr(static_cast<std::size_t>(n_)), ddr(static_cast<std::size_t>(n_));
  for (int s = 0; s < S; ++s) {
    const double u = u0 + (u1 - u0) * s / (closed ? S : S - 1);
    basisAt(u, r.data(), dr.data(), nullptr);
    scanU[static_cast<std::size_t>(s)] = u;
    scanA[static_cast<std::size_t>(s)] = combine(x, offsetA_, r.data());
    scanB[static_cast<std::size_t>(s)] = combine(x, offsetB_, r.data());
  }

  for (int j = 0; j < count(); ++j) {
    const Eigen::Vector3d q = points_.row(j).transpose();
    double bestDistance = std::numeric_limits<double>::infinity(), u = u0, v = 0.0;
    for (std::size_t s = 0; s < scanU.size(); ++s) {
      const double t = segmentParameter(scanA[s], scanB[s], q);
      const double d = ((1.0 - t) * scanA[s] + t * scanB[s] - q).squaredNorm();
      if (d < bestDistance) bestDistance = d, u = scanU[s], v = t;
    }
    const double startU = u, startV = v;
    // Newton on F(u, v) = ½|s(u, v) − q|² (Gauss–Newton where the Hessian is not positive
    // definite), backtracking until F decreases; u clamped (wrapped when closed), v in [0, 1].
    auto distanceAt = [this, &x, &q, &r, &dr](double uu, double vv) {
      basisAt(uu, r.data(), dr.data(), nullptr);
      return ((1.0 - vv) * combine(x, offsetA_, r.data()) + vv * combine(x, offsetB_, r.data()) - q).squaredNorm();
    };
    double current = bestDistance;
    for (int step = 0; step < refinementSteps; ++step) {
      basisAt(u, r.data(), dr.data(), ddr.data());
      const Eigen::Vector3d pa = combine(x, offsetA_, r.data()), pb = combine(x, offsetB_, r.data());
      const Eigen::Vector3d ta = combine(x, offsetA_, dr.data()), tb = combine(x, offsetB_, dr.data());
      const Eigen::Vector3d ca = combine(x, offsetA_, ddr.data()), cb = combine(x, offsetB_, ddr.data());
      const Eigen::Vector3d residual = (1.0 - v) * pa + v * pb - q;
      const Eigen::Vector3d su = (1.0 - v) * ta + v * tb, sv = pb - pa;
      const Eigen::Vector3d suu = (1.0 - v) * ca + v * cb, suv = tb - ta;
      const Eigen::Vector2d gradient(su.dot(residual), sv.dot(residual));
      const double huu = su.dot(su) + suu.dot(residual), guu = su.dot(su);
      // Active set: a bound that the descent direction pushes against holds its coordinate.
      const bool closedCurve = knots_.kind() == spline::KnotKind::Periodic;
      const bool holdV = (v <= 0.0 && gradient[1] > 0.0) || (v >= 1.0 && gradient[1] < 0.0);
      const bool holdU = !closedCurve && ((u <= u0 && gradient[0] > 0.0) || (u >= u1 && gradient[0] < 0.0));
      if (holdU && holdV) break;  // a corner of the strip
      Eigen::Vector2d delta = Eigen::Vector2d::Zero();
      if (holdV) {
        delta[0] = -gradient[0] / (huu > 0.0 ? huu : std::max(guu, 1e-300));
      } else if (holdU) {
        delta[1] = -gradient[1] / std::max(sv.dot(sv), 1e-300);
      } else {
        Eigen::Matrix2d H;
        H << huu, su.dot(sv) + suv.dot(residual), su.dot(sv) + suv.dot(residual), sv.dot(sv);
        if (!(H(0, 0) > 0.0 && H.determinant() > 1e-14 * H(0, 0) * H(1, 1))) {
          H << guu, su.dot(sv), su.dot(sv), sv.dot(sv);
          H.diagonal() *= 1.0 + 1e-9;
          if (!(H.determinant() > 1e-300)) break;
        }
        delta = -H.ldlt().solve(gradient);
      }
      if (!delta.allFinite()) break;
      double scale = 1.0, trialU = u, trialV = v, trial = current;
      for (int halving = 0; halving < 30; ++halving, scale *= 0.5) {
        trialU = wrapOrClamp(u + scale * delta[0]);
        trialV = std::clamp(v + scale * delta[1], 0.0, 1.0);
        trial = distanceAt(trialU, trialV);
        if (trial <= current) break;
      }
      if (!(trial <= current)) break;
      const bool converged = std::abs(trialU - u) <= 1e-13 * (u1 - u0) && std::abs(trialV - v) <= 1e-13;
      u = trialU, v = trialV, current = trial;
      if (converged) break;
    }
    // Keep the better of the scan start and the refinement (a step may only ever improve).
    if (!(current <= bestDistance)) u = startU, v = startV;
    basisAt(u, r.data(), dr.data(), nullptr);
    u_[static_cast<std::size_t>(j)] = u;
    v_[static_cast<std::size_t>(j)] = v;
    std::copy(r.begin(), r.end(), basis_.begin() + static_cast<std::ptrdiff_t>(j) * n_);
    std::copy(dr.begin(), dr.end(), derivative_.begin() + static_cast<std::ptrdiff_t>(j) * n_);
  }
}

}  // namespace devsurf::terms
