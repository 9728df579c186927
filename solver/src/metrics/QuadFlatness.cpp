#include "devsurf/metrics/QuadFlatness.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>

namespace devsurf::metrics {

double quadFlatness(const Eigen::Vector3d& p0, const Eigen::Vector3d& p1, const Eigen::Vector3d& p2,
                    const Eigen::Vector3d& p3, double tiny) {
  double e[4] = {(p1 - p0).norm(), (p2 - p1).norm(), (p3 - p2).norm(), (p0 - p3).norm()};
  std::sort(e, e + 4);
  if (e[0] <= tiny) return 0.0;
  const Eigen::Vector3d d1 = p2 - p0, d2 = p3 - p1;
  const Eigen::Vector3d c = d1.cross(d2);
  // Parallel diagonals (or one of no length) lie in one plane with all four corners: planar.
  // (The distance between the two parallel lines says nothing about planarity: four corners of a
  // flat polygon such as (100,0), (85,40), (70,40), (70,60) have parallel diagonals 12 apart.)
  // Parallel up to rounding counts: d1 and d2 carry errors of ~ε × the coordinates' size, and
  // so does c's direction then, which would make the distance anything up to the lines' gap.
  const double size = std::max({p0.cwiseAbs().maxCoeff(), p1.cwiseAbs().maxCoeff(), p2.cwiseAbs().maxCoeff(),
                                p3.cwiseAbs().maxCoeff()});
  const double roundoff = 64.0 * std::numeric_limits<double>::epsilon() * size * (d1.norm() + d2.norm());
  if (c.norm() <= std::max(1e-14 * d1.norm() * d2.norm(), roundoff)) return 0.0;
  const double dist = std::abs((p1 - p0).dot(c)) / c.norm();
  return dist / (0.5 * (e[0] + e[1]));
}

}  // namespace devsurf::metrics
