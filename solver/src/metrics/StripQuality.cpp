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

StripQuality stripQuality(const spline::BSplineCurve& a, const spline::BSplineCurve& b,
                          int rulings) {
  if (rulings < 2) throw std::invalid_argument("stripQuality: need at least 2 rulings");
  StripQuality q;
  q.rulings = rulings;
  const double u0 = a.knots.domainBegin(), u1 = a.knots.domainEnd();
  double sum = 0.0;
  for (int i = 0; i < rulings; ++i) {
    const double u = u0 + (u1 - u0) * static_cast<double>(i) / (rulings - 1);
    const Eigen::Vector3d pa = a.evaluate(u, 0), pb = b.evaluate(u, 0);
    const Eigen::Vector3d ta = a.evaluate(u, 1), tb = b.evaluate(u, 1);
    const double warp = warpAngleDeg(pa, ta, pb, tb);
    q.warpAngleMaxDeg = std::max(q.warpAngleMaxDeg, warp);
    sum += warp;
    q.developabilityResidualMax =
        std::max(q.developabilityResidualMax, developabilityResidual(pa, ta, pb, tb));
  }
  q.warpAngleMeanDeg = sum / rulings;
  return q;
}

}  // namespace devsurf::metrics
