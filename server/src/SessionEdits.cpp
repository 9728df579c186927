// Session: the edits of a scene (apply and its refusals, rebuilds for an edit, the fold slider, a
// curve's control points).
#include "devsurf/server/Session.h"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "devsurf/proto/Geometry.h"
#include "devsurf/proto/Report.h"

#include "SessionPointRefs.h"

namespace devsurf::server {
namespace {

using nlohmann::json;
using models::strip::StripDesign;
namespace composite = models::composite;
namespace qm = models::quad_mesh;

/// Creases folded by less than this are left out when the fold slider takes a design's current
/// fold angles as its 100 % (degrees).
constexpr double kFoldCaptureMinDeg = 0.5;

}  // namespace

using detail::codeOf;
using detail::compositeRefOf;
using detail::quadRefOf;
using detail::refOf;

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
    dropDragHandles();  // the rebuilt model has none (persistentScene)
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
    // is pulled and take the new fold when it is released (release()). So may a drag of the flat
    // design (the slider at 0 %), whose targets would hold every crease at 0°.
    if (hasFoldAngles()) solver_->compositeModel().holdFoldTargets(false);
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
    dropDragHandles();
    rebuild(previous);
    return true;
  }
  if (type == "reset") {
    pushUndo();
    dropDragHandles();
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
    dropDragHandles();
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
  dropDragHandles();
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
    dropDragHandles();
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

}  // namespace devsurf::server
