#include "devsurf/io/FoldImport.h"

#include <algorithm>
#include <cmath>
#include <array>
#include <map>
#include <optional>
#include <set>
#include <stdexcept>
#include <utility>

#include "devsurf/spatial/IsometricUnfolding.h"
#include "devsurf/spatial/PlanarArrangement.h"

namespace devsurf::io {

namespace {

using json = nlohmann::json;

[[noreturn]] void refuse(const std::string& what) { throw std::invalid_argument("FOLD: " + what); }

std::string at(const std::string& key, std::size_t i) { return key + "[" + std::to_string(i) + "]"; }

/// A frame with its inherited keys resolved, and where it came from.
struct FoldFrame {
  json keys;
  std::string name;  ///< "the key frame" or "file_frames[i]"
  bool hasClass(const char* c) const {
    const auto it = keys.find("frame_classes");
    return it != keys.end() && it->is_array() && std::find(it->begin(), it->end(), json(c)) != it->end();
  }
};

std::vector<FoldFrame> foldFrames(const json& doc) {
  std::vector<FoldFrame> frames;
  json key = json::object();
  for (const auto& [k, v] : doc.items())
    if (k.rfind("file_", 0) != 0) key[k] = v;
  frames.push_back({key, "the key frame"});
  const auto list = doc.find("file_frames");
  if (list == doc.end()) return frames;
  if (!list->is_array()) refuse("file_frames is not an array");
  for (std::size_t i = 0; i < list->size(); ++i) {
    const json& f = (*list)[i];
    if (!f.is_object()) refuse(at("file_frames", i) + " is not an object");
    json keys = f;
    if (f.value("frame_inherit", false)) {
      const json parent = f.value("frame_parent", json());
      if (!parent.is_number_integer() || parent.get<int>() < 0 || parent.get<std::size_t>() > i)
        refuse(at("file_frames", i) + ".frame_parent must name an earlier frame");
      for (const auto& [k, v] : frames[parent.get<std::size_t>()].keys.items())
        if (!keys.contains(k)) keys[k] = v;
    }
    frames.push_back({keys, at("file_frames", i)});
  }
  return frames;
}

double frameUnitInMm(const std::string& unit) {
  if (unit == "mm") return 1.0;
  if (unit == "cm") return 10.0;
  if (unit == "m") return 1000.0;
  if (unit == "um") return 1e-3;
  if (unit == "nm") return 1e-6;
  if (unit == "in") return 25.4;
  if (unit == "pt") return 25.4 / 72.0;
  return 0.0;
}

/// vertices_coords as n×3 (missing coordinates 0), naming the frame and entry of what is wrong.
Eigen::MatrixX3d frameCoordinates(const FoldFrame& frame, const char* key = "vertices_coords") {
  const auto it = frame.keys.find(key);
  if (it == frame.keys.end()) refuse(frame.name + " has no " + key);
  if (!it->is_array()) refuse(frame.name + ": " + key + " is not an array");
  Eigen::MatrixX3d out = Eigen::MatrixX3d::Zero(static_cast<Eigen::Index>(it->size()), 3);
  for (std::size_t i = 0; i < it->size(); ++i) {
    const json& c = (*it)[i];
    if (!c.is_array() || c.size() < 2 || c.size() > 3) refuse(frame.name + ": " + at(key, i) + " must be 2 or 3 numbers");
    for (std::size_t d = 0; d < c.size(); ++d) {
      if (!c[d].is_number()) refuse(frame.name + ": " + at(key, i) + " must be 2 or 3 numbers");
      const double value = c[d].get<double>();
      if (!std::isfinite(value)) refuse(frame.name + ": " + at(key, i) + " is not finite");
      // Beyond this the arrangement's tolerances (relative to the extent) lose every short edge.
      if (std::abs(value) > 1e9) refuse(frame.name + ": " + at(key, i) + " is too large (coordinates are at most 1e9)");
      out(static_cast<Eigen::Index>(i), static_cast<Eigen::Index>(d)) = value;
    }
  }
  return out;
}

/// The same points (rows), to 1e-9 of their extent.
bool sameCoordinates(const Eigen::MatrixX3d& a, const Eigen::MatrixX3d& b) {
  if (a.rows() != b.rows() || a.rows() == 0) return false;
  const double extent = (a.colwise().maxCoeff() - a.colwise().minCoeff()).norm();
  return (a - b).cwiseAbs().maxCoeff() <= 1e-9 * std::max(extent, 1.0);
}

/// Whether all points lie in the plane z = 0 (up to round-off against their extent).
bool isFlat(const Eigen::MatrixX3d& points) {
  if (points.rows() == 0) return true;
  const double extent = (points.colwise().maxCoeff() - points.colwise().minCoeff()).norm();
  return points.col(2).cwiseAbs().maxCoeff() <= 1e-9 * std::max(extent, 1e-300);
}

std::vector<std::vector<int>> frameFaces(const FoldFrame& frame, int vertexCount) {
  std::vector<std::vector<int>> faces;
  const auto it = frame.keys.find("faces_vertices");
  if (it == frame.keys.end()) return faces;
  if (!it->is_array()) refuse("faces_vertices is not an array");
  for (std::size_t f = 0; f < it->size(); ++f) {
    const json& loop = (*it)[f];
    if (!loop.is_array() || loop.size() < 3) refuse(at("faces_vertices", f) + " must list at least 3 vertices");
    std::vector<int> ids;
    for (const json& v : loop) {
      if (!v.is_number_integer() || v.get<long long>() < 0 || v.get<long long>() >= vertexCount)
        refuse(at("faces_vertices", f) + " has a vertex id out of range [0, " + std::to_string(vertexCount) + ")");
      ids.push_back(v.get<int>());
    }
    faces.push_back(std::move(ids));
  }
  return faces;
}

}  // namespace

FoldImport importFoldDocument(const json& doc) {
  if (!doc.is_object()) refuse("the document is not a JSON object");
  FoldImport result;
  CreasePattern& p = result.pattern;
  for (const char* key : {"file_title", "frame_title"})
    if (const auto t = doc.find(key); p.title.empty() && t != doc.end() && t->is_string()) p.title = t->get<std::string>();

  const std::vector<FoldFrame> frames = foldFrames(doc);
  // Which frame is the development, which the folded state.
  const FoldFrame* development = nullptr;
  const FoldFrame* folded = nullptr;
  for (const FoldFrame& f : frames)
    if (!development && f.keys.contains("vertices_coords") && f.hasClass("creasePattern")) development = &f;
  for (const FoldFrame& f : frames)
    if (!development && f.keys.contains("vertices_coords") && !f.hasClass("foldedForm") && isFlat(frameCoordinates(f)))
      development = &f;
  for (const FoldFrame& f : frames) {
    if (folded || !f.keys.contains("vertices_coords") || !f.hasClass("foldedForm")) continue;
    const Eigen::MatrixX3d coordinates = frameCoordinates(f);
    if (isFlat(coordinates)) {
      // The sheet as it lies (a design exported before it was folded) says nothing to note.
      const bool unfolded = development && development->keys.contains("vertices_coords") &&
                            sameCoordinates(frameCoordinates(*development), coordinates);
      if (!unfolded)
        result.notes.push_back({f.name, "a flat-folded form (every fold at 180°) cannot be a surface's folded state; "
                                        "the crease pattern is imported flat"});
      if (!development && f.keys.contains("vertices_flatUnfoldCoords")) development = &f;
      continue;
    }
    folded = &f;
  }
  if (!development && !folded) {
    for (const FoldFrame& f : frames)
      if (!development && f.keys.contains("vertices_flatUnfoldCoords")) development = &f;
    if (!development) refuse("no frame has vertices_coords of a crease pattern or a folded form");
  }
  const FoldFrame& topology = development ? *development : *folded;

  // Units.
  if (const auto u = topology.keys.find("frame_unit"); u != topology.keys.end() && u->is_string()) {
    const std::string unit = u->get<std::string>();
    if (frameUnitInMm(unit) > 0.0) {
      result.unit = unit;
      p.unitToMm = frameUnitInMm(unit);
    } else if (unit != "unit") {
      result.notes.push_back({"frame_unit", "\"" + unit + "\" is not a FOLD unit; coordinates read as millimetres"});
    }
  }

  // Coordinates.
  Eigen::MatrixX3d devCoords;
  if (development) {
    const bool flatUnfold = development->hasClass("foldedForm") || !development->keys.contains("vertices_coords");
    devCoords = frameCoordinates(*development, flatUnfold ? "vertices_flatUnfoldCoords" : "vertices_coords");
    if (!isFlat(devCoords)) refuse(development->name + ": the crease pattern's coordinates are not in the plane z = 0");
  }
  Eigen::MatrixX3d foldedCoords;
  if (folded) {
    foldedCoords = frameCoordinates(*folded);
    if (development && foldedCoords.rows() != devCoords.rows()) {
      result.notes.push_back({folded->name, "the folded form has " + std::to_string(foldedCoords.rows()) +
                                                " vertices, the crease pattern " + std::to_string(devCoords.rows()) +
                                                "; the folded form is left out"});
      foldedCoords.resize(0, 3);
      folded = nullptr;
    }
  }
  const int n = static_cast<int>(development ? devCoords.rows() : foldedCoords.rows());
  if (n == 0) refuse("vertices_coords is empty");

  // Faces and edges as the file gives them.
  std::vector<std::vector<int>> faces = frameFaces(topology, n);
  std::vector<std::array<int, 2>> edgeEnds;
  if (const auto ev = topology.keys.find("edges_vertices"); ev != topology.keys.end()) {
    if (!ev->is_array()) refuse("edges_vertices is not an array");
    for (std::size_t e = 0; e < ev->size(); ++e) {
      const json& pair = (*ev)[e];
      if (!pair.is_array() || pair.size() != 2) refuse(at("edges_vertices", e) + " is not a pair of vertex ids");
      std::array<int, 2> ends{};
      for (int k = 0; k < 2; ++k) {
        if (!pair[k].is_number_integer() || pair[k].get<long long>() < 0 || pair[k].get<long long>() >= n)
          refuse(at("edges_vertices", e) + " has a vertex id out of range [0, " + std::to_string(n) + ")");
        ends[k] = pair[k].get<int>();
      }
      if (ends[0] == ends[1]) refuse(at("edges_vertices", e) + " joins vertex " + std::to_string(ends[0]) + " to itself");
      edgeEnds.push_back(ends);
    }
  }
  const std::size_t fileEdges = edgeEnds.size();
  std::vector<std::optional<EdgeAssignment>> assignments(fileEdges);
  std::vector<std::optional<double>> foldAngles(fileEdges);
  if (const auto ea = topology.keys.find("edges_assignment"); ea != topology.keys.end()) {
    if (!ea->is_array() || ea->size() != fileEdges) refuse("edges_assignment must have one letter per edge of edges_vertices");
    for (std::size_t e = 0; e < fileEdges; ++e) {
      if (!(*ea)[e].is_string()) refuse(at("edges_assignment", e) + " is not a string");
      try {
        assignments[e] = parseFoldAssignment((*ea)[e].get<std::string>());
      } catch (const std::invalid_argument&) {
        refuse(at("edges_assignment", e) + ": \"" + (*ea)[e].get<std::string>() + "\" is not one of B M V F U C J");
      }
    }
  }
  // FOLD 1.1 and later spell it edges_foldAngle; FOLD 1.0 files (and tools that still write them)
  // edges_foldAngles, in the same degrees.
  std::string foldAngleKey = "edges_foldAngle";
  auto ef = topology.keys.find(foldAngleKey);
  if (ef == topology.keys.end()) {
    foldAngleKey = "edges_foldAngles";
    ef = topology.keys.find(foldAngleKey);
    if (ef != topology.keys.end())
      result.notes.push_back({foldAngleKey, "read as edges_foldAngle (its FOLD 1.0 spelling)"});
  }
  if (ef != topology.keys.end()) {
    if (!ef->is_array() || ef->size() != fileEdges) refuse(foldAngleKey + " must have one entry per edge of edges_vertices");
    for (std::size_t e = 0; e < fileEdges; ++e) {
      const json& a = (*ef)[e];
      if (a.is_null()) continue;
      if (!a.is_number() || !std::isfinite(a.get<double>()) || std::abs(a.get<double>()) > 180.0)
        refuse(at(foldAngleKey, e) + " must be a number of degrees in [-180, 180]");
      foldAngles[e] = a.get<double>();
    }
  }

  // The curves devsurf's own export drew as chains of edges (one crease each).
  std::vector<int> curveOfFileEdge;
  if (const auto ec = topology.keys.find("edges_devsurf:curve"); ec != topology.keys.end()) {
    if (!ec->is_array() || ec->size() != fileEdges) refuse("edges_devsurf:curve must have one entry per edge of edges_vertices");
    for (std::size_t e = 0; e < fileEdges; ++e) {
      const json& c = (*ec)[e];
      if (!c.is_null() && !(c.is_number_integer() && c.get<long long>() >= 0 && c.get<long long>() <= 1000000000))
        refuse(at("edges_devsurf:curve", e) + " must be a curve id (an integer ≥ 0) or null");
      curveOfFileEdge.push_back(c.is_null() ? -1 : c.get<int>());
    }
  }
  const auto curveOf = [&curveOfFileEdge](int source) {
    return source >= 0 && static_cast<std::size_t>(source) < curveOfFileEdge.size() ? curveOfFileEdge[static_cast<std::size_t>(source)] : -1;
  };
  std::vector<int> patternEdgeCurves;  // per p.edges entry, as they are added

  // Edges a composite kept smooth (devsurf's own FOLD export, CreaseEdge::proposed): flat ones
  // stay smooth when read back instead of becoming hinges that fold freely.
  std::vector<bool> smooth(fileEdges, false);
  if (const auto es = topology.keys.find("edges_devsurf:smooth"); es != topology.keys.end()) {
    if (!es->is_array() || es->size() != fileEdges) refuse("edges_devsurf:smooth must have one entry per edge of edges_vertices");
    for (std::size_t e = 0; e < fileEdges; ++e) {
      const json& v = (*es)[e];
      if (!v.is_boolean() && !v.is_null()) refuse(at("edges_devsurf:smooth", e) + " must be true, false or null");
      if (!v.is_boolean() || !v.get<bool>()) continue;
      if (assignments[e] && *assignments[e] != EdgeAssignment::Flat)
        result.notes.push_back({at("edges_devsurf:smooth", e), "smooth, but not a flat (F) edge; read as its assignment says"});
      else
        smooth[e] = true;
    }
  }

  // The development of a folded form without one: unfold it from its own edge lengths.
  if (!development) {
    if (faces.empty()) refuse(folded->name + ": a folded form without a crease pattern needs faces_vertices to be unfolded");
    std::vector<Eigen::Vector3d> points(n);
    for (int i = 0; i < n; ++i) points[i] = foldedCoords.row(i).transpose();
    const spatial::FlatLayout layout = spatial::unfoldPieces(points, faces, std::vector<int>(faces.size(), 0));
    devCoords = Eigen::MatrixX3d::Zero(n, 3);
    std::vector<bool> placed(n, false);
    for (Eigen::Index k = 0; k < layout.vertices.rows(); ++k) {
      devCoords.row(layout.pointOfVertex[k]).head<2>() = layout.vertices.row(k);
      placed[layout.pointOfVertex[k]] = true;
    }
    std::vector<std::vector<int>> kept;
    for (std::size_t f = 0; f < faces.size(); ++f) {
      if (layout.polygons[f].empty()) {
        result.notes.push_back({at("faces_vertices", f), "not joined to the sheet through an edge; left out"});
        continue;
      }
      kept.push_back(faces[f]);
    }
    faces = std::move(kept);
    if (layout.lengthErrorMax > 1e-6)
      result.notes.push_back({folded->name, "the folded form is not an isometric image of one flat sheet: unfolded, edge "
                                            "lengths differ by up to " + std::to_string(100.0 * layout.lengthErrorMax) + " %"});
    result.notes.push_back({folded->name, "no crease pattern in the file: the development is the folded form unfolded"});
  }

  // Faces counter-clockwise in the development.
  Eigen::MatrixX2d dev2 = devCoords.leftCols<2>();
  if (!faces.empty()) {
    int clockwise = 0;
    for (const auto& f : faces)
      if (spatial::loopSignedArea2(dev2, f) < 0.0) ++clockwise;
    if (2 * clockwise > static_cast<int>(faces.size())) {
      // The sheet is seen from its back: mirror the development (x ↦ −x) rather than reverse faces,
      // so the folded state keeps its orientation.
      dev2.col(0) = -dev2.col(0);
      result.notes.push_back({"faces_vertices", "clockwise in the crease pattern; the pattern is mirrored (x ↦ −x) so the "
                                                "faces run counter-clockwise"});
    }
    for (std::size_t f = 0; f < faces.size(); ++f) {
      const double area2 = spatial::loopSignedArea2(dev2, faces[f]);
      if (area2 < 0.0) {
        std::reverse(faces[f].begin(), faces[f].end());
        result.notes.push_back({at("faces_vertices", f), "runs against its neighbours; reversed"});
      } else if (area2 == 0.0) {
        refuse(at("faces_vertices", f) + " has zero area in the crease pattern");
      }
    }
  }

  p.vertices2d = dev2;
  if (folded) p.vertices3d = foldedCoords;
  std::map<std::pair<int, int>, int> edgeOfPair;
  auto assignmentOf = [&assignments](std::size_t e) { return assignments[e]; };
  if (faces.empty()) {
    // Faces from the planar arrangement of the edges.
    if (edgeEnds.empty()) refuse("neither faces_vertices nor edges_vertices: nothing to import");
    spatial::PlanarArrangementOptions arrangementOptions;
    arrangementOptions.bridgeIslands = true;
    spatial::PlanarArrangement arrangement = spatial::planarArrangement(dev2, edgeEnds, arrangementOptions);
    // Holes: faces that boundary (B) or cut (C) edges inside the sheet wall off from its outline.
    if (const int holes = spatial::cutOutHoles(arrangement, [&assignmentOf](int source) {
          const auto a = assignmentOf(static_cast<std::size_t>(source));
          return a && (*a == EdgeAssignment::Boundary || *a == EdgeAssignment::Cut);
        }))
      result.notes.push_back({"edges_assignment", std::to_string(holes) + " face(s) walled off from the sheet's outline by "
                                                  "boundary (B) or cut (C) edges; cut out as holes"});
    for (const auto& [i, j] : arrangement.crossings)
      result.notes.push_back({at("edges_vertices", i), "crosses or touches " + at("edges_vertices", j) + "; split there"});
    for (int s : arrangement.unusedSegments)
      result.notes.push_back({at("edges_vertices", s), "dangling, of zero length or apart from the sheet; left out"});
    if (arrangement.islands > 0)
      result.notes.push_back({"edges_vertices", std::to_string(arrangement.islands) +
                                                    " island(s) inside the sheet not bridged (no straight bridge "
                                                    "fits, or past the bound on bridging work); left out"});
    if (arrangement.bridgedIslands > 0)
      result.notes.push_back({"edges_vertices", std::to_string(arrangement.bridgedIslands) +
                                                    " island(s) inside the sheet (edges touching nothing around them) joined "
                                                    "to the sheet by two flat edges each"});
    if (arrangement.pinchedFaces > 0)
      result.notes.push_back({"edges_vertices", std::to_string(arrangement.pinchedFaces) +
                                                    " face(s) touching themselves at a vertex; left out"});
    if (arrangement.faces.empty()) refuse("edges_vertices enclose no face");
    for (int i = 0; i < n; ++i)
      if (arrangement.mergedInto[i] != i)
        result.notes.push_back({at("vertices_coords", i), "coincides with vertex " + std::to_string(arrangement.mergedInto[i]) + "; merged"});
    p.vertices2d = arrangement.points;
    if (p.vertices3d.rows() > 0 && arrangement.points.rows() != n) {
      result.notes.push_back({folded->name, "crossing edges were split (or a bridge to an island added a point), so the folded form no longer fits; left out"});
      p.vertices3d.resize(0, 3);
    }
    faces = arrangement.faces;
    std::map<std::pair<int, int>, int> faceCountOfPair;
    for (const auto& f : arrangement.faces)
      for (std::size_t k = 0; k < f.size(); ++k) ++faceCountOfPair[std::minmax(f[k], f[(k + 1) % f.size()])];
    for (std::size_t s = 0; s < arrangement.segments.size(); ++s) {
      const int source = arrangement.sourceOfSegment[s];
      CreaseEdge edge;
      edge.v0 = arrangement.segments[s][0];
      edge.v1 = arrangement.segments[s][1];
      const auto faceCount = faceCountOfPair.find(std::minmax(edge.v0, edge.v1));
      if (faceCount == faceCountOfPair.end()) continue;  // inside a hole
      if (source < 0) {  // a bridge to an island
        edge.proposed = true;
        edge.assignment = faceCount->second == 1 ? EdgeAssignment::Boundary : EdgeAssignment::Flat;
        edgeOfPair[std::minmax(edge.v0, edge.v1)] = static_cast<int>(p.edges.size());
        p.edges.push_back(edge);
        patternEdgeCurves.push_back(-1);
        continue;
      }
      if (assignmentOf(source)) edge.assignment = *assignmentOf(source);
      edge.foldAngle = foldAngles[source];
      edge.proposed = smooth[static_cast<std::size_t>(source)];
      edgeOfPair[std::minmax(edge.v0, edge.v1)] = static_cast<int>(p.edges.size());
      p.edges.push_back(edge);
      patternEdgeCurves.push_back(curveOf(source));
    }
  } else {
    for (std::size_t e = 0; e < fileEdges; ++e) {
      const auto key = std::minmax(edgeEnds[e][0], edgeEnds[e][1]);
      if (edgeOfPair.count(key)) {
        result.notes.push_back({at("edges_vertices", e), "repeats " + at("edges_vertices", edgeOfPair[key]) + "; left out"});
        continue;
      }
      CreaseEdge edge;
      edge.v0 = edgeEnds[e][0];
      edge.v1 = edgeEnds[e][1];
      if (assignments[e]) edge.assignment = *assignments[e];
      edge.foldAngle = foldAngles[e];
      edge.proposed = smooth[e];
      edgeOfPair[key] = static_cast<int>(p.edges.size());
      p.edges.push_back(edge);
      patternEdgeCurves.push_back(curveOf(static_cast<int>(e)));
    }
  }
  // Edges the faces need but the file does not list, and assignments the file leaves out.
  std::map<std::pair<int, int>, int> facesOfPair;
  for (const auto& f : faces)
    for (std::size_t k = 0; k < f.size(); ++k) ++facesOfPair[std::minmax(f[k], f[(k + 1) % f.size()])];
  for (const auto& [key, count] : facesOfPair) {
    if (edgeOfPair.count(key)) continue;
    CreaseEdge edge;
    edge.v0 = key.first;
    edge.v1 = key.second;
    edge.assignment = count == 1 ? EdgeAssignment::Boundary : EdgeAssignment::Flat;
    edgeOfPair[key] = static_cast<int>(p.edges.size());
    p.edges.push_back(edge);
    patternEdgeCurves.push_back(-1);
  }
  if (!curveOfFileEdge.empty()) result.edgeCurves = std::move(patternEdgeCurves);
  const bool anyAssignment = std::any_of(assignments.begin(), assignments.end(), [](const auto& a) { return a.has_value(); });
  if (!anyAssignment) {
    // No edges_assignment (optional in FOLD): the outline is B; an inside edge with a fold angle
    // folds by its sign (FOLD: positive is a valley), the others are read as U, flat — said in a
    // note, since a drawn crease silently flat was a new user's surprise.
    int flat = 0, bySign = 0;
    for (auto& edge : p.edges) {
      const auto it = facesOfPair.find(std::minmax(edge.v0, edge.v1));
      const int count = it == facesOfPair.end() ? 0 : it->second;
      if (count == 1) {
        edge.assignment = EdgeAssignment::Boundary;
      } else if (edge.foldAngle && *edge.foldAngle != 0.0 && !edge.proposed) {  // smooth stays flat
        edge.assignment = *edge.foldAngle > 0.0 ? EdgeAssignment::Valley : EdgeAssignment::Mountain;
        ++bySign;
      } else {
        edge.assignment = EdgeAssignment::Flat;
        if (!edge.proposed) ++flat;
      }
    }
    if (flat > 0 || bySign > 0) {
      std::string note = "missing: ";
      if (bySign > 0) note += std::to_string(bySign) + " edge(s) inside the sheet fold by the sign of edges_foldAngle";
      if (bySign > 0 && flat > 0) note += ", ";
      if (flat > 0)
        note += std::to_string(flat) + " edge(s) inside the sheet read as unassigned (U): flat, not folded (give them M or V "
                                       "in edges_assignment to fold them)";
      result.notes.push_back({"edges_assignment", note});
    }
  }
  // Fold angles must agree with the assignment (CreasePattern::validate): drop those that do not.
  for (std::size_t e = 0; e < p.edges.size(); ++e) {
    CreaseEdge& edge = p.edges[e];
    if (!edge.foldAngle) continue;
    const double a = *edge.foldAngle;
    const bool fits = edge.assignment == EdgeAssignment::Mountain   ? a <= 0.0
                      : edge.assignment == EdgeAssignment::Valley ? a >= 0.0
                                                                  : a == 0.0;
    if (!fits) {
      result.notes.push_back({"edges_foldAngle", "edge " + std::to_string(edge.v0) + "–" + std::to_string(edge.v1) + ": " +
                                                     std::to_string(a) + "° does not fit its assignment " +
                                                     assignmentName(edge.assignment) + "; left out"});
      edge.foldAngle.reset();
    }
  }
  p.faces = std::move(faces);
  try {
    p.validate();
  } catch (const std::invalid_argument& e) {
    refuse(e.what());
  }
  return result;
}

FoldImport importFoldText(const std::string& text) {
  json doc;
  try {
    doc = json::parse(text);
  } catch (const json::exception& e) {  // a syntax error, or a number out of range (1e400)
    refuse(std::string("not JSON: ") + e.what());
  }
  return importFoldDocument(doc);
}

}  // namespace devsurf::io
