#include "devsurf/models/quad_mesh/FaceMeasures.h"

#include <Eigen/Geometry>

namespace devsurf::models::quad_mesh {

namespace {
double triangleArea(const Eigen::MatrixX3d& v, int a, int b, int c) {
  return 0.5 * (v.row(b) - v.row(a)).cross(v.row(c) - v.row(a)).norm();
}
}  // namespace

double faceArea(const Eigen::MatrixX3d& v, const Face& f) {
  if (faceSize(f) == 3) return triangleArea(v, f[0], f[1], f[2]);
  return 0.5 * (triangleArea(v, f[0], f[1], f[2]) + triangleArea(v, f[0], f[2], f[3]) +
                triangleArea(v, f[1], f[2], f[3]) + triangleArea(v, f[1], f[3], f[0]));
}

double signedPlanarArea(const Eigen::MatrixX3d& v, const Face& f) {
  const int n = faceSize(f);
  double twice = 0.0;
  for (int k = 0; k < n; ++k) {
    const int a = f[k], b = f[(k + 1) % n];
    twice += v(a, 0) * v(b, 1) - v(a, 1) * v(b, 0);
  }
  return 0.5 * twice;
}

Eigen::MatrixX3d unitVertexNormals(const Eigen::MatrixX3d& mesh, const std::vector<Face>& faces) {
  Eigen::MatrixX3d normals = Eigen::MatrixX3d::Zero(mesh.rows(), 3);
  for (const Face& f : faces) {
    const Eigen::Vector3d area =
        faceSize(f) == 4 ? Eigen::Vector3d((mesh.row(f[2]) - mesh.row(f[0])).cross(mesh.row(f[3]) - mesh.row(f[1])))
                         : Eigen::Vector3d((mesh.row(f[1]) - mesh.row(f[0])).cross(mesh.row(f[2]) - mesh.row(f[0])));
    for (int k = 0; k < faceSize(f); ++k) normals.row(f[k]) += area.transpose();
  }
  for (Eigen::Index i = 0; i < normals.rows(); ++i) {
    const double length = normals.row(i).norm();
    if (length > 0.0) normals.row(i) /= length;
  }
  return normals;
}

}  // namespace devsurf::models::quad_mesh
