#pragma once

#include <cstdint>
#include <map>
#include <stdexcept>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "devsurf/models/quad_mesh/SegmentedApproximation.h"
#include "devsurf/proto/Scene.h"
#include "devsurf/reference/ReferenceShape.h"
#include "devsurf/server/ShapeUpload.h"

namespace devsurf::server {

/// What to make of a reference mesh (issue 15, 004_… §5): `devsurf approximate` and
/// POST /api/approximations.
struct ApproximationRequest {
  std::vector<int> patchIds;  ///< one per triangle of the mesh as read; empty: `segments` or one patch
  int segments = 0;           ///< > 0: reference::segmentByNormals into this many
  std::uint32_t seed = 1;     ///< its k-means++ seeding
  models::quad_mesh::SegmentedApproximationOptions options;
  int iterations = 40;        ///< the scene's solver.iterations
  std::string name;           ///< the scene's name ("" = from the source)
  std::string units = "mm";
};

/// The scene made, and what was built (the CLI prints it, the route returns it as "summary").
struct ApproximationResult {
  proto::Scene scene;
  models::quad_mesh::SegmentedApproximation approximation;
  int segments = 0;  ///< distinct patch ids the quads belong to
  /// Faces of the file its reader left out (reference::ReferenceShape::facesSkipped): a repeated
  /// or out-of-range vertex index, a coordinate it could not read. Said in the summary.
  long long facesSkipped = 0;

  nlohmann::json summaryJson() const;
  std::string summaryText() const;
};

/// Builds the quad_mesh scene of glued developable patches over a reference triangle mesh.
/// @param[in] source  names the input in the scene's name and description (a file name)
/// @throws ApproximationInputError (field "mesh", "patches", …) for a point cloud, patch ids that
///         do not match the triangles, a mesh that is not a disk, a spacing out of range
ApproximationResult approximateShape(const reference::ReferenceShape& shape, const std::string& source,
                                     const ApproximationRequest& request);

/// The request of POST /api/approximations from its query parameters: segments, seed, faces,
/// spacing, isometry, proximity, fairness, iterations, name, units (all optional; unknown ones
/// are refused).
/// @throws ApproximationInputError naming the parameter
ApproximationRequest approximationRequestFromQuery(const std::multimap<std::string, std::string>& params);

/// POST /api/approximations: the body is a mesh file of `format` ("off", "obj", "ply", "stl"), read
/// through reference::readReferenceShape (from a private temporary file) within `limits`.
/// @throws ApproximationInputError naming "format", "body" or a parameter
ApproximationResult approximateUpload(const std::string& body, const std::string& format,
                                      const ApproximationRequest& request, const reference::ReferenceLimits& limits);

}  // namespace devsurf::server
