// Session: targets of drags and handles — canonical forms, handle lookup and release, the
// handles and constraints sent to clients.
#include "devsurf/server/Session.h"

#include <algorithm>
#include <cmath>

#include "SessionPointRefs.h"

namespace devsurf::server {
namespace {

using nlohmann::json;
using models::strip::ControlPointRef;
using models::strip::Curve;
using models::strip::StripDesign;
namespace composite = models::composite;
namespace qm = models::quad_mesh;

}  // namespace

using detail::compositeRefOf;
using detail::compositeTargetJson;
using detail::point3Json;
using detail::quadRefOf;
using detail::quadTargetJson;
using detail::refOf;
using detail::targetJson;

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

}  // namespace devsurf::server
