// The drag-stress suite (issue 11): every preset in examples/ — discovered, so a new preset is
// covered without editing this file — opened as a session exactly as the daemon opens a demo, and
// dragged as the web app drags: a path of messages (one per animation frame), then drag_end. For
// every preset several targets (a corner, a crease vertex, an interior control point), three
// directions (up, sideways, inward) and three lengths (10%, 25%, 40% of the bounding-box
// diagonal). The quality is checked while dragging (every streamed iterate) and after the release
// — from the session's metrics and, independently, recomputed from its OBJ and FOLD exports.

#include <gtest/gtest.h>

#include <map>
#include <set>

#include <algorithm>
#include <chrono>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <set>
#include <sstream>

#include <Eigen/Eigenvalues>

#include "devsurf/server/Session.h"
#include "devsurf/server/Tokens.h"
#include "server/SessionTesting.h"
#include "support/ExportChecks.h"
#include "support/Presets.h"

namespace devsurf::server {
namespace {

using nlohmann::json;
namespace checks = devsurf::testing;
using testing::Inbox;
using testing::ManualExecutor;

using devsurf::testing::presetFiles;
using devsurf::testing::readPreset;

Eigen::Vector3d vec(const json& p) { return {p[0].get<double>(), p[1].get<double>(), p[2].get<double>()}; }

/// A point a user can grab, with where it is in the scene.
struct DragTarget {
  std::string role;  ///< "corner", "crease vertex", "interior point"
  json target;
  Eigen::Vector3d position;
};

/// Every control point of the scene's model (for the bounding box and the directions).
std::vector<Eigen::Vector3d> allPoints(const json& model) {
  std::vector<Eigen::Vector3d> pts;
  for (const char* c : {"a", "b", "c1", "c2", "p", "q"})
    if (model.contains(c))
      for (const json& p : model[c]["points"]) pts.push_back(vec(p));
  if (model.contains("vertices"))
    for (const json& p : model["vertices"]) pts.push_back(vec(p));
  if (model.contains("mesh"))  // quad_mesh: M
    for (const json& p : model["mesh"]["vertices"]) pts.push_back(vec(p));
  if (model.contains("control"))  // quad_mesh spline surface: its control points
    for (const json& p : model["control"]["points"]) pts.push_back(vec(p));
  if (model.contains("edges"))
    for (const json& e : model["edges"])
      for (const json& p : e.value("points", json::array())) pts.push_back(vec(p));
  return pts;
}

bool isFixed(const json& model, const json& target) {
  for (const json& f : model.value("fixed", json::array())) {
    const json key = f.is_number_integer() ? json{{"vertex", f}} : f;  // quad_mesh: a vertex of M by its index
    if (key == target) return true;
  }
  return false;
}

/// The targets of a drag: for composites a boundary corner, a vertex of a crease and an interior
/// control point of a crease (each not fixed, the farthest from the centre of its kind); for the
/// curve-based kinds an end of the second curve, an end of the first and an interior point.
std::vector<DragTarget> dragTargets(const json& model, const Eigen::Vector3d& centre) {
  std::vector<DragTarget> out;
  const std::string kind = model["kind"];
  auto farthest = [&centre](std::vector<DragTarget> candidates) {
    return *std::max_element(candidates.begin(), candidates.end(), [&centre](const DragTarget& a, const DragTarget& b) {
      return (a.position - centre).norm() < (b.position - centre).norm();
    });
  };
  if (kind == "composite") {
    const json& edges = model["edges"];
    std::vector<int> faceCount(edges.size(), 0);
    for (const json& f : model["faces"])
      for (const json& e : f) ++faceCount[e.get<int>()];
    std::vector<DragTarget> corners, creaseVertices, interior, anyInterior;
    std::set<int> seen;
    for (std::size_t e = 0; e < edges.size(); ++e) {
      const std::string crease = edges[e].value("crease", "");
      const bool isCrease = crease == "fold" || crease == "geodesic" || crease == "straight";
      for (int v : {edges[e]["v"][0].get<int>(), edges[e]["v"][1].get<int>()}) {
        const json t = {{"vertex", v}};
        if (isFixed(model, t)) continue;
        const DragTarget d{"", t, vec(model["vertices"][v])};
        if (faceCount[e] == 1) corners.push_back({"corner", t, d.position});
        if (isCrease) creaseVertices.push_back({"crease vertex", t, d.position});
      }
      const json& pts = edges[e].value("points", json::array());
      if (!pts.empty()) {
        const int k = static_cast<int>(pts.size()) / 2;
        const json t = {{"edge", static_cast<int>(e)}, {"index", k + 1}};
        if (isFixed(model, t)) continue;
        (isCrease ? interior : anyInterior).push_back({"interior point", t, vec(pts[k])});
      }
    }
    if (!corners.empty()) out.push_back(farthest(corners));
    if (!creaseVertices.empty()) {
      std::vector<DragTarget> others;
      for (const DragTarget& c : creaseVertices)
        if (out.empty() || c.target != out.front().target) others.push_back(c);
      if (!others.empty()) out.push_back(farthest(others));
    }
    if (!interior.empty()) out.push_back(farthest(interior));
    else if (!anyInterior.empty()) out.push_back(farthest(anyInterior));
    return out;
  }
  if (kind == "quad_mesh" && model.contains("control")) {
    // A spline surface: its control points, as the web app drags them — the boundary point of a
    // patch farthest from the centre and the interior point farthest from it.
    std::set<int> rimPoints;
    const json& c = model["control"];
    json patches = c.value("patches", json::array());
    if (patches.empty()) {
      json indices = json::array();
      for (std::size_t i = 0; i < c["points"].size(); ++i) indices.push_back(static_cast<int>(i));
      patches.push_back({{"rows", c["rows"]}, {"columns", c["columns"]}, {"indices", indices}});
    }
    for (const json& p : patches) {
      const int rows = p["rows"], columns = p["columns"];
      for (int r = 0; r < rows; ++r)
        for (int k = 0; k < columns; ++k)
          if (r == 0 || k == 0 || r == rows - 1 || k == columns - 1)
            rimPoints.insert(p["indices"][static_cast<std::size_t>(r * columns + k)].get<int>());
    }
    std::vector<DragTarget> rim, inner;
    for (std::size_t i = 0; i < c["points"].size(); ++i) {
      const json t = {{"on", "control"}, {"vertex", static_cast<int>(i)}};
      if (isFixed(model, t)) continue;
      const bool onRim = rimPoints.count(static_cast<int>(i)) > 0;
      (onRim ? rim : inner).push_back({onRim ? "control corner" : "control interior", t, vec(c["points"][i])});
    }
    if (!rim.empty()) out.push_back(farthest(rim));
    if (!inner.empty()) out.push_back(farthest(inner));
    return out;
  }
  if (kind == "quad_mesh") {
    // M's vertices (M′'s when only the unfolding moves): the boundary vertex farthest from the
    // centre, the boundary vertex nearest to it and the interior vertex farthest from it.
    const bool onUnfolding = model.value("variables", "mesh") == "unfolding";
    const json& points = model[onUnfolding ? "unfolding" : "mesh"]["vertices"];
    std::map<std::pair<int, int>, int> edgeFaces;
    for (const json& f : model["mesh"]["faces"])
      for (std::size_t k = 0; k < f.size(); ++k) {
        const int a = f[k], b = f[(k + 1) % f.size()];
        ++edgeFaces[{std::min(a, b), std::max(a, b)}];
      }
    std::set<int> boundary;
    for (const auto& [e, n] : edgeFaces)
      if (n == 1) boundary.insert({e.first, e.second});
    std::vector<DragTarget> rim, inner;
    for (std::size_t v = 0; v < points.size(); ++v) {
      json t = {{"vertex", static_cast<int>(v)}};
      if (onUnfolding) t = {{"on", "unfolding"}, {"vertex", static_cast<int>(v)}};
      if (isFixed(model, t) || isFixed(model, json{{"on", onUnfolding ? "unfolding" : "mesh"}, {"vertex", static_cast<int>(v)}}))
        continue;
      const json& p = points[v];
      const Eigen::Vector3d position(p[0].get<double>(), p[1].get<double>(), p.size() > 2 ? p[2].get<double>() : 0.0);
      (boundary.count(static_cast<int>(v)) ? rim : inner).push_back({boundary.count(static_cast<int>(v)) ? "corner" : "interior point", t, position});
    }
    if (!rim.empty()) {
      out.push_back(farthest(rim));
      out.push_back(*std::min_element(rim.begin(), rim.end(), [&centre](const DragTarget& a, const DragTarget& b) {
        return (a.position - centre).norm() < (b.position - centre).norm();
      }));
      out.back().role = "rim point";
    }
    if (!inner.empty()) out.push_back(farthest(inner));
    return out;
  }
  const bool quasi = kind == "quasi_strip", conical = kind == "conical_strip";
  const std::string first = quasi ? "c1" : conical ? "p" : "a", second = quasi ? "c2" : conical ? "q" : "b";
  auto point = [&model](const std::string& curve, int index) {
    return vec(model[curve]["points"][static_cast<std::size_t>(index)]);
  };
  auto add = [&](const std::string& role, const std::string& curve, std::vector<int> indices) {
    for (int i : indices) {
      const json t = {{"curve", curve}, {"index", i}};
      if (!isFixed(model, t)) {
        out.push_back({role, t, point(curve, i)});
        return;
      }
    }
  };
  const int n2 = static_cast<int>(model[second]["points"].size()), n1 = static_cast<int>(model[first]["points"].size());
  add("corner", second, {n2 - 1, 0});
  add("corner", first, {n1 - 1, 0});
  add("interior point", second, {n2 / 2, n2 / 2 + 1, n2 / 2 - 1});
  return out;
}

/// What one drag did.
struct DragOutcome {
  std::string label;
  int streamed = 0;
  double streamedFlatnessMax = 0.0;  ///< composites: largest δ_max of a streamed iterate
  double streamedWarpMax = 0.0;      ///< strips: largest max warp of a streamed iterate
  json solved;                       ///< the `solved` message
  json metrics;                      ///< the session's metrics after the release
  int errors = 0;
  std::string firstError;
  checks::FlatnessStats obj;        ///< δ recomputed from the OBJ export
  checks::FoldDevelopmentCheck fold;  ///< from the FOLD export (composites with a development)
  double rulingMinRatio = 1.0;       ///< strips: narrowest ruling of the OBJ over the narrowest at the start
  std::string foldError;             ///< the FOLD export failed
  double releaseMs = 0.0;
  double handleLag = 0.0;            ///< distance of the released point from the pointer / drag length
  int stripFlips = 0;                ///< strips: development triangles turned over (OBJ export)
  double objLengthError = 0.0;       ///< quad_mesh: L-Err recomputed from the obj and unfolding_obj exports
  bool conformal = false;            ///< quad_mesh: a conformal design (L-Err is not its measure)
  std::vector<std::string> nonFinite;  ///< metrics that are not finite
};

/// Narrowest ruling of a strip's OBJ export (200 × 8 grid: ruling i is vertices 8i … 8i+7).
double narrowestRuling(const checks::ObjMesh& mesh) {
  double narrowest = std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i + 7 < mesh.vertices.size(); i += 8)
    narrowest = std::min(narrowest, (mesh.vertices[i + 7] - mesh.vertices[i]).norm());
  return narrowest;
}

/// Where the scene has a target now.
Eigen::Vector3d currentPosition(const json& model, const json& target) {
  if (model["kind"] == "quad_mesh") {
    const std::string on = target.value("on", "mesh");
    const json& p = on == "control" ? model["control"]["points"][target["vertex"].get<std::size_t>()]
                                    : model[on == "unfolding" ? "unfolding" : "mesh"]["vertices"][target["vertex"].get<std::size_t>()];
    return {p[0].get<double>(), p[1].get<double>(), p.size() > 2 ? p[2].get<double>() : 0.0};
  }
  if (target.contains("vertex")) return vec(model["vertices"][target["vertex"].get<std::size_t>()]);
  if (target.contains("edge"))
    return vec(model["edges"][target["edge"].get<std::size_t>()]["points"][target["index"].get<std::size_t>() - 1]);
  return vec(model[target["curve"].get<std::string>()]["points"][target["index"].get<std::size_t>()]);
}

/// The preset as the daemon opens a demo (solved first), solved once per preset: every drag of a
/// preset starts from the same state, and the solve is deterministic (spline-watertight: 5.9 s).
/// A preset's document: "name.json" as shipped, or "ruling:name.json" with its crease rows on the
/// faces' rulings (`solver.crease_normals`; the presets, all under 5 000 unknowns, keep the free
/// rows under `auto`).
/// "alternating:name.json" has its development solved apart (`solver.development_solve`).
json presetDocument(const std::string& preset) {
  const std::string ruling = "ruling:", alternating = "alternating:";
  if (preset.rfind(alternating, 0) == 0) {
    json doc = readPreset(preset.substr(alternating.size()));
    doc["solver"]["development_solve"] = "alternating";
    return doc;
  }
  if (preset.rfind(ruling, 0) != 0) return readPreset(preset);
  json doc = readPreset(preset.substr(ruling.size()));
  doc["solver"]["crease_normals"] = "ruling";
  return doc;
}

const proto::Scene& solvedPreset(const std::string& preset) {
  static std::map<std::string, proto::Scene> solved;
  auto found = solved.find(preset);
  if (found == solved.end())
    found = solved.emplace(preset, SceneSolver::solvedScene(proto::sceneFromJson(presetDocument(preset)))).first;
  return found->second;
}

/// The daemon's settings; for quad meshes the release after drag_end is bounded by its iteration
/// count alone: its 2 s time budget made the outcome depend on the machine's load (on a CI run with
/// two heavy suites at once, D-form releases stopped at the budget 0.2 % short of the threshold).
/// Composites keep the budget: their releases run to the iteration cap (200) at ~16 s each, which
/// over 18 drags exceeds the test's timeout, and they meet their thresholds well within 2 s.
/// The drag itself keeps the 25 ms frame budget, as a mouse drag has.
SessionSettings releaseSettingsFor(const proto::Scene& scene) {
  SessionSettings settings;
  if (std::string(proto::modelKind(scene.model)) == "quad_mesh") settings.releaseTimeBudgetMs = 600000.0;
  return settings;
}

struct Fixture {
  ManualExecutor ex;
  std::shared_ptr<Session> session;
  Inbox inbox;
  int pid = 0;
  explicit Fixture(const std::string& preset) {
    const proto::Scene& scene = solvedPreset(preset);
    session = std::make_shared<Session>("drag-stress", scene, Session::Tokens{tokenHash("e"), tokenHash("v")},
                                        releaseSettingsFor(scene), ex.scheduler(), nullptr, nullptr, true);
    pid = session->join(Role::Edit, "stress", inbox.sink());
    ex.runAll();
  }
};

/// Drags `t` by `length` along `direction` in `messages` drag messages, then releases it. The
/// session runs its queue after every `perFrame` messages: 1 is a mouse on a fast connection
/// (every message is solved), more is a slow solver behind the pointer (queued drags of one
/// target coalesce, so only the newest of each batch is solved).
DragOutcome runDrag(const std::string& preset, const DragTarget& t, const Eigen::Vector3d& direction, double length,
                    int messages, int perFrame) {
  Fixture f(preset);
  DragOutcome out;
  const std::string kind = f.session->sceneJson()["model"]["kind"];
  const double startRuling =
      kind == "strip" ? narrowestRuling(checks::parseObj(f.session->exportAs("obj").content)) : 0.0;
  // The start position is the point where the session has it now (demo sessions start solved).
  const Eigen::Vector3d start = currentPosition(f.session->sceneJson()["model"], t.target);
  const Eigen::Vector3d end = start + length * direction;
  f.inbox.messages.clear();
  for (int k = 1; k <= messages; ++k) {
    const Eigen::Vector3d p = start + (end - start) * (static_cast<double>(k) / messages);
    f.session->post(f.pid, {{"type", "drag"}, {"op", k}, {"target", t.target}, {"position", {p.x(), p.y(), p.z()}}});
    if (k % perFrame == 0 || k == messages) f.ex.runAll();
  }
  for (const json& m : f.inbox.ofType("iterate")) {
    ++out.streamed;
    const json& mm = m["metrics"];
    out.streamedFlatnessMax = std::max(out.streamedFlatnessMax, mm.value("face_flatness_max", 0.0));
    out.streamedWarpMax = std::max(out.streamedWarpMax, mm.value("warp_angle_max_deg", 0.0));
  }
  const auto t0 = std::chrono::steady_clock::now();
  f.session->post(f.pid, {{"type", "drag_end"}, {"op", messages + 1}, {"target", t.target}});
  f.ex.runAll();
  out.releaseMs = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  out.handleLag = (currentPosition(f.session->sceneJson()["model"], t.target) - end).norm() / length;
  for (const json& e : f.inbox.ofType("error")) {
    if (out.errors++ == 0) out.firstError = e.dump();
  }
  out.solved = f.inbox.last("solved");
  out.metrics = f.session->metricsJson();
  out.obj = checks::objFlatness(checks::parseObj(f.session->exportAs("obj").content));
  if (kind == "quad_mesh") {
    out.objLengthError = checks::objEdgeLengthError(checks::parseObj(f.session->exportAs("obj").content),
                                                   checks::parseObj(f.session->exportAs("unfolding_obj").content));
    out.conformal = f.session->sceneJson()["model"].value("conformal", false);
  }
  if (kind == "strip") {
    const checks::ObjMesh mesh = checks::parseObj(f.session->exportAs("obj").content);
    out.rulingMinRatio = narrowestRuling(mesh) / startRuling;
    out.stripFlips = checks::stripDevelopmentFlips(mesh, 8);
  }
  for (const auto& [name, value] : out.metrics.items())
    if (value.is_number() && !std::isfinite(value.get<double>())) out.nonFinite.push_back(name);
  if (kind == "composite") {  // the development's crease pattern, or the pieces cut along seams
    try {
      out.fold = checks::checkFoldDevelopment(json::parse(f.session->exportAs("fold").content));
    } catch (const ExportUnavailable& e) {
      if (f.session->sceneJson()["model"].contains("development")) {
        out.foldError = e.what();
        out.fold.flippedFaces = -1;
      }
    } catch (const std::exception& e) {
      out.foldError = e.what();
      out.fold.flippedFaces = -1;
    }
  }
  return out;
}

class DragStress : public ::testing::TestWithParam<std::string> {};

/// What a drag must never do: lose or break the session, tear (a streamed composite iterate above
/// δ 1e-2), fold the development over, pinch a strip, or export what cannot be read back.
/// Composites: no flipped development face (metric, and recomputed from the FOLD export); strips:
/// narrowest ruling ≥ 25 % of the start and no development triangle turned over (both recomputed
/// from the OBJ export).
struct Violations {
  std::vector<std::string> tears;     ///< never allowed
  std::vector<std::string> accuracy;  ///< fabrication thresholds missed (see kAccuracyMissesAllowed)
};

/// The fabrication thresholds of issue 11, after the release. Composites: δ_max ≤ 1e-3 (from the
/// session and, independently, from its OBJ), δ_mean ≤ 2e-4 (OBJ), vertex curvature ≤ 1e-3, an edge
/// length error ≤ 0.5 % (FOLD), `crease_backtrack_max` ≤ 0.05. Strips: max warp ≤ 0.05°. The strips
/// between curves (quasi_strip, conical_strip) keep their input curves, so whatever the drag did to
/// the curves decides their warp: there every metric is finite and the release ends in `solved`.
Violations violations(const std::string& kind, const DragOutcome& o) {
  Violations v;
  auto above = [](std::vector<std::string>& into, const char* what, double value, double limit) {
    if (!(value <= limit)) into.push_back(std::string(what) + " " + std::to_string(value) + " > " + std::to_string(limit));
  };
  if (o.errors > 0) v.tears.push_back("error message: " + o.firstError);
  if (o.solved.is_null()) v.tears.push_back("no solved message after the release");
  for (const std::string& n : o.nonFinite) v.tears.push_back("metric " + n + " is not finite");
  const json& m = o.metrics;
  if (kind == "composite") {
    above(v.tears, "streamed δ_max", o.streamedFlatnessMax, 1e-2);
    above(v.accuracy, "δ_max", m.value("face_flatness_max", 1.0), 1e-3);
    above(v.accuracy, "δ_max (OBJ)", o.obj.max, 1e-3);
    above(v.accuracy, "δ_mean (OBJ)", o.obj.mean, 2e-4);
    above(v.accuracy, "vertex_curvature_max", m.value("vertex_curvature_max", 1.0), 1e-3);
    above(v.accuracy, "crease_backtrack_max", m.value("crease_backtrack_max", 0.0), 0.05);  // as SceneSolver::quality()
    if (m.contains("development_flipped_faces"))
      above(v.tears, "development_flipped_faces", m["development_flipped_faces"].get<double>(), 0.0);
    // The FOLD export (a development's crease pattern, or the pieces cut along seams) whenever
    // the design has one; a development without it is a tear.
    above(v.tears, "flipped faces (FOLD)", o.fold.flippedFaces < 0 ? 1e9 : o.fold.flippedFaces, 0.0);
    if (!o.foldError.empty()) v.tears.push_back("FOLD export: " + o.foldError);
    above(v.accuracy, "edge length error (FOLD)", o.fold.lengthError, 5e-3);
  } else if (kind == "quad_mesh") {
    // Never: M′ folded over. Fabrication: L-Err ≤ 1 % after the release (conformal maps 5 %,
    // Fig. 4: 4.2 %), from the session and independently from the two OBJ exports; glued pairs
    // within 1e-4 of the size. The presets as shipped meet 0.5 % (PresetAsShipped); after a drag of
    // 25 % of the diagonal the D-forms — rigid shapes: two convex domains glue to one surface —
    // end at up to 0.67 % within the 2 s release budget (measured, 18 drags).
    above(v.tears, "unfolding_flipped_faces", m.value("unfolding_flipped_faces", 1.0), 0.0);
    const double limit = o.conformal ? 0.05 : 1e-2;
    above(v.accuracy, "length_error", m.value("length_error", 1.0), limit);
    above(v.accuracy, "length error (OBJ)", o.objLengthError, limit);
    above(v.accuracy, "glue_gap_max", m.value("glue_gap_max", 1.0), 1e-4);
  } else if (kind == "strip") {
    if (!(o.rulingMinRatio >= 0.25)) v.tears.push_back("narrowest ruling " + std::to_string(o.rulingMinRatio) + " of the start");
    above(v.tears, "development triangles turned over", o.stripFlips, 0.0);
    above(v.accuracy, "warp_angle_max_deg", m.value("warp_angle_max_deg", 90.0), 0.05);
  }
  return v;
}

/// Drags of one preset that may end outside the fabrication thresholds (never torn). The release
/// runs under a 2 s budget, so a machine under load — CI runs two suites at once — gets fewer
/// iterations than the run that measured (three lengths then, 27 drags a preset; now 12): 0 of the 390 drags (16 presets) missed a threshold in the
/// last full run on 2 cores with two suites in parallel; before the per-side strip-width rows the
/// folded annulus missed 2 (vertex curvature 0.07–0.11). Every miss is printed with its values.
constexpr int kAccuracyMissesAllowed = 1;

TEST_P(DragStress, EveryDragKeepsTheShapeValid) {
  const std::string preset = GetParam();
  const json doc = presetDocument(preset);
  const json& model = doc["model"];
  const std::string kind = model["kind"];
  const bool keepsInput = kind == "quasi_strip" || kind == "conical_strip";
  const std::vector<Eigen::Vector3d> pts = allPoints(model);
  Eigen::Vector3d lo = pts[0], hi = pts[0], centre = Eigen::Vector3d::Zero();
  for (const auto& p : pts) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
    centre += p;
  }
  centre /= static_cast<double>(pts.size());
  const double diagonal = (hi - lo).norm();
  Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
  for (const auto& p : pts) cov += (p - centre) * (p - centre).transpose();
  const Eigen::Vector3d planeNormal = Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(cov).eigenvectors().col(0);

  const std::vector<DragTarget> targets = dragTargets(model, centre);
  ASSERT_FALSE(targets.empty()) << preset << ": no point to drag";
  // quad_mesh rows: "δmax" is the session's length_error, "dev err" the one recomputed from the OBJs.
  std::printf("%-28s %-15s %-8s %4s %9s %9s %9s %9s %9s %4s %8s %6s %8s %5s %6s %s\n", "preset", "target", "dir", "len",
              "drag", kind == "quad_mesh" ? "L-Err" : "δmax", "δmax obj", "δmean obj", "K max", "flip",
              kind == "quad_mesh" ? "L-Err obj" : "dev err", "ruling", "warp", "lag", "rel ms", "reason");
  int drags = 0, misses = 0, pair = 0, targetIndex = 0;
  for (const DragTarget& t : targets) {
    // The shorter drag of this target goes in one direction, a different one per target.
    const int shortDirection = targetIndex++ % 3;
    int directionIndex = 0;
    Eigen::Vector3d inward = centre - t.position;
    inward -= planeNormal * planeNormal.dot(inward);
    if (inward.norm() < 1e-9 * diagonal) inward = planeNormal.unitOrthogonal();
    inward.normalize();
    const Eigen::Vector3d up = planeNormal, sideways = planeNormal.cross(inward).normalized();
    const std::pair<const char*, Eigen::Vector3d> directions[] = {{"up", up}, {"sideways", sideways}, {"inward", inward}};
    const bool variant = preset.find(':') != std::string::npos;
    for (const auto& [dirName, dir] : directions) {
      // Quad meshes: up and inward only (a D-form's release runs to its iteration cap, ~7 s a drag:
      // the sideways drags cost CI ~45 s), one of them per point in turn, the last of a single
      // point both: every direction at least once a preset (both on every point cost CI ~80
      // CPU-seconds more, stop 51).
      if (kind == "quad_mesh") {
        if (std::string(dirName) == "sideways") continue;
        const bool quadOwn = (std::string(dirName) == "up") == ((targetIndex - 1) % 2 == 0);
        if (!quadOwn && targets.size() > 1) continue;
      }
      const int thisDirection = directionIndex++;
      const bool targetsOwnDirection = thisDirection == shortDirection;
      // The solver variants of the composites drag each target in one direction, a different one
      // per target, and the last of fewer than three targets the directions left: every direction
      // once a preset, 3 drags, not 9 (6 cost CI ~105 CPU-seconds; the Examples suite drags the
      // same presets in every direction with the default solver).
      const bool directionLeft = targetIndex == static_cast<int>(targets.size()) && targets.size() < 3 &&
                                 thisDirection >= static_cast<int>(targets.size());
      if (variant && !targetsOwnDirection && !directionLeft) continue;
      // Every drag goes to 40 % of the diagonal (the long drag, in every direction), and one
      // direction of the first two targets also gets a shorter one, 10 % and 25 %; quad_mesh
      // presets one length per direction (a D-form's release takes ~1 s). 11 drags a preset (12
      // with a shorter drag of the third target too, until stop 51): a shorter drag in every
      // direction (18) cost CI ~65 s more, all three lengths (27) ~165 s. The solver variants of
      // the composites (ruling crease rows, the development apart) take the long drags alone
      // (their shorter drags cost CI ~50 s).
      // Composites take the long drags alone since stop 59 (their two shorter drags cost a CI run
      // ~30 test-seconds of the four largest presets' ~120; their solver variants drag them too).
      const bool withShorter = targetsOwnDirection && !variant && targetIndex <= 2 && kind != "composite";
      const double shorter = withShorter && pair++ % 2 == 0 ? 0.10 : 0.25;
      const std::vector<double> fractions = kind == "quad_mesh" ? std::vector<double>{0.25}
                                            : withShorter       ? std::vector<double>{shorter, 0.40}
                                                                : std::vector<double>{0.40};
      for (double fraction : fractions) {
        // ~0.7 s of mouse moves as the web app sends them; the strips between curves rebuild
        // their whole solve per message, so there the queue coalesces them six at a time.
        // DEVSURF_DRAG_ONLY="interior point/inward/25" runs one drag of each preset (for study).
        const char* only = std::getenv("DEVSURF_DRAG_ONLY");
        if (only && std::string(only) != t.role + "/" + dirName + "/" + std::to_string(static_cast<int>(fraction * 100)))
          continue;
        const DragOutcome o = runDrag(preset, t, dir, fraction * diagonal, 24, keepsInput ? 6 : 1);
        ++drags;
        const json& m = o.metrics;
        std::printf("%-28s %-15s %-8s %3.0f%% %9.2e %9.2e %9.2e %9.2e %9.2e %4d %8.2e %6.3f %8.2e %5.2f %6.0f %s\n",
                    preset.substr(0, 28).c_str(), (t.role + " " + t.target.dump()).substr(0, 15).c_str(), dirName,
                    fraction * 100, kind == "composite" ? o.streamedFlatnessMax : o.streamedWarpMax,
                    kind == "quad_mesh" ? m.value("length_error", 0.0) : m.value("face_flatness_max", 0.0), o.obj.max,
                    o.obj.mean, m.value("vertex_curvature_max", 0.0),
                    kind == "strip" ? o.stripFlips : o.fold.flippedFaces,
                    kind == "quad_mesh" ? o.objLengthError : o.fold.lengthError, o.rulingMinRatio,
                    m.value("warp_angle_max_deg", 0.0), o.handleLag, o.releaseMs,
                    o.solved.is_null() ? "-" : o.solved.value("reason", "").c_str());
        std::fflush(stdout);
        const Violations bad = violations(kind, o);
        const std::string what = preset + ": " + t.role + " " + t.target.dump() + " dragged " + dirName + " by " +
                                 std::to_string(static_cast<int>(fraction * 100)) + "% of the diagonal: ";
        for (const std::string& b : bad.tears) ADD_FAILURE() << what << b;
        if (!bad.accuracy.empty()) ++misses;
        for (const std::string& b : bad.accuracy) std::printf("  outside the thresholds: %s%s\n", what.c_str(), b.c_str());
      }
    }
  }
  std::printf("%s: %d drags, %d outside the fabrication thresholds\n", preset.c_str(), drags, misses);
  EXPECT_LE(misses, kAccuracyMissesAllowed) << preset << ": " << misses << " of " << drags
                                            << " drags ended outside the fabrication thresholds (listed above)";
}

INSTANTIATE_TEST_SUITE_P(Examples, DragStress, ::testing::ValuesIn(presetFiles()),
                         devsurf::testing::presetTestName<::testing::TestParamInfo<std::string>>);

/// The same drags on every composite preset with the crease rows on the faces' rulings (what
/// `auto` gives designs from 5 000 unknowns on).
std::vector<std::string> compositePresetsWithRulingCreases() {
  std::vector<std::string> out;
  for (const std::string& name : presetFiles())
    if (readPreset(name)["model"]["kind"] == "composite") out.push_back("ruling:" + name);
  return out;
}

INSTANTIATE_TEST_SUITE_P(RulingCreases, DragStress, ::testing::ValuesIn(compositePresetsWithRulingCreases()),
                         devsurf::testing::presetTestName<::testing::TestParamInfo<std::string>>);

/// The same drags on every composite preset with a development, solved apart from the surface
/// (`"development_solve": "alternating"`, the Solver panel's choice for large developed designs).
std::vector<std::string> developedPresetsSolvedApart() {
  std::vector<std::string> out;
  for (const std::string& name : presetFiles()) {
    const json doc = readPreset(name);
    if (doc["model"]["kind"] == "composite" && doc["model"].contains("development")) out.push_back("alternating:" + name);
  }
  return out;
}

INSTANTIATE_TEST_SUITE_P(AlternatingDevelopment, DragStress, ::testing::ValuesIn(developedPresetsSolvedApart()),
                         devsurf::testing::presetTestName<::testing::TestParamInfo<std::string>>);

}  // namespace
}  // namespace devsurf::server
