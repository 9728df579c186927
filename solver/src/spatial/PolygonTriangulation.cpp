#include "devsurf/spatial/PolygonTriangulation.h"

#include <cmath>
#include <numeric>
#include <stdexcept>

#include <Eigen/Geometry>

namespace devsurf::spatial {

namespace {

double turnOf(const Eigen::Vector2d& a, const Eigen::Vector2d& b, const Eigen::Vector2d& c) {
  return (b - a).x() * (c - a).y() - (b - a).y() * (c - a).x();
}

}  // namespace

std::vector<std::array<int, 3>> triangulateSimplePolygon(const Eigen::MatrixX2d& loop) {
  const int n = static_cast<int>(loop.rows());
  if (n < 3) throw std::invalid_argument("triangulateSimplePolygon: a polygon needs at least 3 corners");
  double area2 = 0.0;
  for (int k = 0; k < n; ++k) area2 += turnOf(Eigen::Vector2d::Zero(), loop.row(k).transpose(), loop.row((k + 1) % n).transpose());
  const double orientation = area2 >= 0.0 ? 1.0 : -1.0;
  const double scale = (loop.colwise().maxCoeff() - loop.colwise().minCoeff()).squaredNorm();
  const double flat = 1e-14 * scale;
  std::vector<int> left(static_cast<std::size_t>(n));
  std::iota(left.begin(), left.end(), 0);
  std::vector<std::array<int, 3>> triangles;
  const auto at = [&loop](int i) { return Eigen::Vector2d(loop.row(i).transpose()); };
  // Scans on from the last ear clipped, so each clip costs one pass at most over the corners left
  // for the ear and one over them for its emptiness: O(n²) in all for ordinary polygons.
  std::size_t k = 0;
  while (left.size() > 3) {
    const std::size_t m = left.size();
    bool clipped = false;
    for (std::size_t tried = 0; tried < m && !clipped; ++tried, k = (k + 1) % m) {
      const int a = left[(k + m - 1) % m], b = left[k], c = left[(k + 1) % m];
      const Eigen::Vector2d A = at(a), B = at(b), C = at(c);
      if (orientation * turnOf(A, B, C) <= flat) continue;  // reflex or straight: not an ear
      bool empty = true;
      for (std::size_t j = 0; j < m && empty; ++j) {
        const int p = left[j];
        if (p == a || p == b || p == c) continue;
        const Eigen::Vector2d P = at(p);
        if ((P - A).squaredNorm() == 0.0 || (P - B).squaredNorm() == 0.0 || (P - C).squaredNorm() == 0.0) continue;
        empty = !(orientation * turnOf(A, B, P) >= 0.0 && orientation * turnOf(B, C, P) >= 0.0 &&
                  orientation * turnOf(C, A, P) >= 0.0);
      }
      if (!empty) continue;
      triangles.push_back({a, b, c});
      left.erase(left.begin() + static_cast<std::ptrdiff_t>(k));
      k = k % left.size();
      clipped = true;
    }
    if (clipped) continue;
    // Only straight corners left among the convex ones (collinear runs): clip one that keeps the
    // rest simple, as a zero-area triangle, rather than give up.
    for (std::size_t j = 0; j < m && !clipped; ++j) {
      const Eigen::Vector2d A = at(left[(j + m - 1) % m]), B = at(left[j]), C = at(left[(j + 1) % m]);
      if (std::abs(turnOf(A, B, C)) <= flat && (B - A).dot(C - B) > 0.0) {
        triangles.push_back({left[(j + m - 1) % m], left[j], left[(j + 1) % m]});
        left.erase(left.begin() + static_cast<std::ptrdiff_t>(j));
        k = j % left.size();
        clipped = true;
      }
    }
    if (!clipped) throw std::invalid_argument("triangulateSimplePolygon: the polygon is not simple (no ear left)");
  }
  triangles.push_back({left[0], left[1], left[2]});
  return triangles;
}

bool isConvexPolygon(const Eigen::MatrixX2d& loop) {
  const int n = static_cast<int>(loop.rows());
  if (n < 3) return false;
  const double scale = (loop.colwise().maxCoeff() - loop.colwise().minCoeff()).squaredNorm();
  int sign = 0;
  for (int k = 0; k < n; ++k) {
    const double t = turnOf(loop.row((k + n - 1) % n).transpose(), loop.row(k).transpose(), loop.row((k + 1) % n).transpose());
    if (std::abs(t) <= 1e-14 * scale) continue;
    const int s = t > 0 ? 1 : -1;
    if (sign == 0) sign = s;
    if (s != sign) return false;
  }
  return true;
}

Eigen::MatrixX2d polygonInItsPlane(const Eigen::MatrixX3d& corners) {
  const Eigen::Index n = corners.rows();
  if (n < 3) throw std::invalid_argument("polygonInItsPlane: a polygon needs at least 3 corners");
  Eigen::Vector3d normal = Eigen::Vector3d::Zero();
  for (Eigen::Index k = 0; k < n; ++k) normal += Eigen::Vector3d(corners.row(k)).cross(Eigen::Vector3d(corners.row((k + 1) % n)));
  if (normal.norm() == 0.0) normal = Eigen::Vector3d::UnitZ();
  normal.normalize();
  const Eigen::Vector3d u = normal.unitOrthogonal(), v = normal.cross(u);
  Eigen::MatrixX2d out(n, 2);
  for (Eigen::Index k = 0; k < n; ++k) out.row(k) << corners.row(k).dot(u), corners.row(k).dot(v);
  return out;
}

}  // namespace devsurf::spatial
