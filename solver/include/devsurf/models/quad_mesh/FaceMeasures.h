#pragma once

#include <vector>

#include <Eigen/Core>

#include "devsurf/models/quad_mesh/QuadMeshTopology.h"

namespace devsurf::models::quad_mesh {

/// Area of a face of a quad-dominant mesh: a triangle's, or the mean of a quad's two
/// triangulations (A-Err of 004_… Fig. 22: "for nonplanar quads computed via a subdivision into
/// triangles").
/// @param[in] vertices  V×3
double faceArea(const Eigen::MatrixX3d& vertices, const Face& face);

/// Signed area of a face's polygon in the xy plane (shoelace; > 0 counter-clockwise).
double signedPlanarArea(const Eigen::MatrixX3d& vertices, const Face& face);

/// Unit vertex normals: at every vertex the normalized sum of its faces' vector areas (a quad's
/// inscribed parallelogram normal (v2 − v0) × (v3 − v1), a triangle's (v1 − v0) × (v2 − v0));
/// zero where they cancel.
/// @param[in] mesh  V×3
Eigen::MatrixX3d unitVertexNormals(const Eigen::MatrixX3d& mesh, const std::vector<Face>& faces);

}  // namespace devsurf::models::quad_mesh
