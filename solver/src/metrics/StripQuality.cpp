#include "devsurf/metrics/StripQuality.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace devsurf::metrics {

double warpAngleDeg(const Eigen::Vector3d& a, const Eigen::Vector3d& da, const Eigen::Vector3d& b,
                    const Eigen::Vector3d& db) {
  const Eigen::Vector3d ruling = b - a;
  const Eigen::Vector3d na = da.cross(ruling);
  const Eigen::Vector3d nb = db.cross(ruling);
  const double la = na.norm(), lb = nb.norm();
  const double scale = ruling.norm() * std::max(da.norm(), db.norm());
  if (la <= 1e-14 * scale || lb <= 1e-14 * scale) return 0.0;
  // atan2 of |sin| and |cos| is accurate near 0 (acos is not).
  const double sine = na.cross(nb).norm() / (la * lb);
  const double cosine = std::abs(na.dot(nb)) / (la * lb);
  return std::atan2(sine, cosine) * 180.0 / M_PI;
}

double developabilityResidual(const Eigen::Vector3d& a, const Eigen::Vector3d& da,
                              const Eigen::Vector3d& b, const Eigen::Vector3d& db) {
  const Eigen::Vector3d ruling = b - a;
  const double denominator = ruling.norm() * da.norm() * db.norm();
  if (denominator <= 1e-300) return 0.0;
  return std::abs(ruling.dot(da.cross(db))) / denominator;
}

namespace {

/// The metrics over `count` rulings whose ends and tangents `sample(i, da, db)` gives.
template <class Sample>
StripQuality measuredRulings(int count, const Sample& sample) {
  StripQuality q;
  q.rulings = count;
  double sum = 0.0;
  Eigen::Matrix<double, 3, 2> da, db;  // point and tangent of each boundary
  for (int i = 0; i < count; ++i) {
    sample(i, da, db);
    const Eigen::Vector3d pa = da.col(0), pb = db.col(0), ta = da.col(1), tb = db.col(1);
    const double warp = warpAngleDeg(pa, ta, pb, tb);
    q.warpAngleMaxDeg = std::max(q.warpAngleMaxDeg, warp);
    sum += warp;
    q.developabilityResidualMax = std::max(q.developabilityResidualMax, developabilityResidual(pa, ta, pb, tb));
  }
  q.warpAngleMeanDeg = sum / count;
  return q;
}

}  // namespace

StripQuality stripQuality(const spline::BSplineCurve& a, const spline::BSplineCurve& b,
                          int rulings) {
  if (rulings < 2) throw std::invalid_argument("stripQuality: need at least 2 rulings");
  const double u0 = a.knots.domainBegin(), u1 = a.knots.domainEnd();
  const spline::CurvePair pair(a, b);  // one basis evaluation for both when they share knots
  return measuredRulings(rulings, [&pair, u0, u1, rulings](int i, Eigen::Matrix<double, 3, 2>& da,
                                                            Eigen::Matrix<double, 3, 2>& db) {
    pair.derivatives(u0 + (u1 - u0) * static_cast<double>(i) / (rulings - 1), 1, da, db);
  });
}

StripQuality stripQuality(const spline::BasisTable& rulings, const spline::BSplineCurve& a,
                          const spline::BSplineCurve& b) {
  if (rulings.size() < 2 || rulings.derivatives() < 1)
    throw std::invalid_argument("stripQuality: the table needs at least 2 rulings and first derivatives");
  if (!rulings.fits(a) || !rulings.fits(b) || a.dimension() != 3 || b.dimension() != 3)
    throw std::invalid_argument("stripQuality: the curves do not fit the table's knot vector");
  return measuredRulings(rulings.size(), [&rulings, &a, &b](int i, Eigen::Matrix<double, 3, 2>& da,
                                                            Eigen::Matrix<double, 3, 2>& db) {
    rulings.evaluate(i, a.points, 1, da);
    rulings.evaluate(i, b.points, 1, db);
  });
}

}  // namespace devsurf::metrics
