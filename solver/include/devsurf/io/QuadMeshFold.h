#pragma once

#include <array>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <nlohmann/json.hpp>

#include "devsurf/io/PolygonMesh.h"

namespace devsurf::io {

/// Options of the quad-mesh FOLD export.
struct QuadMeshFoldOptions {
  std::string title;        ///< file_title; "devsurf quad mesh" when empty
  std::string author;       ///< file_author when non-empty
  std::string description;  ///< file_description when non-empty
  double unitToMm = 1.0;    ///< millimetres per design unit (> 0); see "Units" below
  int indent = 1;           ///< JSON indentation of the text; negative = one line
};

/// FOLD 1.2 export (https://github.com/edemaine/fold, doc/spec.md) of a quad mesh M and its
/// unfolding M′ (same vertex indices), in the house style of FoldWriter.h. It also writes a
/// composite cut along its seams (server::SceneSolver): M′ its flat pieces, several parts of one
/// crease pattern, M where their vertices are on the surface, the seams' copies as glue pairs.
///  * file metadata: file_spec 1.2, file_creator "devsurf", file_classes ["singleModel"],
///    file_title, file_author / file_description when given;
///  * key frame (top level) = the crease pattern M′: frame_title, frame_classes
///    ["creasePattern"], frame_attributes ["2D" (or "3D" for a non-planar M′), "joins" |
///    "noJoins"], frame_unit, vertices_coords ([x, y]; [x, y, z] for a V×3 M′ whose z is not all
///    zero), faces_vertices (3 or 4 indices, counter-clockwise), edges_vertices (each edge once, in
///    findGlueSeams' order and orientation), edges_assignment: "B" a boundary edge that is cut,
///    "J" (FOLD 1.2 join) a boundary edge glued to another boundary edge, "F" an interior edge;
///    custom keys "edges_devsurf:seam" (per edge its 1-based seam number — the number printed on
///    the SVG cutting pattern — or null; written when there are glued edges),
///    "devsurf:gluePairs" (the glue vertex pairs as given; written when non-empty) and
///    "devsurf:unitToMm";
///  * file_frames[0] = the folded form M, when M has rows: frame_title, frame_classes
///    ["foldedForm"], frame_attributes ["3D"], frame_parent 0, frame_inherit true (edges,
///    faces, assignments come from the key frame), frame_unit, vertices_coords [x, y, z].
///
/// Units: when unitToMm is exactly one of FOLD's units (1 "mm", 10 "cm", 1000 "m", 25.4 "in",
/// 25.4/72 "pt", 1e-3 "um", 1e-6 "nm") frame_unit is that unit and coordinates are design units
/// as they are; otherwise frame_unit is "mm" and coordinates are design units × unitToMm.
///
/// @param unfolding V×2 or V×3 vertices of M′
/// @param mesh V×3 vertices of M, or no rows (no folded frame)
/// @throws std::invalid_argument for mismatched sizes, non-finite coordinates, bad faces or glue
///         pairs (findGlueSeams), unitToMm ≤ 0.
nlohmann::json quadMeshFoldDocument(const Eigen::MatrixXd& unfolding, const Eigen::MatrixXd& mesh,
                                    const std::vector<PolygonFace>& faces,
                                    const std::vector<std::array<int, 2>>& gluePairs,
                                    const QuadMeshFoldOptions& options = {});

/// quadMeshFoldDocument serialised as text (keys in the spec's reading order).
std::string quadMeshFoldString(const Eigen::MatrixXd& unfolding, const Eigen::MatrixXd& mesh,
                               const std::vector<PolygonFace>& faces,
                               const std::vector<std::array<int, 2>>& gluePairs,
                               const QuadMeshFoldOptions& options = {});

/// Writes quadMeshFoldString to `path` (conventionally *.fold).
/// @throws std::invalid_argument as above, std::runtime_error naming the file when writing fails.
void writeQuadMeshFold(const Eigen::MatrixXd& unfolding, const Eigen::MatrixXd& mesh,
                       const std::vector<PolygonFace>& faces,
                       const std::vector<std::array<int, 2>>& gluePairs, const std::string& path,
                       const QuadMeshFoldOptions& options = {});

}  // namespace devsurf::io
