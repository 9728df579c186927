#pragma once

#include <string>

#include <Eigen/Core>

namespace devsurf::io {

/// A polygon mesh of quads (the sampled surfaces the models extract).
struct QuadMesh {
  Eigen::MatrixX3d vertices;  ///< m×3
  Eigen::MatrixX4i quads;     ///< f×4 vertex indices, counter-clockwise seen from the normal side
};

/// Writes the mesh through OpenMesh; the format follows the extension (.obj, .off, .ply, .stl).
/// @throws std::runtime_error naming the file when writing fails.
void writeMesh(const QuadMesh& mesh, const std::string& path);

/// Reads a polygon mesh through OpenMesh (faces that are not quads are rejected).
/// @throws std::runtime_error naming the file when reading fails.
QuadMesh readQuadMesh(const std::string& path);

}  // namespace devsurf::io
