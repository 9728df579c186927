#pragma once

#include <array>
#include <string>
#include <vector>

#include <Eigen/Core>

namespace devsurf::io {

/// A face of a quad-dominant mesh: four vertex indices, or three with [3] = -1 (a triangle);
/// counter-clockwise seen from the front (for an unfolding M′: counter-clockwise in its plane).
using PolygonFace = std::array<int, 4>;

/// Number of corners of a face: 3 when face[3] == -1, else 4.
inline int cornerCount(const PolygonFace& face) { return face[3] < 0 ? 3 : 4; }

/// Checks that every face has valid, pairwise distinct vertex indices in [0, vertexCount) (a
/// triangle: [3] exactly -1).
/// @throws std::invalid_argument naming the face.
void validatePolygonFaces(const std::vector<PolygonFace>& faces, int vertexCount);

/// A Wavefront OBJ text of a mixed triangle/quad mesh: a comment line per line of `comment` (when
/// non-empty), "v x y z" per vertex in the given order (17 significant digits, so a mesh reads
/// back exactly; a V×2 matrix, a planar unfolding, is written with z = 0), then "f a b c [d]"
/// per face with 1-based indices in the face's order. Vertex order and indices are kept, so M
/// and its unfolding M′ written separately correspond vertex for vertex.
/// @param vertices V×3 (a surface M) or V×2 (a planar unfolding M′)
/// @throws std::invalid_argument for another column count, non-finite coordinates or bad faces.
std::string objString(const Eigen::MatrixXd& vertices, const std::vector<PolygonFace>& faces,
                      const std::string& comment = {});

/// Writes objString to `path`.
/// @throws std::invalid_argument as objString, std::runtime_error naming the file when writing
///         fails.
void writeObj(const Eigen::MatrixXd& vertices, const std::vector<PolygonFace>& faces,
              const std::string& path, const std::string& comment = {});

}  // namespace devsurf::io
