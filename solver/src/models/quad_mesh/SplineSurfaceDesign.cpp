// The design of a developable spline surface (004_… §4, Algorithm 2): S^k(M) of a control net.
#include <cmath>
#include <stdexcept>
#include <string>

#include "devsurf/models/quad_mesh/QuadMeshDesign.h"
#include "devsurf/spline/CubicSubdivision.h"

namespace devsurf::models::quad_mesh {

QuadMeshDesign splineSurfaceDesign(ControlNet net) {
  if (net.rows < 4 || net.columns < 4)
    throw std::invalid_argument("control: a bicubic net needs at least 4 rows and 4 columns, got " +
                                std::to_string(net.rows) + " × " + std::to_string(net.columns));
  if (net.rounds < 0 || net.rounds > 4)
    throw std::invalid_argument("control.rounds: 0 … 4, got " + std::to_string(net.rounds));
  if (net.points.rows() != static_cast<Eigen::Index>(net.rows) * net.columns)
    throw std::invalid_argument("control.points: " + std::to_string(net.rows * net.columns) + " expected, got " +
                                std::to_string(net.points.rows()));
  if (!net.points.allFinite()) throw std::invalid_argument("control.points: every coordinate must be a finite number");
  const int R = spline::cubicSubdividedCount(net.rows, net.rounds);
  const int C = spline::cubicSubdividedCount(net.columns, net.rounds);
  QuadMeshDesign d;
  d.mesh = spline::cubicGridSubdivisionMatrix(net.rows, net.columns, net.rounds) * net.points;
  for (int r = 0; r + 1 < R; ++r)
    for (int c = 0; c + 1 < C; ++c) {
      const int a = r * C + c;
      d.faces.push_back({a, a + 1, a + C + 1, a + C});
    }
  d.variable = VariableMeshes::Both;
  d.control = std::move(net);
  return d;
}

}  // namespace devsurf::models::quad_mesh
