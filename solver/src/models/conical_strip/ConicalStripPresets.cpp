#include "devsurf/models/conical_strip/ConicalStripPresets.h"

#include <cmath>

namespace devsurf::models::conical_strip {

ConicalStripDesign figure11LikeDesign() {
  constexpr double kPi = 3.14159265358979323846;
  constexpr int kControlPoints = 40;
  constexpr double kWobble = 0.3;
  Eigen::MatrixXd p(kControlPoints, 3), q(kControlPoints, 3);
  for (int k = 0; k < kControlPoints; ++k) {
    const double t = 2.0 * kPi * k / (kControlPoints - 1);
    p.row(k) << 16.0 * std::cos(t), 16.0 * std::sin(t), 2.0 * t + kWobble * std::sin(2.0 * t);
    q.row(k) << 19.0 * std::cos(t), 19.0 * std::sin(t), 2.0 * t + 0.5 + kWobble * std::cos(2.0 * t);
  }
  ConicalStripDesign d;
  d.p.knots = spline::KnotVector::clampedUniform(3, kControlPoints);
  d.p.points = p;
  d.q.knots = spline::KnotVector::clampedUniform(3, kControlPoints);
  d.q.points = q;
  d.np = 55;
  d.nq = 65;
  d.h3 = 4.0;
  d.h4 = 4.0;
  d.ra = 1.2;
  d.objective = Objective::NormalVariation;
  d.g1 = true;
  return d;
}

}  // namespace devsurf::models::conical_strip
