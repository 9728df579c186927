// Approximating a user's mesh by glued developable patches: the service behind `devsurf
// approximate` and POST /api/approximations (issue 15, 004_… §5).
#include "devsurf/server/ShapeApproximation.h"

#include <atomic>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <random>
#include <set>
#include <sstream>

#include <unistd.h>

#include "devsurf/reference/SurfaceSegmentation.h"

namespace devsurf::server {
namespace qm = models::quad_mesh;

namespace {

}  // namespace

nlohmann::json ApproximationResult::summaryJson() const {
  const qm::SegmentedApproximation& a = approximation;
  return {{"quads", static_cast<int>(a.design.faces.size())},
          {"vertices", a.design.mesh.rows()},
          {"patches", a.pieces},
          {"segments", segments},
          {"glue_pairs", static_cast<int>(a.design.glue.size())},
          {"spacing", a.spacing},
          {"unfoldings_mapped_alone", a.piecesMappedAlone},
          {"border_nodes_aligned", a.bordersAligned},
          {"slivers_merged", a.mergedPieces},
          {"quads_dropped", a.droppedFaces},
          {"faces_skipped", facesSkipped}};
}

std::string ApproximationResult::summaryText() const {
  const qm::SegmentedApproximation& a = approximation;
  std::ostringstream s;
  s << a.design.faces.size() << " faces (quads, and triangles along the boundary), " << a.design.mesh.rows()
    << " vertices, " << a.pieces << " patches from " << segments << " segments, " << a.design.glue.size()
    << " glue pairs; spacing " << a.spacing << "; " << a.piecesMappedAlone << " of " << a.pieces
    << " unfoldings mapped on their own (the rest are not disks)";
  if (a.bordersAligned > 0) s << "; " << a.bordersAligned << " grid nodes moved onto patch borders";
  if (a.mergedPieces > 0) s << "; " << a.mergedPieces << " slivers joined a neighbour";
  if (a.droppedFaces > 0) s << "; " << a.droppedFaces << " isolated quads left out";
  if (facesSkipped > 0)
    s << "; " << facesSkipped
      << (facesSkipped == 1 ? " face of the file could not be read and was" : " faces of the file could not be read and were")
      << " left out (a repeated or out-of-range vertex index, or a coordinate that is not a number)";
  return s.str();
}

ApproximationResult approximateShape(const reference::ReferenceShape& shape, const std::string& source,
                                     const ApproximationRequest& request) {
  // Faces the reader left out (a repeated or out-of-range vertex index, a coordinate it could not
  // read): a few degenerate ones are common in exported meshes and are said in the summary; when a
  // tenth of the file is missing, what is left is not the shape it describes.
  const long long declaredFaces = static_cast<long long>(shape.triangles.rows()) + shape.facesSkipped;
  if (shape.facesSkipped > 0 && 10 * shape.facesSkipped >= declaredFaces)
    throw ApproximationInputError("mesh", source + ": " + std::to_string(shape.facesSkipped) +
                                              (shape.facesSkipped == 1 ? " face" : " faces") +
                                              " could not be read (a repeated or out-of-range vertex index, or a "
                                              "coordinate that is not a number), against " +
                                              std::to_string(shape.triangles.rows()) +
                                              " triangles read; approximating needs the shape the file describes");
  if (!shape.isMesh())
    throw ApproximationInputError("mesh", source + ": a point cloud; approximating by patches needs a triangle mesh "
                                                   "(fit takes clouds)");
  std::vector<int> patches = request.patchIds;
  if (!patches.empty() && static_cast<Eigen::Index>(patches.size()) != shape.triangles.rows())
    throw ApproximationInputError("patches", "patches: " + std::to_string(patches.size()) + " ids; " + source + " has " +
                                                 std::to_string(shape.triangles.rows()) + " triangles (one id per triangle)");
  if (patches.empty()) {
    if (request.segments > 0) {
      reference::NormalSegmentationOptions segmentation;
      segmentation.patches = request.segments;
      segmentation.seed = request.seed;
      patches = reference::segmentByNormals(shape.points, shape.triangles, segmentation);
    } else {
      patches.assign(static_cast<std::size_t>(shape.triangles.rows()), 0);
    }
  }
  ApproximationResult result;
  result.facesSkipped = shape.facesSkipped;
  try {
    result.approximation = qm::segmentedApproximation(shape.points, shape.triangles, patches, request.options);
  } catch (const std::invalid_argument& e) {
    // The grid's spacing (given, or from the quad count) is the request's, not the mesh's fault.
    const std::string what = e.what();
    if (what.find("quad spacing") != std::string::npos || what.find("lower the spacing") != std::string::npos) {
      const std::string field = request.options.spacing > 0.0 ? "spacing" : "faces";
      throw ApproximationInputError(field, field + ": " + what + " (" + source + ")");
    }
    throw ApproximationInputError("mesh", source + ": " + what);
  }
  const qm::SegmentedApproximation& a = result.approximation;
  result.segments = static_cast<int>(std::set<int>(a.facePatch.begin(), a.facePatch.end()).size());
  proto::Scene& scene = result.scene;
  scene.name = request.name.empty() ? "developable patches approximating " + source : request.name;
  scene.description = "A piecewise-developable approximation of " + source + " (Jiang et al. 2020 §5): " +
                      std::to_string(a.design.faces.size()) + " faces in " + std::to_string(a.pieces) +
                      " patches glued along their borders, each with its own unfolding; both meshes move, kept near " +
                      "the reference by proximity.";
  scene.units = request.units;
  scene.model = a.design;
  scene.solver.iterations = request.iterations;
  return result;
}

ApproximationRequest approximationRequestFromQuery(const std::multimap<std::string, std::string>& params) {
  ApproximationRequest r;
  std::set<std::string> seen;
  for (const auto& [key, value] : params) {
    if (!seen.insert(key).second) throw ApproximationInputError(key, key + ": given more than once");
    if (key == "format") continue;  // read by approximateUpload's caller
    if (key == "segments") r.segments = static_cast<int>(integerParameter(key, value, 1, 1000));
    else if (key == "seed") r.seed = static_cast<std::uint32_t>(integerParameter(key, value, 0, 4294967295L));
    else if (key == "faces") r.options.targetFaces = static_cast<int>(integerParameter(key, value, 4, 100000));
    else if (key == "spacing") r.options.spacing = numberParameter(key, value, 0.0, 1e12, true);
    else if (key == "isometry") r.options.weights.isometry = r.options.weights.position = numberParameter(key, value, 0.0, 1e6, false);
    else if (key == "proximity")
      r.options.weights.proximityPoint = r.options.weights.proximityPlane = numberParameter(key, value, 0.0, 1e6, false);
    else if (key == "fairness")
      r.options.weights.fairnessMesh = r.options.weights.fairnessUnfolding = numberParameter(key, value, 0.0, 1e6, false);
    else if (key == "iterations") r.iterations = static_cast<int>(integerParameter(key, value, 0, 10000));
    else if (key == "name") r.name = nameParameter(key, value);
    else if (key == "units") r.units = unitsParameter(key, value);
    else {
      throw ApproximationInputError(key, key + ": unknown parameter (segments, seed, faces, spacing, isometry, proximity, "
                                           "fairness, iterations, name, units, format)");
    }
  }
  return r;
}

ApproximationResult approximateUpload(const std::string& body, const std::string& format,
                                      const ApproximationRequest& request, const reference::ReferenceLimits& limits) {
  const reference::ReferenceShape shape = readUploadedShape(body, format, {"off", "obj", "ply", "stl"}, limits);
  return approximateShape(shape, request.name.empty() ? "the uploaded mesh" : request.name, request);
}

}  // namespace devsurf::server
