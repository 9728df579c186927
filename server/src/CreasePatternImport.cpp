#include "devsurf/server/CreasePatternImport.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <optional>
#include <sstream>

#include "devsurf/io/FoldCurvedCreases.h"
#include "devsurf/io/SvgImport.h"
#include "devsurf/models/composite/CompositeFromCreasePattern.h"
#include "devsurf/models/composite/CompositeFromDrawing.h"
#include "devsurf/models/composite/CompositeModel.h"
#include "devsurf/models/composite/CompositeTopology.h"
#include "devsurf/proto/BoundedJson.h"
#include "devsurf/server/ShapeUpload.h"

namespace devsurf::server {

namespace {
constexpr double kUnitlessSheetMm = 200.0;  ///< longest side of a unitless sheet drawn on a unit square
}  // namespace

nlohmann::json CreasePatternImportResult::summaryJson() const {
  nlohmann::json notesJson = nlohmann::json::array();
  for (const io::ImportNote& n : notes) notesJson.push_back({{"element", n.element}, {"message", n.message}});
  return {{"format", format},
          {"curved_creases", curvedCreases},
          {"faces", faces},
          {"edges", {{"mountain", mountain}, {"valley", valley}, {"flat", flat}, {"boundary", boundary}, {"cut", cut}}},
          {"folded_state", foldedState},
          {"notes", notesJson}};
}

bool isCreasePatternFile(const std::string& path) {
  std::string extension = std::filesystem::path(path).extension().string();
  std::transform(extension.begin(), extension.end(), extension.begin(), [](unsigned char c) { return std::tolower(c); });
  return extension == ".fold" || extension == ".svg";
}

std::string creasePatternFormatOf(const std::string& body, const std::string& fileName) {
  std::string extension = std::filesystem::path(fileName).extension().string();
  std::transform(extension.begin(), extension.end(), extension.begin(), [](unsigned char c) { return std::tolower(c); });
  if (extension == ".svg") return "svg";
  if (extension == ".fold") return "fold";
  std::size_t k = body.compare(0, 3, "\xEF\xBB\xBF") == 0 ? 3 : 0;
  while (k < body.size() && std::isspace(static_cast<unsigned char>(body[k]))) ++k;
  return k < body.size() && body[k] == '<' ? "svg" : "fold";
}

CreasePatternImportResult importCreasePattern(const std::string& body, const CreasePatternImportRequest& request) {
  if (request.format != "fold" && request.format != "svg")
    throw ApproximationInputError("format", "format: expected fold or svg, got \"" + request.format + "\"");
  const std::string name = request.name.empty() ? "" : nameParameter("name", request.name);
  const std::string units = request.units.empty() ? "" : unitsParameter("units", request.units);
  CreasePatternImportResult result;
  result.format = request.format;
  io::FoldImport imported;
  std::vector<io::CreaseStroke> drawing;  // the SVG's strokes (a FOLD file's edges below)
  try {
    if (request.format == "svg") {
      io::SvgImportOptions options;
      options.maxSegments = request.maxEdges;
      io::SvgImport svg = io::importSvgText(body, options);
      // The reader converts the drawing's units to millimetres. A drawing that states no size (its
      // user units read as px) is unitless: units asked for read its numbers in them.
      if (!svg.sizeStated && !units.empty()) {
        const double toUserUnits = 1.0 / svg.mmPerUserUnit;
        svg.pattern.vertices2d *= toUserUnits;
        for (io::CreaseStroke& stroke : svg.drawing)
          for (Eigen::Vector2d& point : stroke.points) point *= toUserUnits;
        svg.notes.erase(std::remove_if(svg.notes.begin(), svg.notes.end(),
                                       [](const io::ImportNote& n) { return n.message.rfind("no width or height", 0) == 0; }),
                        svg.notes.end());
        svg.notes.push_back({"svg", "no width or height: one user unit is read as one " + units + " (units)"});
      }
      imported.pattern = std::move(svg.pattern);
      imported.notes = std::move(svg.notes);
      imported.unit = svg.sizeStated || units.empty() ? "mm" : "";
      drawing = std::move(svg.drawing);
    } else {
      nlohmann::json document;
      try {
        document = proto::parseBoundedJson(body);
      } catch (const std::invalid_argument& e) {  // JsonSyntaxError, JsonTooDeep: a number out of range too
        throw ApproximationInputError("body", std::string("body: not JSON (a FOLD file is JSON): ") + e.what());
      }
      if (const auto ev = document.find("edges_vertices");
          ev != document.end() && ev->is_array() && static_cast<long>(ev->size()) > request.maxEdges)
        throw ApproximationInputError("body", "body: " + std::to_string(ev->size()) + " edges; at most " +
                                                  std::to_string(request.maxEdges) + " are imported", true);
      imported = io::importFoldDocument(document);
      // Curved creases drawn as chains of straight edges are laid out again from their lines, as
      // an SVG's strokes are (rulings proposed anew, the file's facets left out).
      io::FoldCurvedCreases curved = io::foldCurvedCreases(imported.pattern, imported.edgeCurves);
      if (!curved.strokes.empty()) {
        io::CreaseStrokesOptions strokeOptions;
        strokeOptions.maxSegments = request.maxEdges;
        strokeOptions.source = "FOLD";
        strokeOptions.curvedDecided = true;
        io::StrokePattern made = io::creasePatternFromStrokes(curved.strokes, strokeOptions);
        for (std::size_t i = 0; i < curved.strokes.size(); ++i) curved.strokes[i].curved = made.strokeCurved[i];
        made.pattern.title = imported.pattern.title;
        made.pattern.unitToMm = imported.pattern.unitToMm;
        imported.pattern = std::move(made.pattern);
        imported.notes.insert(imported.notes.end(), curved.notes.begin(), curved.notes.end());
        imported.notes.insert(imported.notes.end(), made.notes.begin(), made.notes.end());
        drawing = std::move(curved.strokes);
      }
    }
  } catch (const ApproximationInputError&) {
    throw;
  } catch (const nlohmann::json::exception& e) {  // a FOLD field of the wrong JSON type
    throw ApproximationInputError("body", std::string("body: ") + e.what());
  } catch (const std::length_error& e) {
    throw ApproximationInputError("body", std::string("body: ") + e.what(), true);
  } catch (const std::invalid_argument& e) {
    throw ApproximationInputError("body", std::string("body: ") + e.what());
  }
  io::CreasePattern& pattern = imported.pattern;
  result.notes = imported.notes;
  // Curved creases as drawn (mountain, valley, flat), not curved outline or cut strokes.
  result.curvedCreases = static_cast<int>(std::count_if(drawing.begin(), drawing.end(), [](const io::CreaseStroke& s) {
    return s.curved && s.assignment != io::EdgeAssignment::Boundary && s.assignment != io::EdgeAssignment::Cut;
  }));
  // A "folded form" in which no crease folds (a flat sheet's export: its frame inherits the
  // designed fold angles) is the crease pattern itself: read as folded it would open at 100 %
  // with its targets unmet, and the first solve would snap it.
  if (pattern.hasFoldedState()) {
    bool folds = false;
    for (const std::optional<double>& angle : io::measuredFoldAngles(pattern)) folds = folds || (angle && std::abs(*angle) >= 0.5);
    if (!folds) {
      pattern.vertices3d.resize(0, 3);
      result.notes.push_back({"file_frames", "the folded form folds no crease; read as the flat crease pattern"});
    }
  }

  // Units: a FOLD unit the scene knows is kept; others become millimetres. Units asked for are the
  // scene's: a file that says its own (an SVG's width and height, a FOLD frame_unit) is converted
  // to them, so the sheet keeps its size; a unitless file's numbers are read in them.
  std::string sceneUnits = units;
  const auto scaleDesign = [&pattern, &drawing](double factor) {
    pattern.vertices2d *= factor;
    if (pattern.hasFoldedState()) pattern.vertices3d *= factor;
    for (io::CreaseStroke& stroke : drawing)
      for (Eigen::Vector2d& point : stroke.points) point *= factor;
  };
  if (!units.empty() && !imported.unit.empty()) {
    const bool known = imported.unit == "mm" || imported.unit == "cm" || imported.unit == "m" || imported.unit == "in";
    const double fileMm = known ? proto::millimetresPerUnit(imported.unit) : pattern.unitToMm;
    const double factor = fileMm / proto::millimetresPerUnit(units);
    if (factor != 1.0) {
      scaleDesign(factor);
      const std::string from = request.format == "svg" ? "the drawing's size (in mm)" : "frame_unit \"" + imported.unit + "\"";
      result.notes.push_back({request.format == "svg" ? "svg" : "frame_unit", from + " converted to " + units});
    }
  }
  if (sceneUnits.empty()) {
    if (imported.unit == "mm" || imported.unit == "cm" || imported.unit == "m" || imported.unit == "in") {
      sceneUnits = imported.unit;
    } else if (!imported.unit.empty()) {
      scaleDesign(pattern.unitToMm);
      sceneUnits = "mm";
      result.notes.push_back({"frame_unit", "\"" + imported.unit + "\" converted to millimetres"});
    } else {
      sceneUnits = "mm";
      // Unitless files are mostly drawn on a unit square (the FOLD examples, Origami Simulator's
      // exports): a sheet smaller than 10 units is scaled to a 200 mm sheet, larger ones are read
      // as millimetres.
      const Eigen::Vector2d extent = pattern.vertices2d.colwise().maxCoeff() - pattern.vertices2d.colwise().minCoeff();
      const double side = extent.maxCoeff();
      if (side > 0.0 && side < 10.0) {
        const double scale = kUnitlessSheetMm / side;
        scaleDesign(scale);
        std::ostringstream note;
        note << "none given: the sheet, " << side << (side == 1.0 ? " unit" : " units") << " across, is scaled to " << kUnitlessSheetMm
             << " mm (choose its units to keep the file's numbers in mm, cm, m or in: the start page's \"Crease pattern "
                "units\", devsurf import --units, or the request's units)";
        result.notes.push_back({"frame_unit", note.str()});
      } else {
        result.notes.push_back({"frame_unit",
                                "none given: one unit of the file is read as 1 mm (choose other units on the start page's \"Crease "
                                "pattern units\", with devsurf import --units, or with the request's units)"});
      }
    }
  }

  models::composite::CreasePatternComposite composite;
  try {
    composite = models::composite::compositeFromCreasePattern(pattern);
    const models::composite::CompositeTopology topology(composite.design);  // the model's own checks, early
    (void)topology;
  } catch (const std::invalid_argument& e) {
    throw ApproximationInputError("body", std::string("body: the crease pattern does not make a composite: ") + e.what());
  }
  result.notes.insert(result.notes.end(), composite.notes.begin(), composite.notes.end());
  // The drawing travels with the design, so the browser can draw on it (layout edits rebuild from
  // it): an SVG's strokes as read, a FOLD file's edges as straight strokes in the scene's numbers.
  composite.design.drawing = drawing.empty() ? models::composite::drawingOfCreasePattern(pattern) : std::move(drawing);
  for (io::CreaseStroke& s : composite.design.drawing) s.element.clear();
  if (!pattern.hasFoldedState()) composite.design.foldAmount = 0.0;  // flat: the fold slider at 0 %
  for (const io::CreaseEdge& e : pattern.edges) {
    switch (e.assignment) {
      case io::EdgeAssignment::Mountain: ++result.mountain; break;
      case io::EdgeAssignment::Valley: ++result.valley; break;
      case io::EdgeAssignment::Flat: ++result.flat; break;
      case io::EdgeAssignment::Boundary: ++result.boundary; break;
      case io::EdgeAssignment::Cut: ++result.cut; break;
    }
  }
  // Creases as drawn (an SVG's strokes, a FOLD file's edges), not the pieces the faces cut them into.
  int mountainCreases = 0, valleyCreases = 0, flatCreases = 0;
  for (const io::CreaseStroke& stroke : composite.design.drawing) {
    mountainCreases += stroke.assignment == io::EdgeAssignment::Mountain;
    valleyCreases += stroke.assignment == io::EdgeAssignment::Valley;
    flatCreases += stroke.assignment == io::EdgeAssignment::Flat;
  }
  result.faces = static_cast<int>(composite.design.faces.size());
  result.foldedState = pattern.hasFoldedState();

  proto::Scene& scene = result.scene;
  scene.name = !name.empty() ? name : !pattern.title.empty() ? pattern.title.substr(0, 200) : "imported crease pattern";
  std::ostringstream description;
  const bool curved = composite.design.developmentDomain.boundary.size() > 0;
  description << "Imported from " << (request.format == "svg" ? "an SVG drawing" : "a FOLD file") << ": " << result.faces
              << (curved ? " faces between curved and straight creases (" : " planar faces between straight creases (")
              << mountainCreases << " mountain and " << valleyCreases << (valleyCreases == 1 ? " valley crease" : " valley creases");
  if (flatCreases > 0) description << ", " << flatCreases << " flat";
  description << "). "
              << (result.foldedState ? "It starts in the file's folded form; the largest face is fixed, and every crease "
                                       "folds freely: drag a corner to fold it."
                                     : "It starts flat; the largest face is fixed. Fold it with the Fold slider (devsurf "
                                       "solve --fold-amount), or drag a corner.");
  scene.description = description.str();
  scene.units = sceneUnits;
  scene.model = std::move(composite.design);
  // Read back as any scene is: the schema, indices, the model's checks and the limits.
  try {
    result.scene = proto::sceneFromJson(proto::sceneToJson(scene));
  } catch (const proto::SceneError& e) {
    throw ApproximationInputError("body", std::string("body: the imported scene does not validate: ") + e.what());
  }
  // And opened as a session opens it (the model's own checks: a fold-angle target needs a hinge):
  // an import answers with a scene that opens, or with what stops it, never with one that cannot.
  try {
    const models::composite::CompositeModel model(std::get<models::composite::CompositeDesign>(result.scene.model),
                                                  result.scene.solver.compositeOptions());
    (void)model;
  } catch (const std::bad_alloc&) {
    throw;
  } catch (const std::exception& e) {
    // A fold target without a hinge: the faces beside a crease's end are degenerate there (two
    // straight creases meeting alone at a corner, a zigzag): said where, in the file's terms.
    const std::string what = e.what();
    const auto& design = std::get<models::composite::CompositeDesign>(result.scene.model);
    const std::size_t open = what.find("fold_angles["), close = what.find(']', open);
    if (open != std::string::npos && close != std::string::npos && what.find("has no hinge there") != std::string::npos) {
      const std::size_t target = std::strtoul(what.c_str() + open + 12, nullptr, 10);
      if (target < design.foldAngles.size()) {
        const models::composite::FoldAngleTarget& t = design.foldAngles[target];
        const models::composite::CompositeEdge& edge = design.edges[static_cast<std::size_t>(t.edge)];
        const int v = t.end == 0 ? edge.v0 : edge.v1;
        // Where the vertex lies in the crease pattern (a folded form's vertices are 3D).
        Eigen::Vector2d at(design.vertices(v, 0), design.vertices(v, 1));
        for (const models::composite::DomainCorner& c : design.developmentDomain.corners)
          if (c.vertex == v) at = c.at;
        std::ostringstream where;
        where.precision(4);
        where << "body: the crease pattern cannot fold at (" << at.x() << ", " << at.y() << ") " << sceneUnits
              << (request.format == "svg" ? " from the page's bottom left, y up" : "") << ": the faces beside the crease there are degenerate (creases meeting alone "
              << "at a corner, as in a zigzag of two, cannot fold; every crease needs a face on each side); redraw "
              << "the creases there";
        throw ApproximationInputError("body", where.str());
      }
    }
    throw ApproximationInputError("body", "body: the imported design cannot be solved: " + what);
  }
  return result;
}

}  // namespace devsurf::server
