#pragma once

#include <string>

#include <nlohmann/json.hpp>

#include "devsurf/io/CreasePattern.h"

namespace devsurf::io {

/// FOLD 1.2 export (https://github.com/edemaine/fold, doc/spec.md).
///
/// Layout of the document:
///  * file metadata: file_spec 1.2, file_creator "devsurf", file_classes ["singleModel"],
///    file_title (the pattern title), file_author / file_description when given;
///  * key frame (top level) = the crease pattern: frame_title, frame_classes ["creasePattern"],
///    frame_attributes ["2D", "cuts" | "noCuts"], frame_unit, vertices_coords [x, y] (see
///    "Units" below), edges_vertices, edges_assignment ("B", "M", "V", "F", "C"; "C" is
///    the FOLD 1.2 cut/slit assignment), edges_foldAngle (degrees, + valley / − mountain; see
///    exportedFoldAngles — omitted as a whole when a mountain or valley edge has no given angle
///    and none can be measured), faces_vertices (counter-clockwise);
///  * file_frames[0] = the folded form, when the pattern has a folded state: frame_title,
///    frame_classes ["foldedForm"], frame_attributes ["3D"] (["2D"] if it is flat),
///    frame_parent 0, frame_inherit true (edges, faces and the custom keys come from the key
///    frame), frame_unit, vertices_coords [x, y, z].
///
/// Units: when unitToMm is exactly one of FOLD's units (1 "mm", 10 "cm", 1000 "m", 25.4 "in",
/// 25.4/72 "pt", 1e-3 "um", 1e-6 "nm") frame_unit is that unit and coordinates are model units as
/// they are; otherwise frame_unit is "mm" and coordinates are model units × unitToMm.
///
/// Custom keys follow the spec's rule for custom properties (a colon; for per-element arrays the
/// namespace goes after the element prefix, like the spec's "edges_tm:structuralType", so that
/// FOLD tools treat them as edge data when they renumber edges):
///  * "edges_devsurf:curve": per edge, the id of the crease line it lies on, or null (written when
///    any edge has one); a composite's S edges joined with one tangent share the first one's id
///    (one crease), so an id may name a line made of several of the splines below;
///  * "edges_devsurf:smooth": per edge, true for CreaseEdge::proposed (a straight edge a composite
///    keeps smooth: read back, a flat edge stays smooth instead of folding freely), else false
///    (written when any edge has it; read back only on flat (F) edges);
///  * "devsurf:curves": per spline (a composite's S edge, by its edge id), {"id", "degree", "knots", "controlPoints"
///    ([x, y, z] in the folded state, in frame_unit), "weights" (rational only)};
///  * "devsurf:rulings": per ruling, [[x0, y0], [x1, y1]] in the development (in frame_unit);
///  * "devsurf:unitToMm": the model scale, so that readFold can restore model units.
struct FoldWriteOptions {
  std::string author;       ///< file_author when non-empty
  std::string description;  ///< file_description when non-empty
  bool foldedFrame = true;  ///< write the folded-form frame when the pattern has a folded state
  int indent = 1;           ///< JSON indentation of foldString / writeFold; negative = one line
};

/// The FOLD document. Validates the pattern first.
/// @throws std::invalid_argument from CreasePattern::validate.
nlohmann::json foldDocument(const CreasePattern& pattern, const FoldWriteOptions& options = {});

/// foldDocument serialised as text.
std::string foldString(const CreasePattern& pattern, const FoldWriteOptions& options = {});

/// Writes foldString to `path` (conventionally *.fold).
/// @throws std::invalid_argument for a bad pattern, std::runtime_error naming the file when
///         writing fails.
void writeFold(const CreasePattern& pattern, const std::string& path,
               const FoldWriteOptions& options = {});

/// Reads a FOLD document back: the key frame as the development (vertices_coords, edges_vertices,
/// edges_assignment with "U" and "J" read as Flat, edges_foldAngle, faces_vertices), the first
/// "foldedForm" frame of file_frames with as many vertices as the folded state, and the devsurf
/// keys above. Coordinates are converted to model units with "devsurf:unitToMm" and frame_unit
/// when present (otherwise unitToMm is frame_unit in millimetres, 1 for "unit" or none).
/// @throws std::invalid_argument when the document is not a FOLD crease pattern this reader
///         understands or the result does not validate.
CreasePattern readFoldDocument(const nlohmann::json& document);

/// readFoldDocument of a JSON text. @throws std::invalid_argument for malformed JSON too.
CreasePattern parseFold(const std::string& text);

/// parseFold of a file. @throws std::runtime_error naming the file when it cannot be read.
CreasePattern readFold(const std::string& path);

}  // namespace devsurf::io
