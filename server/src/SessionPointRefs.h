#pragma once

// Private to server/src/Session*.cpp: the point references of targets and scene entries, read from
// and written to JSON, the first non-finite metric of a state, and the codes of refused scenes.

#include <string>

#include <Eigen/Core>
#include <nlohmann/json.hpp>

#include "devsurf/proto/BoundedJson.h"
#include "devsurf/server/Session.h"

namespace devsurf::server::detail {

using nlohmann::json;
using models::strip::ControlPointRef;
using models::strip::Curve;
namespace composite = models::composite;
namespace qm = models::quad_mesh;

inline ControlPointRef refOf(const json& target) {
  return {target.at("curve").get<std::string>() == "a" ? Curve::A : Curve::B,
          target.at("index").get<int>()};
}

inline json targetJson(const ControlPointRef& r) {
  return {{"curve", models::strip::curveName(r.curve)}, {"index", r.index}};
}

/// A composite point reference of a target or scene entry ({"vertex"} or {"edge","index"}).
inline composite::PointRef compositeRefOf(const json& target) {
  if (target.contains("vertex")) return composite::PointRef::ofVertex(target["vertex"].get<int>());
  return composite::PointRef::ofEdgePoint(target.at("edge").get<int>(), target.at("index").get<int>());
}

/// Canonical target of a valid composite point: an S edge's end control points are its vertices.
inline json compositeTargetJson(const composite::CompositeDesign& d, const composite::PointRef& r) {
  if (r.isVertex()) return {{"vertex", r.vertex}};
  const composite::CompositeEdge& e = d.edges.at(static_cast<std::size_t>(r.edge));
  if (r.index == 0) return {{"vertex", e.v0}};
  if (r.index == e.curve.points.rows() - 1) return {{"vertex", e.v1}};
  return {{"edge", r.edge}, {"index", r.index}};
}

inline json point3Json(const Eigen::Vector3d& p) { return {p.x(), p.y(), p.z()}; }

/// A quad_mesh vertex of a target or scene entry ({"vertex"} with optional "on").
inline qm::VertexRef quadRefOf(const json& target) {
  if (target.is_number_integer()) return {qm::MeshSide::Mesh, target.get<int>()};  // a scene's fixed vertex of M
  const std::string on = target.value("on", std::string("mesh"));
  return {on == "unfolding" ? qm::MeshSide::Unfolding : on == "control" ? qm::MeshSide::Control : qm::MeshSide::Mesh,
          target.at("vertex").get<int>()};
}

/// Canonical target of a quad_mesh vertex: {"vertex": i} on M, {"on": "unfolding", "vertex": i} on
/// M′, {"on": "control", "vertex": i} for a control point of a spline surface.
inline json quadTargetJson(const qm::VertexRef& v) {
  if (v.on != qm::MeshSide::Mesh) return {{"on", qm::meshSideName(v.on)}, {"vertex", v.vertex}};
  return {{"vertex", v.vertex}};
}

/// The first metric that is not finite, or empty.
inline std::string nonFiniteMetric(const json& metrics) {
  for (const auto& [name, value] : metrics.items())
    if (!proto::nonFinitePath(value).empty()) return name;
  return {};
}

/// The error code of a refused scene: `limit` (a resource limit), `time_budget` (the session's
/// time budget ran out while the model was built), else `invalid`.
inline std::string codeOf(const proto::SceneError& e) {
  return e.rule() == "limit" || e.rule() == "time_budget" ? e.rule() : std::string("invalid");
}

}  // namespace devsurf::server::detail
