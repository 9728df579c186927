#include "devsurf/io/PolygonMesh.h"

#include <charconv>
#include <cmath>
#include <fstream>
#include <stdexcept>

namespace devsurf::io {
namespace {

/// Shortest text that reads back as the same double (locale-independent).
std::string exact(double v) {
  char buf[64];
  const auto res = std::to_chars(buf, buf + sizeof buf, v == 0.0 ? 0.0 : v);  // no "-0"
  return std::string(buf, res.ptr);
}

}  // namespace

void validatePolygonFaces(const std::vector<PolygonFace>& faces, int vertexCount) {
  for (std::size_t f = 0; f < faces.size(); ++f) {
    const PolygonFace& face = faces[f];
    const int n = cornerCount(face);
    auto fail = [f](const std::string& why) {
      throw std::invalid_argument("face " + std::to_string(f) + " " + why);
    };
    if (n == 3 && face[3] != -1) fail("has a negative fourth index other than -1");
    for (int c = 0; c < n; ++c) {
      if (face[c] < 0 || face[c] >= vertexCount)
        fail("has vertex index " + std::to_string(face[c]) + " outside [0, " +
             std::to_string(vertexCount) + ")");
      for (int d = 0; d < c; ++d)
        if (face[c] == face[d]) fail("repeats vertex " + std::to_string(face[c]));
    }
  }
}

std::string objString(const Eigen::MatrixXd& vertices, const std::vector<PolygonFace>& faces,
                      const std::string& comment) {
  if (vertices.cols() != 2 && vertices.cols() != 3)
    throw std::invalid_argument("OBJ: vertices must have 2 or 3 columns, not " +
                                std::to_string(vertices.cols()));
  if (!vertices.allFinite()) throw std::invalid_argument("OBJ: vertices must be finite");
  validatePolygonFaces(faces, static_cast<int>(vertices.rows()));
  std::string out;
  std::size_t start = 0;
  while (!comment.empty() && start <= comment.size()) {
    const std::size_t end = std::min(comment.find('\n', start), comment.size());
    out += "# " + comment.substr(start, end - start) + "\n";
    start = end + 1;
  }
  for (Eigen::Index i = 0; i < vertices.rows(); ++i)
    out += "v " + exact(vertices(i, 0)) + " " + exact(vertices(i, 1)) + " " +
           (vertices.cols() == 3 ? exact(vertices(i, 2)) : std::string("0")) + "\n";
  for (const PolygonFace& face : faces) {
    out += "f";
    for (int c = 0; c < cornerCount(face); ++c) out += " " + std::to_string(face[c] + 1);
    out += "\n";
  }
  return out;
}

void writeObj(const Eigen::MatrixXd& vertices, const std::vector<PolygonFace>& faces,
              const std::string& path, const std::string& comment) {
  const std::string text = objString(vertices, faces, comment);
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  if (!out) throw std::runtime_error("cannot write OBJ file " + path);
  out << text;
  out.flush();
  if (!out) throw std::runtime_error("cannot write OBJ file " + path);
}

}  // namespace devsurf::io
