#include "devsurf/creases/FoldSamples.h"

#include <stdexcept>

namespace devsurf::creases {

namespace {

void checkSampledSheet(const SheetSamples& s, const char* who) {
  const auto n = s.crease.rows();
  if (s.rulingEnd.rows() != n || s.devCrease.rows() != n || s.devRulingEnd.rows() != n)
    throw std::invalid_argument(std::string(who) + ": sheet blocks have different row counts");
}

double foldCross2(const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
  return a.x() * b.y() - a.y() * b.x();
}

Eigen::MatrixX4i stripQuads(const SheetSamples& s) {
  const int n = s.size();
  Eigen::MatrixX4i quads(n > 1 ? n - 1 : 0, 4);
  for (int i = 0; i + 1 < n; ++i) {
    const Eigen::Vector2d p0 = s.devCrease.row(i), p1 = s.devCrease.row(i + 1);
    const Eigen::Vector2d q0 = s.devRulingEnd.row(i), q1 = s.devRulingEnd.row(i + 1);
    // Shoelace area of (p0, p1, q1, q0).
    const double area = foldCross2(p0, p1) + foldCross2(p1, q1) + foldCross2(q1, q0) + foldCross2(q0, p0);
    if (area >= 0)
      quads.row(i) << 2 * i, 2 * i + 2, 2 * i + 3, 2 * i + 1;
    else
      quads.row(i) << 2 * i + 2, 2 * i, 2 * i + 1, 2 * i + 3;
  }
  return quads;
}

}  // namespace

QuadMesh3 surfaceMesh(const SheetSamples& sheet) {
  checkSampledSheet(sheet, "surfaceMesh");
  const int n = sheet.size();
  QuadMesh3 mesh;
  mesh.vertices.resize(2 * n, 3);
  for (int i = 0; i < n; ++i) {
    mesh.vertices.row(2 * i) = sheet.crease.row(i);
    mesh.vertices.row(2 * i + 1) = sheet.rulingEnd.row(i);
  }
  mesh.quads = stripQuads(sheet);
  return mesh;
}

QuadMesh2 developmentMesh(const SheetSamples& sheet) {
  checkSampledSheet(sheet, "developmentMesh");
  const int n = sheet.size();
  QuadMesh2 mesh;
  mesh.vertices.resize(2 * n, 2);
  for (int i = 0; i < n; ++i) {
    mesh.vertices.row(2 * i) = sheet.devCrease.row(i);
    mesh.vertices.row(2 * i + 1) = sheet.devRulingEnd.row(i);
  }
  mesh.quads = stripQuads(sheet);
  return mesh;
}

}  // namespace devsurf::creases
