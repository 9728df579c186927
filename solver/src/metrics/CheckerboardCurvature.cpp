#include "devsurf/metrics/CheckerboardCurvature.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>
#include <tuple>
#include <utility>

#include <Eigen/Geometry>
#include <Eigen/LU>

namespace devsurf::metrics {
namespace {

/// A unit null vector of the 2×2 matrix A − λI (an eigenvector of A for λ), or zero when A − λI
/// vanishes up to `tiny`.
Eigen::Vector2d eigenvector(const Eigen::Matrix2d& A, double lambda, double tiny) {
  const Eigen::Vector2d fromRow0(A(0, 1), lambda - A(0, 0));
  const Eigen::Vector2d fromRow1(lambda - A(1, 1), A(1, 0));
  const Eigen::Vector2d& v = fromRow0.norm() >= fromRow1.norm() ? fromRow0 : fromRow1;
  return v.norm() > tiny ? Eigen::Vector2d(v.normalized()) : Eigen::Vector2d::Zero();
}

/// Orthonormal eigenvectors of a symmetric 2×2 matrix, for its larger and smaller eigenvalue.
std::pair<Eigen::Vector2d, Eigen::Vector2d> symmetricEigenvectors(const Eigen::Matrix2d& A,
                                                                 double tiny) {
  const double mean = 0.5 * (A(0, 0) + A(1, 1));
  const double half = std::hypot(0.5 * (A(0, 0) - A(1, 1)), A(0, 1));
  Eigen::Vector2d first = eigenvector(A, mean + half, tiny);
  if (first.isZero()) first = Eigen::Vector2d(1.0, 0.0);  // umbilic: any pair
  return {first, Eigen::Vector2d(-first.y(), first.x())};
}

}  // namespace

FaceCurvature checkerboardFaceCurvature(const Eigen::Vector3d& d0, const Eigen::Vector3d& d1,
                                        const Eigen::Vector3d& m0, const Eigen::Vector3d& m1) {
  FaceCurvature result;
  const Eigen::Vector3d cross = d0.cross(d1);
  const double area = cross.norm();
  const double scale = d0.norm() * d1.norm();
  if (!(area > 1e-14 * scale) || !std::isfinite(area)) return result;
  result.valid = true;
  result.normal = cross / area;
  // Orthonormal basis (e1, e2) of n_f^⊥ with e1 × e2 = n_f; 2D coordinates of the vectors.
  const Eigen::Vector3d e1 = d0.normalized();
  const Eigen::Vector3d e2 = result.normal.cross(e1);
  const auto planar = [&e1, &e2](const Eigen::Vector3d& v) {
    return Eigen::Vector2d(v.dot(e1), v.dot(e2));
  };
  Eigen::Matrix2d D, image;
  D << planar(d0), planar(d1);
  image << -planar(m0), -planar(m1);
  const Eigen::Matrix2d S = image * D.inverse();  // s_f in the basis (e1, e2)
  result.gauss = S.determinant();
  result.mean = 0.5 * S.trace();
  const double discriminant = result.mean * result.mean - result.gauss;
  const double root = discriminant > 0.0 ? std::sqrt(discriminant) : 0.0;
  result.principalMax = result.mean + root;
  result.principalMin = result.mean - root;

  const double tiny = 1e-12 * (S.norm() + std::numeric_limits<double>::min());
  Eigen::Vector2d dirMax = Eigen::Vector2d::Zero(), dirMin = Eigen::Vector2d::Zero();
  if (discriminant > 0.0) {
    dirMax = eigenvector(S, result.principalMax, tiny);
    dirMin = eigenvector(S, result.principalMin, tiny);
  }
  if (dirMax.isZero() || dirMin.isZero())
    std::tie(dirMax, dirMin) = symmetricEigenvectors(0.5 * (S + S.transpose()), tiny);
  result.directionMax = dirMax.x() * e1 + dirMax.y() * e2;
  result.directionMin = dirMin.x() * e1 + dirMin.y() * e2;
  result.ruling = std::abs(result.principalMin) <= std::abs(result.principalMax)
                      ? result.directionMin
                      : result.directionMax;
  return result;
}

std::vector<FaceCurvature> checkerboardCurvature(const Eigen::MatrixX3d& mesh,
                                                 const Eigen::MatrixX3d& normals,
                                                 const std::vector<std::array<int, 4>>& faces) {
  if (mesh.rows() != normals.rows())
    throw std::invalid_argument("checkerboardCurvature: need one normal per mesh vertex");
  const int numVertices = static_cast<int>(mesh.rows());
  std::vector<FaceCurvature> result;
  result.reserve(faces.size());
  for (int f = 0; f < static_cast<int>(faces.size()); ++f) {
    const std::array<int, 4>& face = faces[f];
    const int n = face[3] < 0 ? 3 : 4;
    for (int c = 0; c < n; ++c)
      if (face[c] < 0 || face[c] >= numVertices)
        throw std::invalid_argument("checkerboardCurvature: face " + std::to_string(f) +
                                    " has a vertex index out of range");
    const auto v = [&mesh, &face](int c) -> Eigen::Vector3d { return mesh.row(face[c]); };
    const auto m = [&normals, &face](int c) -> Eigen::Vector3d { return normals.row(face[c]); };
    if (n == 4)
      result.push_back(checkerboardFaceCurvature(v(2) - v(0), v(3) - v(1), m(2) - m(0), m(3) - m(1)));
    else
      result.push_back(checkerboardFaceCurvature(v(1) - v(0), v(2) - v(0), m(1) - m(0), m(2) - m(0)));
  }
  return result;
}

}  // namespace devsurf::metrics
