#pragma once

#include <Eigen/Core>

#include "devsurf/spline/BSplineCurve.h"
#include "devsurf/spline/BasisTable.h"

namespace devsurf::metrics {

/// Warp angle of the ruling a(u)b(u) in degrees (001_… §5): the angle between the surface
/// normals a′×(b−a) at a(u) and b′×(b−a) at b(u), taken between lines (in [0°, 90°]) so that
/// the orientation of the parametrization does not matter.
/// \note Where a normal vanishes (a cone's apex, a cusp) the ruling has one tangent plane and the
///       warp angle is 0.
double warpAngleDeg(const Eigen::Vector3d& a, const Eigen::Vector3d& da, const Eigen::Vector3d& b,
                    const Eigen::Vector3d& db);

/// Scale-free developability residual |det(b−a, a′, b′)| / (|b−a| |a′| |b′|) (0 where a factor
/// vanishes).
double developabilityResidual(const Eigen::Vector3d& a, const Eigen::Vector3d& da,
                              const Eigen::Vector3d& b, const Eigen::Vector3d& db);

/// The strip metrics the reports carry, over `rulings` rulings equally spaced in u.
struct StripQuality {
  double warpAngleMaxDeg = 0.0;            ///< report name warp_angle_max_deg
  double warpAngleMeanDeg = 0.0;           ///< report name warp_angle_mean_deg
  double developabilityResidualMax = 0.0;  ///< report name developability_residual_max
  int rulings = 0;
};

/// @param[in] a, b  the boundary curves (same parameter domain)
/// @param[in] rulings  number of rulings, equally spaced over the domain, ends included (≥ 2)
StripQuality stripQuality(const spline::BSplineCurve& a, const spline::BSplineCurve& b,
                          int rulings = 1000);

/// The same metrics at the parameters of a BasisTable (≥ 1 derivative tabled), for loops that
/// measure one strip every iterate: a and b must fit the table (spline::BasisTable::fits).
/// @throws std::invalid_argument if they do not, or the table has fewer than 2 parameters
StripQuality stripQuality(const spline::BasisTable& rulings, const spline::BSplineCurve& a,
                          const spline::BSplineCurve& b);

}  // namespace devsurf::metrics
