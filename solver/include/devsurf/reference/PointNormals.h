#pragma once

#include <Eigen/Core>

#include "devsurf/reference/ReferenceShape.h"

namespace devsurf::reference {

/// One unit normal per point of a shape, oriented consistently over each connected part:
/// - a mesh: the area-weighted normals of each vertex's triangles (the mesh's own orientation);
/// - a cloud with normals: the file's, normalized;
/// - a cloud without: thinPointCloud at suggestedThinningRadius fits a plane per kept point, each
///   point takes its nearest kept point's normal, and the kept normals are oriented by Hoppe et
///   al.'s propagation (1992): along a spanning tree of the kept points' neighbourhoods (links
///   within 3 thinning radii) that prefers nearly parallel normals, starting from the point
///   farthest from the centroid turned outward. A cloud of several parts is oriented part by part.
/// Points without any normal (an isolated vertex, a ball on a line) get a zero row.
/// @returns points.rows()×3
/// @throws std::invalid_argument if the shape has no points or a value is not finite
Eigen::MatrixX3d orientedPointNormals(const ReferenceShape& shape);

}  // namespace devsurf::reference
