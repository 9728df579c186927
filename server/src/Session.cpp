#include "devsurf/server/Session.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <sstream>

#include <spdlog/spdlog.h>

#include "devsurf/proto/BoundedJson.h"
#include "devsurf/proto/Geometry.h"
#include "devsurf/proto/Report.h"
#include "devsurf/server/Tokens.h"

namespace devsurf::server {
namespace {

/// Creases folded by less than this are left out when the fold slider takes a design's current
/// fold angles as its 100 % (degrees).
constexpr double kFoldCaptureMinDeg = 0.5;

using nlohmann::json;
using models::strip::ControlPointRef;
using models::strip::Curve;
using models::strip::StripDesign;
namespace composite = models::composite;

const char* kPalette[] = {"#e6194b", "#3cb44b", "#4363d8", "#f58231", "#911eb4",
                          "#42d4f4", "#f032e6", "#9a6324", "#800000", "#469990"};

ControlPointRef refOf(const json& target) {
  return {target.at("curve").get<std::string>() == "a" ? Curve::A : Curve::B,
          target.at("index").get<int>()};
}

json targetJson(const ControlPointRef& r) {
  return {{"curve", models::strip::curveName(r.curve)}, {"index", r.index}};
}

/// A composite point reference of a target or scene entry ({"vertex"} or {"edge","index"}).
composite::PointRef compositeRefOf(const json& target) {
  if (target.contains("vertex")) return composite::PointRef::ofVertex(target["vertex"].get<int>());
  return composite::PointRef::ofEdgePoint(target.at("edge").get<int>(), target.at("index").get<int>());
}

/// Canonical target of a valid composite point: an S edge's end control points are its vertices.
json compositeTargetJson(const composite::CompositeDesign& d, const composite::PointRef& r) {
  if (r.isVertex()) return {{"vertex", r.vertex}};
  const composite::CompositeEdge& e = d.edges.at(static_cast<std::size_t>(r.edge));
  if (r.index == 0) return {{"vertex", e.v0}};
  if (r.index == e.curve.points.rows() - 1) return {{"vertex", e.v1}};
  return {{"edge", r.edge}, {"index", r.index}};
}

json point3Json(const Eigen::Vector3d& p) { return {p.x(), p.y(), p.z()}; }

namespace qm = models::quad_mesh;

/// A quad_mesh vertex of a target or scene entry ({"vertex"} with optional "on").
qm::VertexRef quadRefOf(const json& target) {
  if (target.is_number_integer()) return {qm::MeshSide::Mesh, target.get<int>()};  // a scene's fixed vertex of M
  const std::string on = target.value("on", std::string("mesh"));
  return {on == "unfolding" ? qm::MeshSide::Unfolding : on == "control" ? qm::MeshSide::Control : qm::MeshSide::Mesh,
          target.at("vertex").get<int>()};
}

/// Canonical target of a quad_mesh vertex: {"vertex": i} on M, {"on": "unfolding", "vertex": i} on
/// M′, {"on": "control", "vertex": i} for a control point of a spline surface.
json quadTargetJson(const qm::VertexRef& v) {
  if (v.on != qm::MeshSide::Mesh) return {{"on", qm::meshSideName(v.on)}, {"vertex", v.vertex}};
  return {{"vertex", v.vertex}};
}

bool isEdit(const std::string& type) {
  return type != "presence" && type != "ping" && type != "join";
}

/// The first metric that is not finite, or empty.
std::string nonFiniteMetric(const json& metrics) {
  for (const auto& [name, value] : metrics.items())
    if (!proto::nonFinitePath(value).empty()) return name;
  return {};
}

/// The error code of a refused scene: `limit` (a resource limit), `time_budget` (the session's
/// time budget ran out while the model was built), else `invalid`.
std::string codeOf(const proto::SceneError& e) {
  return e.rule() == "limit" || e.rule() == "time_budget" ? e.rule() : std::string("invalid");
}

}  // namespace

Session::Session(std::string id, proto::Scene scene, Tokens tokens, SessionSettings settings,
                 Scheduler schedule, SessionJournal* journal, SessionCounters* counters, bool demo)
    : id_(std::move(id)),
      name_(scene.name),
      tokens_(std::move(tokens)),
      settings_(settings),
      schedule_(std::move(schedule)),
      journal_(journal),
      counters_(counters),
      demo_(demo),
      initialScene_(scene) {
  try {
    rebuild(scene);
  } catch (const SolveFailed& e) {
    throw proto::SceneError("model", "solve", e.what());
  }
  // Revision 0 is the scene the session was built from, as given (it is stored already: the
  // initial scene, or the checkpoint a restart builds it from).
  cachedScene_ = proto::sceneToJson(scene);
  cachedMetrics_ = json(solver_->metrics());
  changed_ = false;
}

Role Session::roleOf(const Tokens& tokens, const std::string& token) {
  // Compare against both (each in constant time) so the time does not tell which one matched.
  const bool edit = hashMatches(token, tokens.editHash);
  const bool view = hashMatches(token, tokens.viewHash);
  return edit ? Role::Edit : (view ? Role::View : Role::None);
}

Role Session::authenticate(const std::string& token) const {
  Tokens tokens;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    tokens = tokens_;
  }
  return roleOf(tokens, token);
}

void Session::setTokens(Tokens tokens) {
  std::lock_guard<std::mutex> lock(mutex_);
  tokens_ = std::move(tokens);
}

void Session::setInitialScene(proto::Scene scene) { initialScene_ = std::move(scene); }

void Session::setRebuildTimeBudget(double ms) { settings_.rebuildTimeBudgetMs = ms; }

Session::Shown Session::shown() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return {shownSeq_, cachedRevision_, cachedScene_, cachedMetrics_};
}

void Session::rebuild(const proto::Scene& scene) {
  // Building the model (and solving quasi/conical strips whole) runs under the session's time
  // budget; over it, nothing changes (the current model stays).
  const engine::Deadline deadline = engine::Deadline::after(settings_.rebuildTimeBudgetMs, "this session's time budget");
  std::unique_ptr<SceneSolver> next;
  engine::SolveSummary summary;
  try {
    next = std::make_unique<SceneSolver>(scene, deadline);  // throws SceneError on a bad design
    next->setSceneTimeBudgetApplies(false);  // the same scene, the same strip: a restart recomputes it
    if (next->keepsInputGeometry()) {
      // The curves' models are solved whole on every change; a failure leaves the current model.
      proto::Metrics m;
      try {
        summary = next->solve();
        m = next->metrics();
      } catch (const engine::DeadlineExceeded&) {
        throw;
      } catch (const std::exception& e) {
        throw SolveFailed("solve_failed", std::string("the solve failed (") + e.what() +
                                              "); the session keeps its last good state");
      }
      const bool finite = std::all_of(m.begin(), m.end(), [](const auto& kv) { return std::isfinite(kv.second); });
      if (summary.reason == engine::TerminationReason::Diverged || !finite)
        throw SolveFailed("diverged", "the solve diverged; the session keeps its last good state");
    }
  } catch (const engine::DeadlineExceeded& e) {
    throw proto::SceneError("model", "time_budget",
                            std::string("building") + (next && next->keepsInputGeometry() ? " and solving" : "") +
                                " the model took too long: " + e.what() +
                                " (devsurf serve --session-time-budget-ms); nothing was applied");
  }
  next->setDeadline({});  // later solves (drags) have budgets of their own
  if (next->keepsInputGeometry()) lastSummary_ = std::move(summary);
  solver_ = std::move(next);
  changed_ = true;  // shown (and checkpointed) by the message that reports the change
}

proto::Scene Session::persistentScene() const {
  proto::Scene s = withoutZeroWeightHandles(solver_->currentScene());
  if (keepsInput()) return s;
  if (auto* c = std::get_if<composite::CompositeDesign>(&s.model)) {
    const composite::CompositeDesign& design = *c;
    c->handles.erase(std::remove_if(c->handles.begin(), c->handles.end(),
                                    [this, &design](const composite::Handle& h) {
                                      return isDragHandle(compositeTargetJson(design, h.point));
                                    }),
                     c->handles.end());
    return s;
  }
  if (auto* q = std::get_if<qm::QuadMeshDesign>(&s.model)) {
    q->handles.erase(std::remove_if(q->handles.begin(), q->handles.end(),
                                    [this](const qm::VertexHandle& h) { return isDragHandle(quadTargetJson(h.vertex)); }),
                     q->handles.end());
    return s;
  }
  auto& d = std::get<StripDesign>(s.model);
  d.handles.erase(std::remove_if(d.handles.begin(), d.handles.end(),
                                 [this](const models::strip::Handle& h) { return isDragHandle(targetJson(h.point)); }),
                  d.handles.end());
  return s;
}

bool Session::isDragHandle(const json& target) const {
  return std::find(dragHandles_.begin(), dragHandles_.end(), target) != dragHandles_.end() || isReleasedHandle(target);
}

bool Session::isReleasedHandle(const json& target) const {
  return std::find(releasedHandles_.begin(), releasedHandles_.end(), target) != releasedHandles_.end();
}

proto::Scene Session::withoutZeroWeightHandles(proto::Scene s) {
  // A handle of weight 0 is a released temporary one (setHandleWeight); no scene may carry it
  // (the schema and the models want weights > 0). The long hostile-client run found one left in
  // a composite after its release list was cleared, and every later rebuild and recovery refused it.
  auto drop = [](auto& handles) {
    handles.erase(std::remove_if(handles.begin(), handles.end(), [](const auto& h) { return !(h.weight > 0.0); }),
                  handles.end());
  };
  if (auto* c = std::get_if<composite::CompositeDesign>(&s.model)) drop(c->handles);
  else if (auto* q = std::get_if<qm::QuadMeshDesign>(&s.model)) drop(q->handles);
  else if (auto* d = std::get_if<StripDesign>(&s.model)) drop(d->handles);
  return s;
}

proto::Scene Session::withoutReleasedHandles(proto::Scene s) const {
  s = withoutZeroWeightHandles(std::move(s));
  if (auto* c = std::get_if<composite::CompositeDesign>(&s.model)) {
    const composite::CompositeDesign& design = *c;
    c->handles.erase(std::remove_if(c->handles.begin(), c->handles.end(),
                                    [this, &design](const composite::Handle& h) {
                                      return isReleasedHandle(compositeTargetJson(design, h.point));
                                    }),
                     c->handles.end());
  } else if (auto* q = std::get_if<qm::QuadMeshDesign>(&s.model)) {
    q->handles.erase(std::remove_if(q->handles.begin(), q->handles.end(),
                                    [this](const qm::VertexHandle& h) { return isReleasedHandle(quadTargetJson(h.vertex)); }),
                     q->handles.end());
  } else if (auto* d = std::get_if<StripDesign>(&s.model)) {
    d->handles.erase(std::remove_if(d->handles.begin(), d->handles.end(),
                                    [this](const models::strip::Handle& h) { return isReleasedHandle(targetJson(h.point)); }),
                     d->handles.end());
  }
  return s;
}

void Session::setHandleWeight(int handle, double weight) {
  if (solver_->isQuadMesh())
    solver_->quadMeshModel().setHandleWeight(handle, weight);
  else if (isComposite())
    solver_->compositeModel().setHandleWeight(handle, weight);
  else
    solver_->stripModel().setHandleWeight(handle, weight);
}

const engine::Problem& Session::problem() const {
  if (isComposite()) return solver_->compositeModel().problem();
  if (solver_->isQuadMesh()) return solver_->quadMeshModel().problem();
  return solver_->stripModel().problem();
}

json Session::geometryJson(json* iterateMetrics) const {
  if (keepsInput()) {
    if (iterateMetrics) *iterateMetrics = json(solver_->metrics());
    if (solver_->isConicalStrip()) return proto::conicalStripGeometryJson(solver_->conicalStripModel());
    return proto::quasiStripGeometryJson(solver_->quasiStripModel(), settings_.surfaceSamples);
  }
  if (solver_->isQuadMesh()) {
    const qm::QuadMeshModel& model = solver_->quadMeshModel();
    const qm::QuadMeshQuality q = model.quality();
    if (iterateMetrics)
      *iterateMetrics = {{"length_error", q.lengthError}, {"area_error", q.areaError},
                         {"isometry_residual_max", q.isometryResidualMax}, {"glue_gap_max", q.glueGapMax},
                         {"unfolding_flipped_faces", q.unfoldingFlippedFaces}};
    // Approximating a reference (issue 15): its distance to M, every iterate (watch it fit).
    if (iterateMetrics && model.reference()) {
      try {
        for (const auto& [name, value] : solver_->referenceMetrics(model.reference()->vertices, 0.0))
          (*iterateMetrics)["approximation_" + name.substr(std::string("reference_").size())] = value;
      } catch (const std::exception&) {
        // A degenerate M has no distances; the length error says what went wrong.
      }
    }
    return proto::quadMeshGeometryJson(model, q);
  }
  if (isComposite()) {
    const composite::CompositeModel& model = solver_->compositeModel();
    const composite::CompositeQuality q = model.quality();
    if (iterateMetrics)
      *iterateMetrics = {{"face_flatness_max", q.faceFlatnessMax}, {"face_flatness_mean", q.faceFlatnessMean},
                         {"vertex_curvature_max", q.vertexCurvatureMax},
                         {"crease_fold_residual_max", q.creaseFoldResidualMax},
                         {"crease_fold_angle_max_deg", q.foldAngleMaxDeg},
                         {"warp_angle_max_deg", q.warpAngleMaxDeg}, {"warp_angle_mean_deg", q.warpAngleMeanDeg},
                         {"ruling_length_min_ratio", model.rulingLengthMinRatio()},
                         {"crease_backtrack_max", model.creaseBacktrackMax()}};
    if (iterateMetrics && model.hasDevelopment())
      (*iterateMetrics)["development_flipped_faces"] = model.flippedDevelopmentFaces();
    return proto::compositeGeometryJson(model, q, settings_.compositeSamplesPerSpan);
  }
  if (iterateMetrics) {
    const metrics::StripQuality q = solver_->stripModel().quality(200);
    *iterateMetrics = {{"warp_angle_max_deg", q.warpAngleMaxDeg}, {"warp_angle_mean_deg", q.warpAngleMeanDeg},
                       {"ruling_length_min_ratio", solver_->stripModel().rulingLengthMinRatio()}};
  }
  json geometry = proto::stripGeometryJson(solver_->stripModel(), settings_.surfaceSamples);
  // A fitted strip: how close it is to its reference points, every iterate (watch it fit); each
  // point's distance rides with the geometry, so the web app colours the points by it.
  if (const auto& target = solver_->stripModel().approximation()) {
    try {
      Eigen::VectorXd distances;
      const proto::Metrics measured = solver_->referenceMetrics(target->points, 0.0, &distances);
      if (iterateMetrics)
        for (const auto& [name, value] : measured)
          (*iterateMetrics)["approximation_" + name.substr(std::string("reference_").size())] = value;
      geometry["approximation_distances"] = std::vector<double>(distances.data(), distances.data() + distances.size());
      geometry["approximation_tolerance"] = measured.at("reference_coverage_tolerance");
    } catch (const std::exception&) {
      // A degenerate surface has no distances; the warp metrics say what went wrong.
    }
  }
  return geometry;
}

json Session::constraintsJson() const {
  const proto::Scene current = solver_->currentScene();
  json fixed = json::array(), handles = json::array();
  auto addHandle = [this, &handles](const json& target, const Eigen::Vector3d& position, double weight) {
    handles.push_back({{"target", target}, {"position", point3Json(position)}, {"weight", weight},
                       {"temporary", isDragHandle(target)}});
  };
  if (keepsInput()) return {{"fixed", fixed}, {"handles", handles}};  // the curves' points have no constraints
  if (const auto* c = std::get_if<composite::CompositeDesign>(&current.model)) {
    for (const auto& f : c->fixed) fixed.push_back(compositeTargetJson(*c, f));
    for (const auto& h : c->handles)
      if (!isReleasedHandle(compositeTargetJson(*c, h.point))) addHandle(compositeTargetJson(*c, h.point), h.position, h.weight);
  } else if (const auto* q = std::get_if<qm::QuadMeshDesign>(&current.model)) {
    for (const auto& f : q->fixed) fixed.push_back(quadTargetJson(f));
    for (const auto& h : q->handles)
      if (!isReleasedHandle(quadTargetJson(h.vertex))) addHandle(quadTargetJson(h.vertex), h.target, h.weight);
  } else {
    const auto& d = std::get<StripDesign>(current.model);
    for (const auto& f : d.fixed) fixed.push_back(targetJson(f));
    for (const auto& h : d.handles)
      if (!isReleasedHandle(targetJson(h.point))) addHandle(targetJson(h.point), h.position, h.weight);
  }
  return {{"fixed", fixed}, {"handles", handles}};
}

json Session::canonicalTarget(const json& target, std::string& path, std::string& message) const {
  const proto::Scene current = solver_->currentScene();
  if (keepsInput()) {
    const bool quasi = std::holds_alternative<proto::QuasiStripScene>(current.model);
    const std::string kind = quasi ? "quasi_strip" : "conical_strip";
    const std::string first = quasi ? "c1" : "p", second = quasi ? "c2" : "q";
    const std::string curve = target.value("curve", "");
    if (curve != first && curve != second) {
      path = target.contains("curve") ? "target.curve" : "target";
      message = "this session edits a " + kind + "; address control points as {\"curve\": \"" + first +
                "\"|\"" + second + "\", \"index\": i}";
      return nullptr;
    }
    const spline::BSplineCurve* c = nullptr;
    if (quasi) {
      const auto& q = std::get<proto::QuasiStripScene>(current.model).design;
      c = curve == "c1" ? &q.c1 : &q.c2;
    } else {
      const auto& d = std::get<models::conical_strip::ConicalStripDesign>(current.model);
      c = curve == "p" ? &d.p : &d.q;
    }
    const int n = static_cast<int>(c->points.rows()), index = target.at("index").get<int>();
    if (index >= n) {
      path = "target.index";
      message = "no such control point (curve " + curve + " has " + std::to_string(n) + ")";
      return nullptr;
    }
    return {{"curve", curve}, {"index", index}};
  }
  if (const auto* q = std::get_if<qm::QuadMeshDesign>(&current.model)) {
    if (!target.contains("vertex")) {
      path = "target";
      message = "this session edits a quad_mesh; address vertices as {\"vertex\": i} (M) or {\"vertex\": i, \"on\": "
                "\"unfolding\"} (M′)";
      return nullptr;
    }
    const qm::VertexRef r = quadRefOf(target);
    if (r.on == qm::MeshSide::Control) {
      if (!q->control) {
        path = "target.on";
        message = "\"control\" addresses control points; this quad_mesh has no control net";
        return nullptr;
      }
      const int np = static_cast<int>(q->control->points.rows());
      if (r.vertex >= np) {
        path = "target.vertex";
        message = "no control point " + std::to_string(r.vertex) + " (the net has " + std::to_string(np) + ")";
        return nullptr;
      }
      return quadTargetJson(r);
    }
    const int nv = static_cast<int>(q->mesh.rows());
    if (r.vertex >= nv) {
      path = "target.vertex";
      message = "no vertex " + std::to_string(r.vertex) + " (the mesh has " + std::to_string(nv) + ")";
      return nullptr;
    }
    return quadTargetJson(r);
  }
  if (target.contains("on")) {
    path = "target.on";
    message = std::string("\"on\" addresses the meshes of a quad_mesh; this session edits a ") + proto::modelKind(current.model);
    return nullptr;
  }
  if (const auto* c = std::get_if<composite::CompositeDesign>(&current.model)) {
    if (target.contains("curve")) {
      path = "target";
      message = "this session edits a composite; address points as {\"vertex\": i} or {\"edge\": e, \"index\": k}";
      return nullptr;
    }
    const composite::PointRef r = compositeRefOf(target);
    const int nv = static_cast<int>(c->vertices.rows()), ne = static_cast<int>(c->edges.size());
    if (r.isVertex()) {
      if (r.vertex >= nv) {
        path = "target.vertex";
        message = "no vertex " + std::to_string(r.vertex) + " (the composite has " + std::to_string(nv) + ")";
        return nullptr;
      }
      return compositeTargetJson(*c, r);
    }
    if (r.edge >= ne) {
      path = "target.edge";
      message = "no edge " + std::to_string(r.edge) + " (the composite has " + std::to_string(ne) + ")";
      return nullptr;
    }
    const composite::CompositeEdge& e = c->edges[static_cast<std::size_t>(r.edge)];
    if (e.type != composite::EdgeType::Spline) {
      path = "target.edge";
      message = "edge " + std::to_string(r.edge) + " is a ruling (R) and has no control points; address its vertices";
      return nullptr;
    }
    if (r.index >= e.curve.points.rows()) {
      path = "target.index";
      message = "edge " + std::to_string(r.edge) + " has " + std::to_string(e.curve.points.rows()) +
                " control points (index 0 … " + std::to_string(e.curve.points.rows() - 1) + ")";
      return nullptr;
    }
    return compositeTargetJson(*c, r);
  }
  if (!target.contains("curve") || (target["curve"] != "a" && target["curve"] != "b")) {
    path = target.contains("curve") ? "target.curve" : "target";
    message = "this session edits a strip; address control points as {\"curve\": \"a\"|\"b\", \"index\": i}";
    return nullptr;
  }
  const auto& d = std::get<StripDesign>(current.model);
  const ControlPointRef r = refOf(target);
  const int n = static_cast<int>((r.curve == Curve::A ? d.a.points : d.b.points).rows());
  if (r.index >= n) {
    path = "target.index";
    message = "no such control point (curve " + std::string(models::strip::curveName(r.curve)) + " has " +
              std::to_string(n) + ")";
    return nullptr;
  }
  return targetJson(r);
}

json Session::pointKey(const proto::Scene& current, const json& entry) const {
  if (const auto* c = std::get_if<composite::CompositeDesign>(&current.model))
    return compositeTargetJson(*c, compositeRefOf(entry));
  if (std::holds_alternative<qm::QuadMeshDesign>(current.model)) return quadTargetJson(quadRefOf(entry));
  return {{"curve", entry.at("curve")}, {"index", entry.at("index")}};
}

int Session::handleIndex(const proto::Scene& current, const json& target) const {
  if (const auto* c = std::get_if<composite::CompositeDesign>(&current.model)) {
    for (std::size_t i = 0; i < c->handles.size(); ++i)
      if (compositeTargetJson(*c, c->handles[i].point) == target) return static_cast<int>(i);
    return -1;
  }
  if (const auto* q = std::get_if<qm::QuadMeshDesign>(&current.model)) {
    for (std::size_t i = 0; i < q->handles.size(); ++i)
      if (quadTargetJson(q->handles[i].vertex) == target) return static_cast<int>(i);
    return -1;
  }
  const auto& d = std::get<StripDesign>(current.model);
  for (std::size_t i = 0; i < d.handles.size(); ++i)
    if (targetJson(d.handles[i].point) == target) return static_cast<int>(i);
  return -1;
}

void Session::setHandleTarget(int handle, const Eigen::Vector3d& position) {
  if (solver_->isQuadMesh())
    solver_->quadMeshModel().setHandleTarget(handle, position);
  else if (isComposite())
    solver_->compositeModel().setHandleTarget(handle, position);
  else
    solver_->stripModel().setHandleTarget(handle, position);
}

void Session::releaseDragHandle(const json& target) {
  std::string path, message;
  const json canonical = canonicalTarget(target, path, message);
  const auto active = std::find(dragHandles_.begin(), dragHandles_.end(), canonical);
  if (active == dragHandles_.end()) return;
  // Released by its weight: the model (and the reference state of its guards) stays; grabbing the
  // point again brings the handle back without a rebuild.
  const int handle = handleIndex(solver_->currentScene(), canonical);
  dragHandles_.erase(active);
  if (handle < 0) return;
  setHandleWeight(handle, 0.0);
  releasedHandles_.push_back(canonical);
}

json Session::sceneJson() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return cachedScene_;
}

std::int64_t Session::revision() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return cachedRevision_;
}

json Session::metricsJson() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return cachedMetrics_;
}

ExportedFile Session::exportAs(const std::string& format) const {
  return SceneSolver::exportScene(sceneJson(), format, settings_.resources,
                                  engine::Deadline::after(settings_.rebuildTimeBudgetMs, "this session's time budget"));
}

ExportedFile Session::thumbnail() const {
  std::lock_guard<std::mutex> lock(thumbnailMutex_);
  const std::int64_t current = revision();  // read before the scene: a newer scene only renders again
  if (thumbnailRevision_ != current || thumbnail_.content.empty()) {
    thumbnail_ = exportAs("png");
    thumbnailRevision_ = current;
  }
  return thumbnail_;
}

int Session::participantCount() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return static_cast<int>(participants_.size());
}

int Session::join(Role role, const std::string& name, MessageSink sink) {
  int pid;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (static_cast<int>(participants_.size()) >= settings_.maxParticipants) {
      sink(proto::wireText(json{{"type", "error"}, {"code", "session_full"},
                {"message", "this session has the maximum of " + std::to_string(settings_.maxParticipants) + " participants"},
                {"path", "session"}}),
           Delivery::Reliable, "");
      return -1;
    }
    pid = nextParticipant_++;
    Participant p{pid, name.empty() ? "guest " + std::to_string(pid) : name,
                  kPalette[(pid - 1) % (sizeof(kPalette) / sizeof(kPalette[0]))], role, std::move(sink),
                  nullptr, nullptr, false};
    participants_.emplace(pid, std::move(p));
  }
  // The state is built on the session's worker so it is consistent with the edit order.
  post(pid, json{{"type", "_state"}});
  return pid;
}

void Session::leave(int participant) {
  json dragging;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    const auto it = participants_.find(participant);
    if (it == participants_.end()) return;
    dragging = it->second.dragging;
    participants_.erase(it);
  }
  // A participant that leaves in the middle of a drag releases it: its temporary handle must not
  // keep pulling the point for everyone else (nor keep the session from being snapshotted).
  // (Presence first: queued behind the release it would interrupt its solve.)
  post(0, json{{"type", "_presence"}});
  if (!dragging.is_null()) post(0, json{{"type", "_release"}, {"target", dragging}});
}

void Session::post(int participant, json message) {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (counters_) ++counters_->messages;
    bool coalesced = false;
    const std::string type = message.value("type", "");
    if (type == "drag" || type == "fold") {
      // Latest wins per target (per participant for the fold slider): replace a queued,
      // unprocessed message of the same gesture.
      for (auto& w : queue_) {
        if (w->message.value("type", "") == type && w->participant == participant &&
            (type == "fold" || w->message["target"] == message["target"])) {
          w->coalescedOps.push_back(w->message.value("op", json()));
          w->message = std::move(message);
          coalesced = true;
          break;
        }
      }
    }
    if (!coalesced) queue_.push_back(std::make_shared<Work>(Work{participant, std::move(message), {}}));
    if (scheduled_) return;
    scheduled_ = true;
  }
  schedule_([self = shared_from_this()]() { self->drain(); });
}

bool Session::hasQueuedWork() const {
  // Only work that changes the model interrupts a solve: a ping, a selection or a newcomer's
  // state waits for it (else another participant's click would cancel a release's `solved`).
  std::lock_guard<std::mutex> lock(mutex_);
  return std::any_of(queue_.begin(), queue_.end(), [](const std::shared_ptr<Work>& w) {
    const std::string type = w->message.value("type", "");
    return type != "ping" && type != "presence" && type != "_state" && type != "_presence" && type != "_links";
  });
}

void Session::drain() {
  for (;;) {
    std::shared_ptr<Work> work;
    {
      std::lock_guard<std::mutex> lock(mutex_);
      if (queue_.empty()) {
        // Idle: a release or solve that newer work interrupted is finished now, unless a drag is
        // still on (its own release will end with `solved`).
        if (!settlePending_ || !dragHandles_.empty()) {
          scheduled_ = false;
          return;
        }
      } else {
        work = queue_.front();
        queue_.pop_front();
      }
    }
    try {
      if (work)
        handle(*work);
      else
        settle();
    } catch (const std::exception& e) {
      // Never let one message take the session down: back to what a restart would restore (the
      // last checkpoint and the edits acknowledged since), and shown as such. A scene the model
      // refused on the way (a drag's first contact rebuilds; the session's time budget) is the
      // sender's error by its own code, not an internal one (hostile client, 20 000 messages).
      if (work) {
        const auto* scene = dynamic_cast<const proto::SceneError*>(&e);
        const auto* journal = dynamic_cast<const JournalError*>(&e);
        error(work->participant, work->message.value("op", json()),
              scene ? codeOf(*scene) : journal ? journal->code() : "internal", e.what(),
              scene ? scene->path() : std::string());
      }
      try {
        recover();
      } catch (const std::exception& again) {
        spdlog::error("session {}: cannot recover after \"{}\": {}", id_, e.what(), again.what());
      }
    }
  }
}

void Session::send(int participant, const json& message, Delivery d, const std::string& key) {
  MessageSink sink;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    auto it = participants_.find(participant);
    if (it == participants_.end()) return;
    sink = it->second.sink;
  }
  sink(proto::wireText(message), d, key);
}

void Session::broadcast(const json& message, Delivery d, const std::string& key) {
  const std::string text = proto::wireText(message);
  std::vector<MessageSink> sinks;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    for (auto& [id, p] : participants_)
      if (p.ready) sinks.push_back(p.sink);
  }
  for (auto& s : sinks) s(text, d, key);
}

void Session::error(int participant, const json& op, const std::string& code,
                    const std::string& message, const std::string& path) {
  json e{{"type", "error"}, {"code", code}, {"message", message}};
  if (!op.is_null()) e["op"] = op;
  if (!path.empty()) e["path"] = path;
  if (counters_) counters_->recordError(code);
  send(participant, e);
}

json Session::participantsJson() const {
  json list = json::array();
  for (const auto& [id, p] : participants_)
    list.push_back({{"id", id}, {"name", p.name}, {"color", p.color},
                    {"role", p.role == Role::Edit ? "edit" : "view"},
                    {"selection", p.selection}, {"dragging", p.dragging}});
  return list;
}

json Session::presenceMessage() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return {{"type", "presence"}, {"participants", participantsJson()}};
}

json Session::stateMessage(int participant) const {
  const json constraints = constraintsJson();
  const json geometry = geometryJson();
  std::lock_guard<std::mutex> lock(mutex_);
  const auto it = participants_.find(participant);
  return {{"type", "state"},
          {"session", id_},
          {"seq", seq_.load()},
          {"revision", cachedRevision_},
          {"you", participant},
          {"role", it != participants_.end() && it->second.role == Role::Edit ? "edit" : "view"},
          {"scene", cachedScene_},
          {"metrics", cachedMetrics_},
          {"geometry", geometry},
          {"constraints", constraints},
          {"participants", participantsJson()},
          {"settings", {{"drag_iterations", settings_.dragIterations},
                        {"release_iterations", settings_.releaseIterations}}},
          {"undo", undoCountsJson()}};
}

bool Session::gestureApplied(int participant, const std::string& letGo) const {
  std::lock_guard<std::mutex> lock(mutex_);
  const auto p = participants_.find(participant);
  if (p == participants_.end()) return true;  // the session's own let-go (_release)
  return letGo == "fold_end" ? p->second.folding : !p->second.dragging.is_null();
}

json Session::undoCountsJson() const { return {{"available", undo_.size()}, {"redo_available", redo_.size()}}; }

void Session::broadcastUpdate() {
  broadcast({{"type", "update"}, {"seq", seq_.load()}, {"revision", revision_}, {"scene", sceneJson()},
             {"metrics", metricsJson()}, {"geometry", geometryJson()}, {"undo", undoCountsJson()}});
}

void Session::pushUndo() { pushUndo(persistentScene()); }

void Session::pushUndo(const proto::Scene& before) {
  undo_.push_back(before);
  if (static_cast<int>(undo_.size()) > settings_.undoDepth) undo_.pop_front();
  redo_.clear();
}

void Session::commit(int participant, const json& edit, const std::vector<json>& ops, const json& result) {
  const std::int64_t seq = seq_.load() + 1;
  json logged = edit;
  logged.erase("op");
  json entry = logged;
  if (!result.is_null()) entry["result"] = result;
  if (journal_) journal_->appendEdit(id_, seq, entry);  // durable before the ack (a failure leaves seq as it was)
  seq_ = seq;
  unshownEdits_.emplace_back(seq, std::move(entry));  // until a checkpoint holds its effect
  for (const json& op : ops) {
    json ack{{"type", "ack"}, {"seq", seq}};
    if (!op.is_null()) ack["op"] = op;
    send(participant, ack);
  }
  json notice{{"type", "edit"}, {"seq", seq}, {"by", participant}, {"edit", logged}};
  std::vector<MessageSink> others;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    for (auto& [id, p] : participants_)
      if (id != participant && p.ready) others.push_back(p.sink);
  }
  const std::string text = proto::wireText(notice);
  for (auto& s : others) s(text, Delivery::Reliable, "");
}

bool Session::apply(int participant, const json& edit, bool replaying) {
  const std::string type = edit.at("type").get<std::string>();
  auto reject = refuser(participant, edit, replaying);
  const proto::Scene current = solver_->currentScene();

  json target;
  if (edit.contains("target")) {
    std::string path, message;
    target = canonicalTarget(edit["target"], path, message);
    if (target.is_null()) return reject("invalid", message, path);
  }
  if (edit.contains("position")) {
    // A pointer far outside the model (a 1e200 from a script, a mouse ray nearly parallel to the
    // drag plane) would be a handle the normalized solve cannot represent.
    const json& p = edit["position"];
    const Eigen::Vector3d pos(p[0].get<double>(), p[1].get<double>(), p[2].get<double>());
    const proto::SceneExtent extent = proto::sceneExtent(current);
    const double reach = proto::kMaxReach * std::max(extent.diagonal, 1e-9);
    const double distance = (pos - extent.centre).norm();
    if (!std::isfinite(distance) || distance > reach) {
      std::ostringstream why;
      why.precision(3);
      if (std::isfinite(distance)) why << "position is " << distance << " from the model's centre";
      else why << "position is too far from the model's centre to measure";
      why << "; it must lie within " << reach << " (" << proto::kMaxReach << "× the model's size)";
      return reject("invalid", why.str(), "position");
    }
  }
  if (type == "set_units") {
    // What one coordinate is; the numbers stay. Every kind has units, so this comes before the
    // kind-specific edits.
    proto::Scene next = persistentScene();
    next.units = edit.at("units").get<std::string>();
    const proto::Scene before = persistentScene();
    if (next.units == before.units) return true;
    try {
      rebuild(proto::sceneFromJson(proto::sceneToJson(next), settings_.resources));
    } catch (const proto::SceneError& e) {
      return reject(codeOf(e), e.what(), e.path());
    }
    pushUndo(before);
    return true;
  }
  if (isDrawingEdit(type)) return applyDrawingEdit(participant, edit, replaying);
  if (type == "rotate_points") return applyGroupRotation(participant, edit, replaying);
  if (type == "add_control_point" || type == "remove_control_point") return applyControlPointEdit(participant, edit, replaying);
  if (type == "relabel_edge" || type == "split_face" || type == "merge_faces" || type == "split_along_ruling" ||
      type == "split_edge" || type == "remove_vertex")
    return applyLabelledMeshEdit(participant, edit, replaying);
  if (type == "fold" || type == "fold_end") {
    if (!isComposite())
      return reject("invalid", std::string("the fold slider applies to composite sessions (sheets with creases); this session edits a ") +
                                   proto::modelKind(current.model),
                    "type");
    if (type == "fold_end") return true;  // the release iterations follow (handle())
    return applyFold(participant, edit, replaying);
  }
  if (keepsInput()) return applyCurveEdit(participant, edit, replaying, target);
  if (type == "drag") {
    const Eigen::Vector3d pos(edit["position"][0].get<double>(), edit["position"][1].get<double>(),
                              edit["position"][2].get<double>());
    const int handle = handleIndex(current, target);
    if (handle < 0) {
      // First contact: a temporary handle (one rebuild). Released temporary handles leave the model.
      pushUndo();
      proto::Scene s = withoutReleasedHandles(current);
      if (auto* c = std::get_if<composite::CompositeDesign>(&s.model))
        c->handles.push_back({compositeRefOf(target), pos, s.solver.handleWeight});
      else if (auto* q = std::get_if<qm::QuadMeshDesign>(&s.model))
        q->handles.push_back({quadRefOf(target), pos, s.solver.handleWeight});
      else
        std::get<StripDesign>(s.model).handles.push_back({refOf(target), pos, s.solver.handleWeight});
      releasedHandles_.clear();
      dragHandles_.push_back(target);
      rebuild(s);
      scheduleIteration_ = 0;
    } else if (isReleasedHandle(target)) {
      // The same point grabbed again: its released handle comes back, without a rebuild.
      pushUndo();
      releasedHandles_.erase(std::find(releasedHandles_.begin(), releasedHandles_.end(), target));
      dragHandles_.push_back(target);
      setHandleWeight(handle, current.solver.handleWeight);
      setHandleTarget(handle, pos);
      solver_->resetStepControl();
      scheduleIteration_ = 0;
    } else {
      if (!isDragHandle(target) && !replaying) {
        bool started = true;  // the first drag of a permanent handle is one undo step
        {
          std::lock_guard<std::mutex> lock(mutex_);
          const auto p = participants_.find(participant);
          started = p == participants_.end() || p->second.dragging != edit["target"];
        }
        if (started) {
          pushUndo();
          solver_->resetStepControl();
          scheduleIteration_ = 0;
        }
      }
      setHandleTarget(handle, pos);
    }
    // A drag may change the fold of a design folded by its targets: they let go while the point
    // is pulled and take the new fold when it is released (release()).
    if (holdsFoldTargets()) solver_->compositeModel().holdFoldTargets(false);
    return true;
  }
  if (type == "drag_end") {
    return true;  // the handle is released after the release iterations (handle())
  }
  if (type == "solve") {
    pushUndo();  // Solve is an edit like any other: undo goes back to before it
    scheduleIteration_ = 0;
    return true;
  }
  if (type == "undo" || type == "redo") {
    auto& from = type == "undo" ? undo_ : redo_;
    auto& to = type == "undo" ? redo_ : undo_;
    if (from.empty()) return reject("conflict", "nothing to " + type, "type");
    to.push_back(persistentScene());
    const proto::Scene previous = from.back();
    from.pop_back();
    dragHandles_.clear();
    releasedHandles_.clear();
    rebuild(previous);
    return true;
  }
  if (type == "reset") {
    pushUndo();
    dragHandles_.clear();
    releasedHandles_.clear();
    rebuild(initialScene_);
    return true;
  }
  // Structural edits go through the scene document, so the model's own validation applies.
  json doc = proto::sceneToJson(persistentScene());
  json& model = doc["model"];
  auto sameTarget = [this, &current, &target](const json& entry) { return pointKey(current, entry) == target; };
  if (type == "add_handle") {
    json handles = model.value("handles", json::array());
    json h = target;
    h["position"] = edit["position"];
    if (edit.contains("weight")) h["weight"] = edit["weight"];
    handles.erase(std::remove_if(handles.begin(), handles.end(), sameTarget), handles.end());
    handles.push_back(h);
    model["handles"] = handles;
  } else if (type == "remove_handle") {
    json handles = model.value("handles", json::array());
    const auto before = handles.size();
    handles.erase(std::remove_if(handles.begin(), handles.end(), sameTarget), handles.end());
    if (handles.size() == before) return reject("invalid", "that point has no handle", "target");
    model["handles"] = handles;
  } else if (type == "set_fixed") {
    json fixed = model.value("fixed", json::array());
    fixed.erase(std::remove_if(fixed.begin(), fixed.end(), sameTarget), fixed.end());
    if (edit["fixed"].get<bool>()) fixed.push_back(target);
    model["fixed"] = fixed;
  } else if (type == "set_solver") {
    if (edit.contains("normals") && isComposite())
      return reject("invalid",
                    "\"normals\" applies to strip sessions; a composite chooses normal splines with the solver's "
                    "\"normal_splines\" setting",
                    "normals");
    for (const auto& [k, v] : edit["solver"].items()) doc["solver"][k] = v;
    if (edit.contains("normals")) model["normals"] = edit["normals"];
  } else if (type == "set_crease") {
    if (!isComposite()) return reject("invalid", "applies to composite sessions; this session edits a strip", "type");
    const int e = edit["edge"].get<int>();
    const std::string crease = edit["crease"].get<std::string>();
    const composite::CompositeTopology& topology = solver_->compositeModel().topology();
    if (e >= topology.numEdges())
      return reject("invalid", "no edge " + std::to_string(e) + " (the composite has " + std::to_string(topology.numEdges()) + ")",
                    "edge");
    if (!topology.edge(e).interior())
      return reject("invalid", "edge " + std::to_string(e) + " is on the boundary; a crease joins two faces", "edge");
    if ((crease == "fold" || crease == "geodesic") && topology.edgeType(e) != composite::EdgeType::Spline)
      return reject("invalid", "\"" + crease + "\" applies to S edges; edge " + std::to_string(e) +
                                   " is a ruling (R), a straight crease that folds freely (use \"none\" or \"smooth\")",
                    "crease");
    json& je = model["edges"][static_cast<std::size_t>(e)];
    if (crease == "none")
      je.erase("crease");
    else
      je["crease"] = crease;
  } else if (type == "set_params" && std::holds_alternative<qm::QuadMeshDesign>(current.model)) {
    static const std::vector<std::string> kQuadMesh = {"weights", "schedule", "variable", "variables", "conformal",
                                                       "gauss_image", "glue"};
    for (const auto& [key, value] : edit["params"].items()) {
      if (std::find(kQuadMesh.begin(), kQuadMesh.end(), key) == kQuadMesh.end())
        return reject("invalid", "\"" + key + "\" is not a quad_mesh parameter (weights, schedule, variable, conformal, "
                                 "gauss_image, glue)",
                      "params." + key);
      if (key == "weights" || key == "schedule")
        for (const auto& [k, v] : value.items()) model[key][k] = v;
      else if (key == "variable" || key == "variables")  // the scene spells it "variables"
        model["variables"] = value;
      else
        model[key] = value;
    }
  } else if (type == "set_params") {
    return reject("invalid", std::string("applies to quasi_strip and conical_strip sessions; this session edits a ") +
                                 proto::modelKind(current.model) + " (use set_solver)",
                  "type");
  } else {
    return reject("invalid", "unknown message type \"" + type + "\"", "type");
  }
  try {
    const proto::Scene next = proto::sceneFromJson(doc, settings_.resources);  // limits: code `limit`
    const proto::Scene before = persistentScene();
    rebuild(next);  // throws (a design the model rejects, the time budget): nothing changed
    pushUndo(before);
    dragHandles_.clear();
    releasedHandles_.clear();
  } catch (const proto::SceneError& e) {
    return reject(codeOf(e), e.what(), e.path());
  }
  if (type == "set_solver") {  // the session's own settings, once the scene took the rest
    if (edit.contains("drag_iterations")) settings_.dragIterations = edit["drag_iterations"];
    if (edit.contains("release_iterations")) settings_.releaseIterations = edit["release_iterations"];
  }
  return true;
}

bool Session::refuse(int participant, const json& edit, bool replaying, const std::string& code, const std::string& message,
                     const std::string& path) {
  if (!replaying) error(participant, edit.value("op", json()), code, edit.at("type").get<std::string>() + ": " + message, path);
  return false;
}

bool Session::rebuildForEdit(int participant, const json& edit, bool replaying, const proto::Scene& before,
                             const proto::Scene& next, const std::string& solvePath) {
  try {
    rebuild(proto::sceneFromJson(proto::sceneToJson(next), settings_.resources));  // throws: nothing changed
  } catch (const proto::SceneError& e) {
    return refuse(participant, edit, replaying, codeOf(e), e.what(), e.path());
  } catch (const SolveFailed& e) {
    return refuse(participant, edit, replaying, e.code(), e.what(), solvePath);
  }
  pushUndo(before);
  dragHandles_.clear();
  releasedHandles_.clear();
  scheduleIteration_ = 0;
  return true;
}

bool Session::applyFold(int participant, const json& edit, bool replaying) {
  const json op = edit.value("op", json());
  const double amount = edit.at("amount").get<double>();
  const proto::Scene current = solver_->currentScene();
  const auto& design = std::get<composite::CompositeDesign>(current.model);
  if (design.foldAngles.empty()) {
    // The first fold of a design without targets: its current fold angles become 100 % (one
    // rebuild, one undo step).
    proto::Scene next = persistentScene();
    auto& d = std::get<composite::CompositeDesign>(next.model);
    for (const auto& h : solver_->compositeModel().hingeAngles())
      if (std::abs(h.angleDeg) >= kFoldCaptureMinDeg) d.foldAngles.push_back({h.edge, h.end, h.angleDeg});
    if (d.foldAngles.empty()) {
      if (!replaying)
        error(participant, op, "invalid",
              "fold: nothing to fold — every crease of the design is flat and it has no fold-angle targets (fold_angles); "
              "fold it by dragging first, or import a crease pattern with fold angles",
              "amount");
      return false;
    }
    // The targets take over from the handles that pulled the design into shape (they would pull
    // it back up against the slider); undo brings them back.
    d.handles.clear();
    d.foldAmount = amount;
    const proto::Scene before = persistentScene();
    try {
      rebuild(proto::sceneFromJson(proto::sceneToJson(next), settings_.resources));
    } catch (const proto::SceneError& e) {
      if (!replaying) error(participant, op, codeOf(e), std::string("fold: ") + e.what(), e.path());
      return false;
    }
    pushUndo(before);
    dragHandles_.clear();
    releasedHandles_.clear();
    scheduleIteration_ = 0;
    if (!replaying) foldTargetsCaptured_ = true;  // handle() sends the new scene before the fold's iterations
    return true;
  }
  bool started = true;  // the first fold message of a gesture is one undo step
  if (!replaying) {
    std::lock_guard<std::mutex> lock(mutex_);
    const auto p = participants_.find(participant);
    started = p == participants_.end() || !p->second.folding;
  }
  if (started && !replaying) pushUndo();
  solver_->compositeModel().holdFoldTargets(true);  // (a drag may have let go of them)
  solver_->compositeModel().setFoldAmount(amount);
  solver_->resetStepControl();
  scheduleIteration_ = 0;
  return true;
}

bool Session::applyCurveEdit(int participant, const json& edit, bool replaying, const json& target) {
  const std::string type = edit.at("type").get<std::string>();
  const json op = edit.value("op", json());
  const proto::Scene current = solver_->currentScene();
  const bool quasi = std::holds_alternative<proto::QuasiStripScene>(current.model);
  const std::string kind = proto::modelKind(current.model);
  auto reject = [&](const std::string& code, const std::string& message, const std::string& path) {
    if (!replaying) error(participant, op, code, type + ": " + message, path);
    return false;
  };
  try {
    if (type == "drag") {
      proto::Scene next = current;
      const std::string curve = target["curve"].get<std::string>();
      spline::BSplineCurve* c = nullptr;
      if (auto* q = std::get_if<proto::QuasiStripScene>(&next.model))
        c = curve == "c1" ? &q->design.c1 : &q->design.c2;
      else {
        auto& d = std::get<models::conical_strip::ConicalStripDesign>(next.model);
        c = curve == "p" ? &d.p : &d.q;
      }
      for (int k = 0; k < 3; ++k) c->points(target["index"].get<int>(), k) = edit["position"][k].get<double>();
      bool started = false;  // the first drag message of a target by a participant is one undo step
      if (!replaying) {
        std::lock_guard<std::mutex> lock(mutex_);
        const auto p = participants_.find(participant);
        started = p == participants_.end() || p->second.dragging != edit["target"];
      }
      rebuild(next);
      if (started) pushUndo(current);
      return true;
    }
    if (type == "drag_end" || type == "solve") return true;  // every change was solved whole already
    if (type == "undo" || type == "redo") {
      auto& from = type == "undo" ? undo_ : redo_;
      auto& to = type == "undo" ? redo_ : undo_;
      if (from.empty()) return reject("conflict", "nothing to " + type, "type");
      rebuild(from.back());
      from.pop_back();
      to.push_back(current);
      return true;
    }
    if (type == "reset") {
      rebuild(initialScene_);
      pushUndo(current);
      return true;
    }
    if (type == "set_params") {
      static const std::vector<std::string> kQuasi = {"mapping", "samples", "method", "optimizer",
                                                      "lambda1", "lambda2", "max_iterations"};
      static const std::vector<std::string> kConical = {"np", "nq", "h3", "h4", "ra", "objective", "g1"};
      const std::vector<std::string>& allowed = quasi ? kQuasi : kConical;
      json doc = proto::sceneToJson(current);
      json& model = doc["model"];
      for (const auto& [key, value] : edit["params"].items()) {
        if (std::find(allowed.begin(), allowed.end(), key) == allowed.end())
          return reject("invalid",
                        "\"" + key + "\" is a " + (quasi ? "conical_strip" : "quasi_strip") +
                            " parameter; this session edits a " + kind,
                        "params." + key);
        if (key == "mapping")
          for (const auto& [k, v] : value.items()) model["mapping"][k] = v;
        else
          model[key] = value;
      }
      proto::Scene next;
      try {
        next = proto::sceneFromJson(doc, settings_.resources);
      } catch (const proto::SceneError& e) {
        // The scene's paths (model.mapping.degree) as the message spells them (params.mapping.degree).
        std::string path = e.path(), message = e.what();
        if (path.rfind("model.", 0) == 0) path = "params." + path.substr(6);
        if (message.rfind(e.path(), 0) == 0) message = path + message.substr(e.path().size());
        return reject(codeOf(e), message, path);
      }
      rebuild(next);
      pushUndo(current);
      return true;
    }
    std::string why = "does not apply to " + kind + " sessions";
    if (type == "add_handle" || type == "remove_handle")
      why += ": they have no handles; drag the input curves' control points directly";
    else if (type == "set_fixed")
      why += ": the input curves stay where they are while solving; there is nothing to fix";
    else if (type == "set_crease")
      why += ": creases belong to composite sessions";
    else if (type == "set_solver")
      why += ": change the model's parameters with set_params";
    return reject("invalid", why, "type");
  } catch (const SolveFailed& e) {
    return reject(e.code(), e.what(), type == "set_params" ? "params" : type == "drag" ? "position" : "type");
  } catch (const proto::SceneError& e) {
    return reject(codeOf(e), e.what(), type == "set_params" && e.path() == "model" ? "params" : e.path());
  }
}

void Session::publishSolve(bool final) {
  const std::int64_t seq = seq_.load();
  json metrics;
  json geometry = geometryJson(&metrics);
  const std::string bad = nonFiniteMetric(metrics);
  if (!bad.empty()) return rollBack("the solve gave a non-finite " + bad);
  if (!showState()) return;
  const std::string residual = solver_->isQuasiStrip() ? "objective" : "normal_variation";
  broadcast({{"type", "iterate"}, {"seq", seq}, {"revision", revision_}, {"iteration", lastSummary_.stepsTaken()},
             {"residuals", {{residual, metrics.value(residual, 0.0)}}},
             {"metrics", metrics},
             {"time_ms", lastSummary_.totalMs},
             {"geometry", std::move(geometry)}},
            Delivery::Latest, "iterate");
  if (final) {
    broadcast({{"type", "solved"}, {"seq", seq}, {"revision", revision_}, {"metrics", metrics},
               {"reason", solver_->keepsInputGeometry() && !solver_->termination().empty()
                              ? solver_->termination()
                              : std::string(engine::terminationReasonName(lastSummary_.reason))},
               {"iterations", lastSummary_.stepsTaken()}});
  }
}

SolveLimits Session::pointDragLimits(SolveLimits limits) const {
  if (isComposite() && solver_->compositeModel().hasDevelopment()) {
    limits.hardBand = solver_->compositeModel().rulingCreases() ? settings_.developedDragHardBandRulingCreases
                                                                 : settings_.developedDragHardBand;
    limits.correctionSteps = settings_.developedCorrectionSteps;
  }
  return limits;
}

bool Session::runSolver(SolveLimits limits, bool final) {
  if (keepsInput()) {  // solved whole when the model was rebuilt
    publishSolve(final);
    return true;
  }
  const std::int64_t seq = seq_.load();
  if (!(limits.hardBand > 0.0)) limits.hardBand = settings_.dragHardBand;
  limits.firstIteration = scheduleIteration_;
  // The solve budgets of a session (drag frames, releases, solve) count the CPU time of this
  // thread: on a busy machine a drag frame or a release takes longer but ends where it would on an
  // idle one (a release's fold under a CI run's load once stopped at 35° of 90°), within
  // budgetWallCap times its budget of wall time. Newer work still interrupts a solve at once
  // (onIteration), so the pointer does not wait for a frame's budget.
  limits.budgetClock = engine::BudgetClock::ThreadCpu;
  if (limits.timeBudgetMs > 0.0) limits.budgetWallCapMs = settings_.budgetWallCap * limits.timeBudgetMs;
  bool interrupted = false;
  std::string failure;  // a state that must not be shown: rolled back after the solve returns
  int streamedIteration = 0;
  // An iterate as the participants get it (geometry, metrics, residuals by term name), made
  // durable first (checkpoint): whatever a participant is shown, a restart restores.
  auto stream = [this, seq, &streamedIteration, &failure](const engine::IterationRecord& r) {
    const auto started = std::chrono::steady_clock::now();
    json residuals = json::object();
    const engine::Problem& terms = problem();  // per-term residuals by name (same names summed)
    for (int t = 0; t < terms.numTerms(); ++t) {
      const std::string& n = terms.term(t).term->name();
      residuals[n] = residuals.value(n, 0.0) + r.termResiduals[t];
    }
    json metrics;
    json geometry = geometryJson(&metrics);
    if (const std::string bad = nonFiniteMetric(metrics); !bad.empty()) {
      failure = "the solve gave a non-finite " + bad;
      return false;
    }
    if (!checkpoint(&failure)) return false;
    broadcast({{"type", "iterate"}, {"seq", seq}, {"revision", revision_}, {"iteration", r.iteration},
               {"residuals", residuals},
               {"hard_max", r.hardResidualMax},
               {"step_scale", r.stepScale},
               {"metrics", std::move(metrics)},
               {"time_ms", r.totalMs},
               {"geometry", std::move(geometry)}},
              Delivery::Latest, "iterate");
    streamedIteration = r.iteration;
    lastStreamed_ = std::chrono::steady_clock::now();
    lastStreamMs_ = std::chrono::duration<double, std::milli>(lastStreamed_ - started).count();
    return true;
  };
  // Every iterate is streamed unless the last one went out less than streamIntervalMs ago (the
  // geometry of a large model costs more than its iteration: folded annulus 50 vs 12 ms); the
  // last iterate of every solve always goes out.
  auto onIteration = [this, &interrupted, &stream](const engine::IterationRecord& r) {
    if (r.iteration == 0) return !(interrupted = hasQueuedWork());
    changed_ = true;
    if (counters_) counters_->recordIteration(r.totalMs);
    const double since = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - lastStreamed_).count();
    // The first step of every solve goes out at once (a drag message's answer: the latency the
    // pointer feels), the rest at most every interval.
    if ((r.iteration == 1 || since >= std::max(settings_.streamIntervalMs, 2.0 * lastStreamMs_)) && !stream(r))
      return false;  // a state that must not be shown: stop here, roll back below
    return !(interrupted = hasQueuedWork());
  };
  const engine::SolveSummary summary = solver_->solve(limits, onIteration);
  scheduleIteration_ += summary.stepsTaken();
  // The last iterate goes out unless newer work interrupted the solve (that work's first step
  // follows at once and supersedes it).
  if (failure.empty() && !interrupted && summary.stepsTaken() > 0 &&
      streamedIteration != summary.iterations.back().iteration)
    stream(summary.iterations.back());
  if (!failure.empty()) {
    rollBack(failure);
    return true;  // the interaction ended here: nothing more to show
  }
  if (summary.reason == engine::TerminationReason::Diverged) {
    if (counters_) counters_->recordError("diverged");
    broadcast({{"type", "error"}, {"code", "diverged"}, {"seq", seq},
               {"message", "the solver diverged; the session keeps its last good state"}});
  }
  if (final && interrupted) settlePending_ = true;  // settle() finishes it once the session is idle
  if (final && !interrupted) {
    settlePending_ = false;
    if (!showState()) return true;  // what a client reads after `solved` is what a restart restores
    broadcast({{"type", "solved"}, {"seq", seq}, {"revision", revision_}, {"metrics", metricsJson()},
               {"reason", engine::terminationReasonName(summary.reason)},
               {"iterations", summary.stepsTaken()},
               {"quality", solver_->quality().toJson()},
               {"undo", undoCountsJson()}});
  }
  return !interrupted;
}

void Session::release(const json& target, int iterations) {
  const engine::ThreadCpuClock::time_point start = engine::ThreadCpuClock::now();
  // Phase 1: the handle catches up with the pointer as far as the hard rows allow.
  SolveLimits withHandle;
  withHandle.iterations = iterations;
  withHandle.timeBudgetMs = settings_.releaseHandleShare * settings_.releaseTimeBudgetMs;
  const bool finished = keepsInput() || iterations == 0 || runSolver(pointDragLimits(withHandle), false);
  releaseDragHandle(target);
  if (!finished) {  // newer work waits: it continues from here, and settle() ends the release later
    settlePending_ = true;
    return;
  }
  // A design folded by fold-angle targets keeps the fold the drag left: its angles become the
  // targets at the slider's amount, held through the projections (holdsFoldTargets).
  const bool hold = holdsFoldTargets();
  if (hold && dragHandles_.empty()) {
    solver_->compositeModel().captureFoldTargets();
    solver_->compositeModel().holdFoldTargets(true);
  }
  polishRelease(start, iterations, hold);
}

bool Session::holdsFoldTargets() const {
  // A design folded by its fold-angle targets keeps them through a release's projections: a curved
  // fold's sheet, its short edges strained at the crease ends, would otherwise project back to the
  // flat drawing — the one state every hard row meets exactly (one drag unfolded a drawn sheet).
  if (!isComposite()) return false;
  const proto::Scene current = solver_->currentScene();
  const auto& design = std::get<models::composite::CompositeDesign>(current.model);
  return !design.foldAngles.empty() && design.foldAmount > 0.0;
}

void Session::releaseFold(int iterations) {
  const engine::ThreadCpuClock::time_point start = engine::ThreadCpuClock::now();
  // Phase 1: the creases catch up with the slider's amount as far as the hard rows allow (the
  // fold-angle rows are relaxable, like a handle).
  SolveLimits withTargets;
  withTargets.iterations = iterations;
  withTargets.timeBudgetMs = settings_.releaseHandleShare * settings_.releaseTimeBudgetMs;
  const bool finished = iterations == 0 || runSolver(withTargets, false);
  if (!finished) {
    settlePending_ = true;
    return;
  }
  polishRelease(start, iterations, true);  // the slider's position holds through the projections
}

void Session::polishRelease(engine::ThreadCpuClock::time_point start, int iterations, bool holdFoldTargets) {
  using Clock = engine::ThreadCpuClock;  // as every budget of a session (runSolver)
  // Phase 2: projection steps (no handles, no fairness) until every hard row is within the
  // tolerance: feasibility restored with the least motion.
  SolveLimits polish;
  // To quality within the time budget, not to a count: cheap models (a strip iterates in ~0.2 ms)
  // may need several hundred projections to bring a badly bent strip to the tolerance.
  polish.iterations = std::max(iterations, settings_.maxIterationsPerRequest);
  polish.hardTolerance = settings_.releaseHardTolerance;
  polish.projectionOnly = true;
  polish.holdTargetsInProjection = holdFoldTargets;
  polish.regularization = settings_.polishRegularization;
  polish.timeBudgetMs = std::max(
      1.0, settings_.releaseTimeBudgetMs - std::chrono::duration<double, std::milli>(Clock::now() - start).count());
  runSolver(polish, true);
}

void Session::settle() {
  settlePending_ = false;
  SolveLimits polish;
  polish.iterations = settings_.maxIterationsPerRequest;
  polish.hardTolerance = settings_.releaseHardTolerance;
  polish.projectionOnly = true;
  polish.holdTargetsInProjection = holdsFoldTargets();
  if (polish.holdTargetsInProjection && dragHandles_.empty()) {  // as release()
    solver_->compositeModel().captureFoldTargets();
    solver_->compositeModel().holdFoldTargets(true);
  }
  polish.regularization = settings_.polishRegularization;
  polish.timeBudgetMs = settings_.releaseTimeBudgetMs;
  runSolver(polish, true);
}

void Session::handle(const Work& work) {
  const json& m = work.message;
  const std::string type = m.value("type", "");
  const json op = m.value("op", json());
  const int pid = work.participant;

  if (type == "_links") {  // the daemon's note for an editor, after its state (Daemon: join)
    send(pid, json{{"type", "links"}, {"view_token", m.at("view_token")}});
    return;
  }
  if (type == "_state") {
    // What the newcomer is shown is durable like everything else shown. When the store cannot
    // take the current state, the session goes back to what a restart would restore (the last
    // checkpoint and the journalled edits since: durable by construction).
    if (!showState()) recover();
    send(pid, stateMessage(pid));  // first message the participant sees …
    {
      std::lock_guard<std::mutex> lock(mutex_);
      const auto it = participants_.find(pid);
      if (it != participants_.end()) it->second.ready = true;  // … then everything after it
    }
    broadcast(presenceMessage());
    return;
  }
  if (type == "_presence") {
    broadcast(presenceMessage());
    return;
  }
  if (type == "_release") {
    // The drag_end the departed participant did not send, journalled like one (a replay then
    // releases the handle too) — if its drag is still on.
    std::string path, message;
    const json canonical = canonicalTarget(m["target"], path, message);
    if (canonical.is_null() || std::find(dragHandles_.begin(), dragHandles_.end(), canonical) == dragHandles_.end())
      return;
    const json end{{"type", "drag_end"}, {"target", m["target"]}};
    if (!apply(0, end, false)) return;
    commit(0, end, {});
    release(m["target"], settings_.releaseIterations);
    return;
  }
  if (type == "ping") {
    json pong{{"type", "pong"}, {"seq", seq_.load()}};
    if (!op.is_null()) pong["op"] = op;
    send(pid, pong);
    return;
  }
  Role role = Role::None;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    const auto it = participants_.find(pid);
    if (it == participants_.end()) return;  // left meanwhile
    role = it->second.role;
    if (type == "presence") {
      if (m.contains("selection")) it->second.selection = m["selection"];
      if (m.contains("name")) it->second.name = m["name"];
    }
  }
  if (type == "presence") {
    broadcast(presenceMessage());
    return;
  }
  if (isEdit(type) && role != Role::Edit) {
    error(pid, op, "forbidden", "this connection joined with a view-only token", "type");
    return;
  }
  if ((type == "drag_end" || type == "fold_end") && !gestureApplied(pid, type)) {
    // The let-go of a gesture the session refused whole — a typed position too far away, a first
    // fold with nothing to fold: acknowledged without an edit. Nothing is solved or journalled;
    // its release would otherwise move a design no edit changed.
    json ack{{"type", "ack"}, {"seq", seq_.load()}};
    if (!op.is_null()) ack["op"] = op;
    send(pid, ack);
    return;
  }
  if (!apply(pid, m, false)) return;
  std::vector<json> ops = work.coalescedOps;
  ops.push_back(op);
  // Undo and redo restore a scene from a history that is not persisted: the journal keeps the
  // scene they produced, so a restart between the ack and the checkpoint still has it.
  const json result = type == "undo" || type == "redo" ? proto::sceneToJson(persistentScene()) : json();
  commit(pid, m, ops, result);

  if (type == "drag") {
    bool started = false;  // first drag message of this target by this participant
    {
      std::lock_guard<std::mutex> lock(mutex_);
      auto it = participants_.find(pid);
      started = it != participants_.end() && it->second.dragging != m["target"];
      if (it != participants_.end()) it->second.dragging = m["target"];
    }
    if (started) broadcast(presenceMessage());
    SolveLimits frame;
    frame.iterations = settings_.dragIterations;
    frame.timeBudgetMs = settings_.dragTimeBudgetMs;
    runSolver(pointDragLimits(frame), false);
  } else if (type == "fold") {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      auto it = participants_.find(pid);
      if (it != participants_.end()) it->second.folding = true;
    }
    if (foldTargetsCaptured_ && showState()) {
      // The first fold took the design's folds as targets and let go of its handles: every
      // client gets the scene without them and the undo step (the iterations carry geometry only).
      broadcastUpdate();
    }
    foldTargetsCaptured_ = false;
    SolveLimits frame;
    frame.iterations = settings_.dragIterations;
    frame.timeBudgetMs = settings_.dragTimeBudgetMs;
    runSolver(frame, false);
  } else if (type == "fold_end") {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      auto it = participants_.find(pid);
      if (it != participants_.end()) it->second.folding = false;
    }
    releaseFold(std::min(m.value("iterations", settings_.releaseIterations), settings_.maxIterationsPerRequest));
  } else if (type == "drag_end") {
    const int iterations = std::min(m.value("iterations", settings_.releaseIterations), settings_.maxIterationsPerRequest);
    {
      // Before the release: a participant that leaves once it has `solved` has no drag left to end.
      std::lock_guard<std::mutex> lock(mutex_);
      auto it = participants_.find(pid);
      if (it != participants_.end()) it->second.dragging = nullptr;
    }
    release(m["target"], iterations);
    broadcast(presenceMessage());
  } else if (type == "solve" || type == "rotate_points" || type == "remove_control_point" || type == "merge_faces" ||
             type == "remove_vertex" ||
             (type == "relabel_edge" && m.value("label", "") == "R")) {
    // A structural edit that then solves: its scene first (the solve's messages carry geometry
    // and metrics only, and a client keeps editing by the scene's indices).
    if (type != "solve" && showState())
      broadcastUpdate();
    SolveLimits limits;
    limits.iterations = std::min(m.value("iterations", settings_.releaseIterations), settings_.maxIterationsPerRequest);
    limits.timeBudgetMs = settings_.releaseTimeBudgetMs;
    limits.hardTolerance = settings_.releaseHardTolerance;
    runSolver(limits, true);
  } else if (showState()) {
    broadcastUpdate();
  }
}

json Session::sessionStateJson() const {
  return {{"drag_iterations", settings_.dragIterations}, {"release_iterations", settings_.releaseIterations}};
}

bool Session::checkpoint(std::string* failure) {
  json scene = proto::sceneToJson(persistentScene());
  json metrics = json(solver_->metrics());
  std::string bad;
  if (const std::string path = proto::nonFinitePath(scene); !path.empty()) bad = "number at " + path;
  else if (const std::string m = nonFiniteMetric(metrics); !m.empty()) bad = m;
  if (!bad.empty()) {
    if (failure) *failure = "the solve gave a non-finite " + bad;
    return false;
  }
  json state = sessionStateJson();
  state["metrics"] = metrics;  // as measured now: a model rebuilt from the scene measures from itself
  SessionCheckpoint c{seq_.load(), revision_ + 1, std::move(scene), std::move(state)};
  if (journal_) {
    try {
      journal_->saveCheckpoint(id_, c);  // durable before anyone is shown it
    } catch (const std::exception& e) {
      // The store failed (disk full …): the state stays in the model, unshown, until a later
      // checkpoint succeeds; REST readers keep the last stored one. Nothing is rolled back.
      if (counters_) counters_->recordError("internal");
      broadcast({{"type", "error"}, {"code", "internal"}, {"seq", seq_.load()},
                 {"message", std::string("the session's state could not be stored (") + e.what() +
                                 "); it is shown once it is"}});
      return false;
    }
  }
  revision_ = c.revision;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    cachedScene_ = std::move(c.scene);
    cachedMetrics_ = std::move(metrics);
    cachedRevision_ = revision_;
    shownSeq_ = c.seq;
  }
  unshownEdits_.clear();
  changed_ = false;
  return true;
}

bool Session::showState() {
  // A new seq is a new state even when the geometry did not move (a drag_end of a quasi strip).
  if (!changed_) {
    std::lock_guard<std::mutex> lock(mutex_);
    if (shownSeq_ == seq_.load()) return true;
  }
  std::string failure;
  if (checkpoint(&failure)) return true;
  if (!failure.empty()) rollBack(failure);  // empty: the store failed, the state waits unshown
  return false;
}

void Session::rollBack(const std::string& why) {
  if (counters_) counters_->recordError("diverged");
  rebuild(proto::sceneFromJson(sceneJson(), settings_.resources));  // the last checkpoint: what everyone was last shown
  dragHandles_.clear();
  releasedHandles_.clear();
  unshownEdits_.clear();  // their effect went with the state: the checkpoint below takes their seq
  // Checkpointed again at the current seq, so a restart does not re-apply the edits that led here.
  checkpoint(nullptr);
  broadcast({{"type", "error"}, {"code", "diverged"}, {"seq", seq_.load()}, {"revision", revision_},
             {"message", why + "; the session went back to its last good state"}});
}

void Session::restore(const json& state, std::int64_t revision,
                      const std::vector<std::pair<std::int64_t, json>>& edits, std::int64_t lastSeq) {
  if (state.is_object()) {
    settings_.dragIterations = state.value("drag_iterations", settings_.dragIterations);
    settings_.releaseIterations = state.value("release_iterations", settings_.releaseIterations);
  }
  revision_ = revision;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    cachedRevision_ = revision;
    shownSeq_ = edits.empty() ? lastSeq : edits.front().first - 1;
    // The metrics as they were shown (a model built from the scene measures from that scene:
    // displacements and ruling ratios would start over).
    if (state.is_object() && state.contains("metrics")) cachedMetrics_ = state["metrics"];
  }
  applyUnsolved(edits);
  seq_ = lastSeq;
  unshownEdits_ = edits;
  if (!edits.empty()) {
    changed_ = true;  // a new revision at the last seq, even when the edits changed nothing (drag_end)
    showState();
  }
}

void Session::applyUnsolved(const std::vector<std::pair<std::int64_t, json>>& edits) {
  // The edits acknowledged after the last checkpoint had shown nothing yet: they are applied,
  // not solved (a solve under a time budget would not give back what the daemon computed, and
  // nobody saw it). Undo and redo carry the scene they produced.
  for (const auto& [seq, edit] : edits) {
    const std::string type = edit.value("type", "");
    if ((type == "undo" || type == "redo") && edit.contains("result")) {
      rebuild(proto::sceneFromJson(edit["result"], settings_.resources));
      dragHandles_.clear();
      releasedHandles_.clear();
    } else if (type == "drag_end") {
      releaseDragHandle(edit["target"]);
    } else if (!apply(0, edit, true)) {
      spdlog::warn("session {}: journalled edit {} ({}) no longer applies; skipped", id_, seq, type);
    }
  }
  if (!dragHandles_.empty() || !releasedHandles_.empty()) {
    // Temporary handles end with their participants (after a restart there are none).
    const proto::Scene scene = persistentScene();
    rebuild(scene);
    dragHandles_.clear();
    releasedHandles_.clear();
  }
}

void Session::recover() {
  rebuild(proto::sceneFromJson(sceneJson(), settings_.resources));  // the last checkpoint
  dragHandles_.clear();
  releasedHandles_.clear();
  const auto edits = unshownEdits_;
  applyUnsolved(edits);
  changed_ = true;
  showState();
}

}  // namespace devsurf::server
