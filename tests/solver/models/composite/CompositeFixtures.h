#pragma once

// Composite designs shared by the composite tests.

#include <algorithm>
#include <cmath>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "devsurf/io/CreasePattern.h"
#include "devsurf/models/composite/CompositeDesign.h"
#include "devsurf/models/composite/CompositeModel.h"

namespace devsurf::models::composite::fixtures {

/// Largest valley and most negative mountain fold angle (degrees) of the model's crease pattern,
/// measured from its face normals (io::measuredFoldAngles), not from the hinge term the slider
/// pulls with.
inline std::pair<double, double> measuredValleyAndMountain(const CompositeModel& model) {
  double valley = 0.0, mountain = 0.0;
  for (const auto& a : io::measuredFoldAngles(model.creasePattern()))
    if (a) {
      valley = std::max(valley, *a);
      mountain = std::min(mountain, *a);
    }
  return {valley, mountain};
}

inline spline::BSplineCurve cubicThrough(const Eigen::MatrixXd& points) {
  spline::BSplineCurve c;
  c.knots = spline::KnotVector::clampedUniform(3, static_cast<int>(points.rows()));
  c.points = points;
  return c;
}

inline CompositeEdge sEdge(int v0, int v1, const Eigen::MatrixXd& points, CreaseKind crease = CreaseKind::None) {
  CompositeEdge e;
  e.v0 = v0;
  e.v1 = v1;
  e.type = EdgeType::Spline;
  e.curve = cubicThrough(points);
  e.crease = crease;
  return e;
}

inline CompositeEdge rEdge(int v0, int v1, CreaseKind crease = CreaseKind::None) {
  CompositeEdge e;
  e.v0 = v0;
  e.v1 = v1;
  e.type = EdgeType::Ruling;
  e.crease = crease;
  return e;
}

/// Control points of a planar curve in z = 0 running along +x (a gentle S-free arc).
inline Eigen::MatrixXd planarCrease(int n = 6) {
  Eigen::MatrixXd p(n, 3);
  for (int i = 0; i < n; ++i) {
    const double t = static_cast<double>(i) / (n - 1);
    p.row(i) << 3.0 * t, 0.6 * std::sin(M_PI * t) + 0.2 * t, 0.0;
  }
  return p;
}

/// Two cylinders sharing the planar crease c (in z = 0): side 1 ruled along d1 = (0, cos φ, sin φ)
/// (on the +y side), side 2 along d2 = (0, −cos φ, sin φ): the mirror image of side 1's tangent
/// planes in the crease's osculating plane, so the curved-fold condition (eq. 7) holds exactly
/// and both strips are exactly developable. Both sides rise: a valley seen from +z.
///
/// Vertices: 0 = c(0), 1 = c(1), 2 = c(1)+d1, 3 = c(0)+d1, 4 = c(0)+d2, 5 = c(1)+d2.
/// Edges: 0 crease S 0→1, 1 R 1→2, 2 S 2→3 (c + d1 reversed), 3 R 3→0, 4 R 0→4, 5 S 4→5 (c + d2), 6 R 5→1.
/// Faces: [0, 1, 2, 3] (side 1), [4, 5, 6, 0] (side 2, crease reversed).
inline CompositeDesign foldedCylinders(double foldDeg = 35.0, CreaseKind crease = CreaseKind::Fold) {
  const double phi = foldDeg * M_PI / 180.0;
  const Eigen::RowVector3d d1(0.0, std::cos(phi), std::sin(phi)), d2(0.0, -std::cos(phi), std::sin(phi));
  const Eigen::MatrixXd c = planarCrease();
  const int n = static_cast<int>(c.rows());
  const Eigen::MatrixXd b1 = c.rowwise() + d1, b2 = c.rowwise() + d2;
  CompositeDesign d;
  d.vertices.resize(6, 3);
  d.vertices.row(0) = c.row(0);
  d.vertices.row(1) = c.row(n - 1);
  d.vertices.row(2) = b1.row(n - 1);
  d.vertices.row(3) = b1.row(0);
  d.vertices.row(4) = b2.row(0);
  d.vertices.row(5) = b2.row(n - 1);
  d.edges = {sEdge(0, 1, c, crease), rEdge(1, 2), sEdge(2, 3, b1.colwise().reverse()), rEdge(3, 0),
             rEdge(0, 4), sEdge(4, 5, b2), rEdge(5, 1)};
  d.faces = {{0, 1, 2, 3}, {4, 5, 6, 0}};
  return d;
}

/// A flat square [0,2]² split by one curved crease from (1,0) to (1,2) into two strips
/// (the setting of 000_… Fig. 8). Vertices: 0 (0,0), 1 (1,0), 2 (2,0), 3 (2,2), 4 (1,2), 5 (0,2).
/// Edges: 0 crease S 1→4, 1 R 0→1, 2 R 1→2, 3 S 2→3, 4 R 3→4, 5 R 4→5, 6 S 5→0.
/// Faces: [0, 5, 6, 1] (left), [2, 3, 4, 0] (right).
inline CompositeDesign flatSheet(CreaseKind crease = CreaseKind::Fold) {
  CompositeDesign d;
  d.vertices.resize(6, 3);
  d.vertices << 0, 0, 0, 1, 0, 0, 2, 0, 0, 2, 2, 0, 1, 2, 0, 0, 2, 0;
  auto line = [](const Eigen::RowVector3d& p, const Eigen::RowVector3d& q) {
    Eigen::MatrixXd m(6, 3);
    for (int i = 0; i < 6; ++i) m.row(i) = p + (q - p) * (i / 5.0);
    return m;
  };
  Eigen::MatrixXd curve(6, 3);
  for (int i = 0; i < 6; ++i) {
    const double t = i / 5.0;
    curve.row(i) << 1.0 + 1.6 * t * (1 - t), 2.0 * t, 0.0;
  }
  d.edges = {sEdge(1, 4, curve, crease),
             rEdge(0, 1),
             rEdge(1, 2),
             sEdge(2, 3, line(d.vertices.row(2), d.vertices.row(3))),
             rEdge(3, 4),
             rEdge(4, 5),
             sEdge(5, 0, line(d.vertices.row(5), d.vertices.row(0)))};
  d.faces = {{0, 5, 6, 1}, {2, 3, 4, 0}};
  return d;
}

}  // namespace devsurf::models::composite::fixtures
