#pragma once

#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "devsurf/io/FoldImport.h"
#include "devsurf/proto/Scene.h"

namespace devsurf::server {

/// What to make of a crease-pattern file (CLI flags of `devsurf import`, query parameters of
/// POST /api/imports).
struct CreasePatternImportRequest {
  std::string format;  ///< "fold" or "svg" (Origami Simulator's colours, io::importSvgText)
  std::string name;    ///< scene name; empty = the file's title, else "imported crease pattern"
  /// Scene units (mm, cm, m, in), the file's numbers kept. Empty = the file's frame_unit; a file
  /// without one is read as millimetres, except that a sheet under 10 units across (drawn on a
  /// unit square) is scaled to 200 mm across.
  std::string units;
  /// Refused above this many edges (the planar arrangement is quadratic in them).
  int maxEdges = 20000;
};

/// A composite scene made from a crease pattern, and what the import changed or left out.
struct CreasePatternImportResult {
  proto::Scene scene;
  std::vector<io::ImportNote> notes;
  int faces = 0;                ///< faces of the composite (planar pieces between creases)
  int mountain = 0, valley = 0, flat = 0, boundary = 0, cut = 0;  ///< edges of the pattern by assignment
  bool foldedState = false;     ///< the scene starts in the file's folded form (else flat)
  std::string format = "fold";  ///< what was read
  int curvedCreases = 0;        ///< curved creases as drawn (mountain, valley, flat strokes; not the outline)
  /// {"format", "curved_creases", "faces", "edges": {"mountain", …}, "folded_state",
  ///  "notes": [{"element", "message"}]}
  nlohmann::json summaryJson() const;
};

/// The format of a crease pattern whose request did not say: "svg" for a file ending in .svg or a
/// body that starts (after white space and a byte-order mark) with "<", else "fold" (a FOLD file
/// is JSON; anything else is then refused as not JSON).
/// @param[in] body      the file's bytes
/// @param[in] fileName  its name if known (a form upload's), else empty
std::string creasePatternFormatOf(const std::string& body, const std::string& fileName = "");

/// Reads a crease pattern (`body`, the file's text) and builds a composite scene from it
/// (io::importFoldDocument or io::importSvgText, models::composite::compositeFromCreasePattern;
/// an SVG with curved strokes gets curved creases and proposed rulings). The scene is read back
/// through proto::sceneFromJson, so it opens and solves like any other.
/// @throws ApproximationInputError naming "format", "name", "units" or "body" (tooLarge past
///         maxEdges)
CreasePatternImportResult importCreasePattern(const std::string& body, const CreasePatternImportRequest& request);

/// Whether a file name is a crease pattern `devsurf import` reads (".fold", ".svg").
bool isCreasePatternFile(const std::string& path);

}  // namespace devsurf::server
