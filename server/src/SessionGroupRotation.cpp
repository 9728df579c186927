// Rotating a selected group of points (000_… §4.1, Fig. 8, bottom row): the points turn rigidly
// about an axis, and guided projection then brings the composite back to a developable shape near
// the turned one (Session::handle runs the solve, as for "solve").
#include <algorithm>
#include <cmath>
#include <sstream>

#include <Eigen/Geometry>

#include "devsurf/server/Session.h"

namespace devsurf::server {

namespace {

using nlohmann::json;

/// The scene's position of a canonical composite target ({"vertex"} or {"edge","index"} with an
/// interior index), as a reference into the scene document.
json* compositeScenePoint(json& model, const json& target) {
  if (target.contains("vertex")) return &model["vertices"][target["vertex"].get<std::size_t>()];
  json& points = model["edges"][target["edge"].get<std::size_t>()]["points"];
  return &points[target["index"].get<std::size_t>() - 1];  // the scene lists interior control points only
}

}  // namespace

bool Session::applyGroupRotation(int participant, const json& edit, bool replaying) {
  auto reject = refuser(participant, edit, replaying);
  if (refusedUnlessComposite(participant, edit, replaying)) return false;
  const json& targets = edit.at("targets");
  if (!targets.is_array() || targets.empty()) return reject("invalid", "expected one point or more", "targets");
  const Eigen::Vector3d axisGiven(edit["axis"][0].get<double>(), edit["axis"][1].get<double>(), edit["axis"][2].get<double>());
  if (!axisGiven.allFinite() || !(axisGiven.norm() > 1e-12)) return reject("invalid", "the axis has no direction", "axis");
  const double angleDeg = edit.at("angle").get<double>();
  if (!std::isfinite(angleDeg) || std::abs(angleDeg) > 360.0) return reject("invalid", "expected degrees in [−360, 360]", "angle");

  const proto::Scene before = persistentScene();
  json doc = proto::sceneToJson(before);
  json& model = doc["model"];
  std::vector<json> canonical;
  for (std::size_t k = 0; k < targets.size(); ++k) {
    std::string path, message;
    const json t = canonicalTarget(targets[k], path, message);
    if (t.is_null()) return reject("invalid", message, "targets[" + std::to_string(k) + "]" + path.substr(std::string("target").size()));
    if (std::find(canonical.begin(), canonical.end(), t) == canonical.end()) canonical.push_back(t);
  }
  std::vector<Eigen::Vector3d> positions;
  for (const json& t : canonical) {
    const json& p = *compositeScenePoint(model, t);
    positions.emplace_back(p[0].get<double>(), p[1].get<double>(), p[2].get<double>());
  }
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();
  if (edit.contains("centre")) {
    centre = Eigen::Vector3d(edit["centre"][0].get<double>(), edit["centre"][1].get<double>(), edit["centre"][2].get<double>());
    const proto::SceneExtent extent = proto::sceneExtent(before);
    if (!centre.allFinite() || (centre - extent.centre).norm() > proto::kMaxReach * std::max(extent.diagonal, 1e-9))
      return reject("invalid", "the centre is far outside the model", "centre");
  } else {
    for (const Eigen::Vector3d& p : positions) centre += p / static_cast<double>(positions.size());
  }
  const Eigen::Matrix3d rotation = Eigen::AngleAxisd(angleDeg * M_PI / 180.0, axisGiven.normalized()).toRotationMatrix();
  for (std::size_t k = 0; k < canonical.size(); ++k) {
    const Eigen::Vector3d turned = centre + rotation * (positions[k] - centre);
    *compositeScenePoint(model, canonical[k]) = json::array({turned.x(), turned.y(), turned.z()});
  }
  // A handle on a turned point turns with it (it says where the user wants the point: now there).
  json none = json::array();
  for (json& h : model.contains("handles") ? model["handles"] : none) {
    if (std::find(canonical.begin(), canonical.end(), pointKey(before, h)) == canonical.end()) continue;
    const Eigen::Vector3d p(h["position"][0].get<double>(), h["position"][1].get<double>(), h["position"][2].get<double>());
    const Eigen::Vector3d turned = centre + rotation * (p - centre);
    h["position"] = json::array({turned.x(), turned.y(), turned.z()});
  }
  proto::Scene next;
  try {
    next = proto::sceneFromJson(doc, settings_.resources);
  } catch (const proto::SceneError& e) {
    return reject(e.rule() == "limit" ? e.rule() : std::string("invalid"), e.what(), e.path());
  }
  return rebuildForEdit(participant, edit, replaying, before, next, "targets");
}

}  // namespace devsurf::server
