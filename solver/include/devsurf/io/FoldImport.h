#pragma once

#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "devsurf/io/CreasePattern.h"

namespace devsurf::io {

/// Something of an imported file that the import changed or could not carry over, by element in
/// the file's own terms ("edges_assignment[4]", "faces_vertices[2]", "file_frames[0]").
struct ImportNote {
  std::string element;
  std::string message;
};

/// A crease pattern read from a FOLD file for editing, and what the reading changed.
struct FoldImport {
  /// Development (always), folded state (when the file has a non-flat folded form), edges with
  /// their assignments and fold angles, faces counter-clockwise in the development.
  CreasePattern pattern;
  std::vector<ImportNote> notes;
  /// The file's frame_unit when it is one FOLD defines ("mm", "cm", "m", "in", "pt", "um", "nm"),
  /// empty for "unit" or none; pattern.unitToMm is its length in millimetres (1 when empty).
  std::string unit;
  /// Per edge of `pattern`: the curve it lies on as devsurf's own FOLD export marks it
  /// (`edges_devsurf:curve`), −1 when unmarked; empty when the file has no such key.
  std::vector<int> edgeCurves;
};

/// Reads a FOLD 1.0–1.2 document (https://github.com/edemaine/fold, doc/spec.md) as made by other
/// tools, more leniently than readFoldDocument (which reads devsurf's own exports back):
///  * frames: frame 0 is the top level, file_frames[i] frame i + 1 (frame_parent/frame_inherit
///    honoured). The development is the first frame classed "creasePattern", else the first flat
///    frame not classed "foldedForm", else a folded frame's `vertices_flatUnfoldCoords`, else the
///    first non-flat folded form unfolded isometrically from its own edge lengths (faces needed).
///    The folded state is the first frame classed "foldedForm" whose coordinates are not all in one
///    plane; a flat-folded form (every fold 180°) is noted and left out.
///  * edges: edges_vertices (derived from faces_vertices when absent); edges_assignment B M V F U C
///    J (U and J read as F; missing ones derived: B on one face, F on two); edges_foldAngle.
///  * faces: faces_vertices when present (turned counter-clockwise in the development); otherwise
///    found from the planar arrangement of the edges (spatial::planarArrangement): crossing edges
///    are split, dangling edges left out, islands (edges touching nothing around them) joined to
///    the sheet by two flat edges each (CreaseEdge::proposed), faces walled off from the outline by
///    B edges cut out as holes — each noted by element.
///  * Coordinates stay as they are (model units); pattern.unitToMm from frame_unit.
/// @throws std::invalid_argument "FOLD: …" naming the key (and index) of what cannot be read
FoldImport importFoldDocument(const nlohmann::json& document);

/// importFoldDocument of a JSON text. @throws std::invalid_argument for malformed JSON too.
FoldImport importFoldText(const std::string& text);

}  // namespace devsurf::io
