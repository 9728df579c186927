#include "devsurf/proto/QuadMeshScene.h"

#include <optional>
#include <string>

#include "devsurf/proto/Scene.h"
#include "devsurf/spline/CubicSubdivision.h"

namespace devsurf::proto {

namespace qm = models::quad_mesh;
using nlohmann::json;

namespace {

std::string at(const std::string& list, std::size_t i) { return list + "[" + std::to_string(i) + "]"; }

/// An index into V vertices, named by path.
int vertexIndex(const json& j, const std::string& path, std::size_t V) {
  if (!j.is_number_integer() && !j.is_number_unsigned()) throw SceneError(path, "type", "must be an integer index");
  if (j.is_number_integer() && !j.is_number_unsigned() && j.get<std::int64_t>() < 0)
    throw SceneError(path, "index", "negative index " + j.dump());
  const std::uint64_t value = j.get<std::uint64_t>();
  if (value >= V)
    throw SceneError(path, "index",
                     "vertex " + j.dump() + " does not exist (" + std::to_string(V) + " vertices)");
  return static_cast<int>(value);
}

qm::MeshSide sideFromJson(const json& j) {
  const std::string on = j.value("on", std::string("mesh"));
  return on == "unfolding" ? qm::MeshSide::Unfolding : on == "control" ? qm::MeshSide::Control : qm::MeshSide::Mesh;
}

/// The number of points a reference on `side` may address.
std::size_t pointCount(qm::MeshSide side, std::size_t V, const qm::QuadMeshDesign& d, const std::string& path) {
  if (side != qm::MeshSide::Control) return V;
  if (!d.control) throw SceneError(path + ".on", "control", "\"control\" addresses control points; this scene has no control net");
  return static_cast<std::size_t>(d.control->points.rows());
}

Eigen::Vector3d quadPoint3(const json& j) { return {j[0].get<double>(), j[1].get<double>(), j[2].get<double>()}; }

}  // namespace

namespace {

/// A well-formed control net (as the schema wants it, and not larger than the schema allows),
/// or nullopt: the schema then names what is wrong. Two forms: {rows, columns, points} (one
/// patch) or {points, patches: [{rows, columns, indices}]}; the patches' indices are checked by
/// the model (splineRefinement), which names the field.
std::optional<qm::ControlNet> controlNetIfWellFormed(const json& c) {
  if (!c.is_object()) return std::nullopt;
  const auto integer = [](const json& o, const char* key, int fallback, int low, int high) -> std::optional<int> {
    if (!o.contains(key)) return fallback >= 0 ? std::optional<int>(fallback) : std::nullopt;
    if (!o[key].is_number_integer()) return std::nullopt;
    const auto v = o[key].get<long long>();
    if (v < low || v > high) return std::nullopt;
    return static_cast<int>(v);
  };
  const auto rounds = integer(c, "rounds", 2, 0, 4);
  if (!rounds || !c.contains("points") || !c["points"].is_array()) return std::nullopt;
  const json& points = c["points"];
  if (points.size() < 16 || points.size() > 40000) return std::nullopt;
  qm::ControlNet net;
  net.rounds = *rounds;
  if (c.contains("smoothness")) {
    if (!c["smoothness"].is_number() || !(c["smoothness"].get<double>() >= 0) || c["smoothness"].get<double>() > 1e6)
      return std::nullopt;
    net.smoothness = c["smoothness"].get<double>();
  }
  long long refined = 0;
  if (c.contains("patches")) {
    if (c.contains("rows") || c.contains("columns") || !c["patches"].is_array() || c["patches"].empty() ||
        c["patches"].size() > 1000)
      return std::nullopt;
    for (const json& p : c["patches"]) {
      if (!p.is_object() || p.size() != 3) return std::nullopt;
      const auto rows = integer(p, "rows", -1, 4, 200), columns = integer(p, "columns", -1, 4, 200);
      if (!rows || !columns || !p.contains("indices") || !p["indices"].is_array()) return std::nullopt;
      qm::ControlPatch patch;
      patch.rows = *rows;
      patch.columns = *columns;
      if (p["indices"].size() != static_cast<std::size_t>(*rows * *columns)) return std::nullopt;
      for (const json& i : p["indices"]) {
        if (!i.is_number_integer() || i.get<long long>() < 0 || i.get<long long>() > 40000) return std::nullopt;
        patch.indices.push_back(static_cast<int>(i.get<long long>()));
      }
      refined += static_cast<long long>(spline::cubicSubdividedCount(patch.rows, net.rounds)) *
                 spline::cubicSubdividedCount(patch.columns, net.rounds);
      net.patches.push_back(std::move(patch));
    }
  } else {
    const auto rows = integer(c, "rows", -1, 4, 200), columns = integer(c, "columns", -1, 4, 200);
    if (!rows || !columns) return std::nullopt;
    if (points.size() != static_cast<std::size_t>(*rows) * static_cast<std::size_t>(*columns)) return std::nullopt;
    net.rows = *rows;
    net.columns = *columns;
    refined = static_cast<long long>(spline::cubicSubdividedCount(net.rows, net.rounds)) *
              spline::cubicSubdividedCount(net.columns, net.rounds);
  }
  net.points.resize(static_cast<Eigen::Index>(points.size()), 3);
  for (std::size_t i = 0; i < points.size(); ++i) {
    const json& p = points[i];
    if (!p.is_array() || p.size() != 3) return std::nullopt;
    for (int k = 0; k < 3; ++k) {
      if (!p[k].is_number()) return std::nullopt;
      net.points(static_cast<Eigen::Index>(i), k) = p[k].get<double>();
    }
  }
  if (!net.points.allFinite()) return std::nullopt;
  // The refined mesh must stay within the mesh limits of the schema (200 000 vertices).
  if (refined > 200000) return std::nullopt;
  return net;
}

/// splineSurfaceDesign with the model's complaints ("control.patches[1].indices[3]: …") as
/// SceneErrors naming model.<field>.
qm::QuadMeshDesign refinedDesign(const qm::ControlNet& net) {
  try {
    return qm::splineSurfaceDesign(net);
  } catch (const std::invalid_argument& e) {
    const std::string what = e.what();
    const std::size_t colon = what.find(": ");
    if (colon == std::string::npos) throw SceneError("model.control", "invalid", what);
    throw SceneError("model." + what.substr(0, colon), "invalid", what.substr(colon + 2));
  }
}

/// A control net's mesh and faces are its refinement (written over any given): the rest of the
/// scene's checks then see the mesh the model will have.
void fillFromControlNet(json& m) {
  if (!m.is_object() || !m.contains("control")) return;
  const std::optional<qm::ControlNet> net = controlNetIfWellFormed(m["control"]);
  if (!net) {
    // The schema reports the control net's fault; the mesh must not be reported missing first.
    if (!m.contains("mesh"))
      m["mesh"] = {{"vertices", json::array({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}})}, {"faces", json::array({json::array({0, 1, 2})})}};
    return;
  }
  const qm::QuadMeshDesign d = refinedDesign(*net);
  json faces = json::array(), mesh = json::array();
  for (const qm::Face& f : d.faces) faces.push_back({f[0], f[1], f[2], f[3]});
  for (Eigen::Index i = 0; i < d.mesh.rows(); ++i) mesh.push_back({d.mesh(i, 0), d.mesh(i, 1), d.mesh(i, 2)});
  m["mesh"] = {{"vertices", std::move(mesh)}, {"faces", std::move(faces)}};
}

}  // namespace

void acceptLegacyQuadMeshSpelling(json& m) {
  if (!m.is_object()) return;
  if (m.contains("mesh") && m["mesh"].is_array()) {
    json mesh = {{"vertices", m["mesh"]}};
    if (m.contains("faces")) {
      mesh["faces"] = m["faces"];
      m.erase("faces");
    }
    m["mesh"] = std::move(mesh);
  } else if (!m.contains("mesh") && m.contains("faces")) {  // faces without points: a control net's
    m["mesh"] = {{"faces", m["faces"]}};                    // (its refinement replaces both)
    m.erase("faces");
  }
  if (m.contains("unfolding") && m["unfolding"].is_array()) m["unfolding"] = {{"vertices", m["unfolding"]}};
  if (m.contains("unfolding_planar")) {
    if (!m.contains("unfolding")) m["unfolding"] = json::object();
    if (m["unfolding"].is_object() && !m["unfolding"].contains("planar")) m["unfolding"]["planar"] = m["unfolding_planar"];
    m.erase("unfolding_planar");
  }
  if (m.contains("variable") && !m.contains("variables")) {
    m["variables"] = m["variable"];
    m.erase("variable");
  }
  if (m.contains("reference") && m["reference"].is_object() && m["reference"].contains("triangles") &&
      !m["reference"].contains("faces")) {
    m["reference"]["faces"] = m["reference"]["triangles"];
    m["reference"].erase("triangles");
  }
  fillFromControlNet(m);
}

qm::QuadMeshDesign quadMeshFromJson(const json& m) {
  qm::QuadMeshDesign d;
  const json& mesh = m.at("mesh").at("vertices");
  const std::size_t V = mesh.size();
  d.mesh.resize(static_cast<Eigen::Index>(V), 3);
  for (std::size_t i = 0; i < V; ++i) d.mesh.row(static_cast<Eigen::Index>(i)) = quadPoint3(mesh[i]).transpose();

  const json& faces = m.at("mesh").at("faces");
  d.faces.reserve(faces.size());
  for (std::size_t f = 0; f < faces.size(); ++f) {
    qm::Face face{-1, -1, -1, -1};
    for (std::size_t k = 0; k < faces[f].size(); ++k)
      face[k] = vertexIndex(faces[f][k], "model.mesh.faces[" + std::to_string(f) + "][" + std::to_string(k) + "]", V);
    d.faces.push_back(face);
  }

  if (m.contains("control")) {
    std::optional<qm::ControlNet> net = controlNetIfWellFormed(m["control"]);
    if (!net)
      throw SceneError("model.control", "invalid",
                       "rows × columns finite points (or patches of them), 4 … 200 each, 0 … 4 rounds, at most 200 000 "
                       "refined vertices");
    const qm::QuadMeshDesign refined = refinedDesign(*net);
    if (refined.mesh.rows() != d.mesh.rows() || refined.faces != d.faces)
      throw SceneError("model.mesh.vertices", "control", "the mesh of a control net is its refinement S^k(M)");
    d.mesh = refined.mesh;
    d.control = std::move(net);
  }
  const json unfolding = m.value("unfolding", json::object());
  d.unfoldingPlanar = unfolding.value("planar", true);
  if (unfolding.contains("vertices")) {
    const json& u = unfolding["vertices"];
    if (u.size() != V)
      throw SceneError("model.unfolding.vertices", "count",
                       std::to_string(u.size()) + " points, the mesh has " + std::to_string(V) + " vertices");
    d.unfolding = Eigen::MatrixX3d::Zero(static_cast<Eigen::Index>(V), 3);
    for (std::size_t i = 0; i < V; ++i) {
      const json& p = u[i];
      if (!d.unfoldingPlanar && p.size() != 3)
        throw SceneError(at("model.unfolding.vertices", i), "type", "expected [x, y, z]: the unfolding is not planar");
      for (std::size_t k = 0; k < p.size(); ++k) d.unfolding(static_cast<Eigen::Index>(i), static_cast<Eigen::Index>(k)) = p[k].get<double>();
      if (d.unfoldingPlanar && p.size() == 3 && p[2].get<double>() != 0.0)
        throw SceneError(at("model.unfolding.vertices", i), "planar", "a planar unfolding has z = 0 (or give [x, y])");
    }
  }
  const std::string variable = m.value("variables", std::string("mesh"));
  d.variable = variable == "both" ? qm::VariableMeshes::Both
               : variable == "unfolding" ? qm::VariableMeshes::Unfolding
                                          : qm::VariableMeshes::Mesh;
  d.conformal = m.value("conformal", false);
  d.gaussImage = m.value("gauss_image", false);
  if (m.contains("conformal_factors")) d.conformalFactors = m["conformal_factors"].get<std::vector<double>>();

  const json handles = m.value("handles", json::array());
  for (std::size_t i = 0; i < handles.size(); ++i) {
    const json& h = handles[i];
    qm::VertexHandle handle;
    const qm::MeshSide side = sideFromJson(h);
    handle.vertex = {side, vertexIndex(h.at("vertex"), at("model.handles", i) + ".vertex",
                                       pointCount(side, V, d, at("model.handles", i)))};
    handle.target = quadPoint3(h.at("position"));
    handle.weight = h.value("weight", 1.0);
    d.handles.push_back(handle);
  }
  const json fixed = m.value("fixed", json::array());
  for (std::size_t i = 0; i < fixed.size(); ++i) {
    if (fixed[i].is_object())
      d.fixed.push_back({sideFromJson(fixed[i]), vertexIndex(fixed[i].at("vertex"), at("model.fixed", i) + ".vertex",
                                                            pointCount(sideFromJson(fixed[i]), V, d, at("model.fixed", i)))});
    else
      d.fixed.push_back({qm::MeshSide::Mesh, vertexIndex(fixed[i], at("model.fixed", i), V)});
  }
  const json glue = m.value("glue", json::array());
  const auto addGluePair = [&d, V](qm::MeshSide side, const json& pair, const std::string& path) {
    const int a = vertexIndex(pair[0], path + "[0]", V), b = vertexIndex(pair[1], path + "[1]", V);
    if (a == b) throw SceneError(path, "pair", "a vertex cannot be glued to itself (" + std::to_string(a) + ")");
    d.glue.push_back({side, a, b});
  };
  for (std::size_t i = 0; i < glue.size(); ++i) {
    if (glue[i].is_array()) {
      addGluePair(qm::MeshSide::Mesh, glue[i], at("model.glue", i));
      continue;
    }
    const qm::MeshSide side = sideFromJson(glue[i]);
    if (side == qm::MeshSide::Control)
      throw SceneError(at("model.glue", i) + ".on", "control", "glue joins vertices of M or M′, not control points");
    const json& pairs = glue[i].at("pairs");
    for (std::size_t k = 0; k < pairs.size(); ++k) addGluePair(side, pairs[k], at(at("model.glue", i) + ".pairs", k));
  }
  if (m.contains("reference")) {
    const json& r = m["reference"];
    qm::ReferenceSurface ref;
    const json& rv = r.at("vertices");
    const json& rt = r.at("faces");
    ref.vertices.resize(static_cast<Eigen::Index>(rv.size()), 3);
    for (std::size_t i = 0; i < rv.size(); ++i) ref.vertices.row(static_cast<Eigen::Index>(i)) = quadPoint3(rv[i]).transpose();
    ref.triangles.resize(static_cast<Eigen::Index>(rt.size()), 3);
    for (std::size_t t = 0; t < rt.size(); ++t)
      for (int k = 0; k < 3; ++k)
        ref.triangles(static_cast<Eigen::Index>(t), k) =
            vertexIndex(rt[t][k], "model.reference.faces[" + std::to_string(t) + "][" + std::to_string(k) + "]",
                        rv.size());
    d.reference = std::move(ref);
  }
  const json w = m.value("weights", json::object());
  qm::QuadMeshWeights& q = d.weights;
  q.isometry = w.value("isometry", q.isometry);
  q.conformality = w.value("conformality", q.conformality);
  q.conformalFactor = w.value("conformal_factor", q.conformalFactor);
  q.position = w.value("position", q.position);
  q.fairnessMesh = w.value("fairness_mesh", q.fairnessMesh);
  q.fairnessUnfolding = w.value("fairness_unfolding", q.fairnessUnfolding);
  q.proximityPoint = w.value("proximity_point", q.proximityPoint);
  q.proximityPlane = w.value("proximity_plane", q.proximityPlane);
  q.mapping = w.value("mapping", q.mapping);
  q.normals = w.value("normals", q.normals);
  q.symmetry = w.value("symmetry", q.symmetry);
  const json s = m.value("schedule", json::object());
  qm::IsometrySchedule& sc = d.schedule;
  sc.energyMin = s.value("energy_min", sc.energyMin);
  sc.isometryMin = s.value("isometry_min", sc.isometryMin);
  sc.roundIterations = s.value("round_iterations", sc.roundIterations);
  sc.rounds = s.value("rounds", sc.rounds);
  sc.fairnessDivisor = s.value("fairness_divisor", sc.fairnessDivisor);
  return d;
}

json quadMeshToJson(const qm::QuadMeshDesign& d) {
  json m;
  m["kind"] = "quad_mesh";
  json faces = json::array();
  for (const qm::Face& f : d.faces) {
    json face = json::array({f[0], f[1], f[2]});
    if (f[3] >= 0) face.push_back(f[3]);
    faces.push_back(std::move(face));
  }
  json mesh = json::array();
  for (Eigen::Index i = 0; i < d.mesh.rows(); ++i) mesh.push_back({d.mesh(i, 0), d.mesh(i, 1), d.mesh(i, 2)});
  m["mesh"] = {{"vertices", std::move(mesh)}, {"faces", std::move(faces)}};
  json unfolding = json::object();
  if (!d.unfoldingPlanar) unfolding["planar"] = false;
  if (d.unfolding.rows() > 0) {
    json u = json::array();
    for (Eigen::Index i = 0; i < d.unfolding.rows(); ++i) {
      if (d.unfoldingPlanar)
        u.push_back({d.unfolding(i, 0), d.unfolding(i, 1)});
      else
        u.push_back({d.unfolding(i, 0), d.unfolding(i, 1), d.unfolding(i, 2)});
    }
    unfolding["vertices"] = std::move(u);
  }
  if (!unfolding.empty()) m["unfolding"] = std::move(unfolding);
  if (d.control) {
    json points = json::array();
    for (Eigen::Index i = 0; i < d.control->points.rows(); ++i)
      points.push_back({d.control->points(i, 0), d.control->points(i, 1), d.control->points(i, 2)});
    json control = {{"rounds", d.control->rounds}, {"points", std::move(points)}};
    if (d.control->patches.empty()) {
      control["rows"] = d.control->rows;
      control["columns"] = d.control->columns;
    } else {
      json patches = json::array();
      for (const qm::ControlPatch& p : d.control->patches)
        patches.push_back({{"rows", p.rows}, {"columns", p.columns}, {"indices", p.indices}});
      control["patches"] = std::move(patches);
    }
    if (d.control->smoothness > 0) control["smoothness"] = d.control->smoothness;
    m["control"] = std::move(control);
  }
  m["variables"] = qm::variableMeshesName(d.variable);
  m["conformal"] = d.conformal;
  if (!d.conformalFactors.empty()) m["conformal_factors"] = d.conformalFactors;
  m["gauss_image"] = d.gaussImage;
  json handles = json::array();
  for (const qm::VertexHandle& h : d.handles)
  {
    json entry = {{"vertex", h.vertex.vertex},
                  {"position", {h.target.x(), h.target.y(), h.target.z()}},
                  {"weight", h.weight}};
    if (h.vertex.on != qm::MeshSide::Mesh) entry["on"] = qm::meshSideName(h.vertex.on);
    handles.push_back(std::move(entry));
  }
  if (!handles.empty()) m["handles"] = std::move(handles);
  json fixed = json::array();
  for (const qm::VertexRef& v : d.fixed) {
    if (v.on == qm::MeshSide::Mesh) {
      fixed.push_back(v.vertex);
      continue;
    }
    fixed.push_back({{"vertex", v.vertex}, {"on", qm::meshSideName(v.on)}});
  }
  if (!fixed.empty()) m["fixed"] = std::move(fixed);
  json glue = json::array(), unfoldingPairs = json::array();
  for (const qm::GluePair& g : d.glue) (g.on == qm::MeshSide::Mesh ? glue : unfoldingPairs).push_back({g.a, g.b});
  if (!unfoldingPairs.empty()) glue.push_back({{"on", "unfolding"}, {"pairs", std::move(unfoldingPairs)}});
  if (!glue.empty()) m["glue"] = std::move(glue);
  if (d.reference) {
    json rv = json::array(), rt = json::array();
    for (Eigen::Index i = 0; i < d.reference->vertices.rows(); ++i)
      rv.push_back({d.reference->vertices(i, 0), d.reference->vertices(i, 1), d.reference->vertices(i, 2)});
    for (Eigen::Index t = 0; t < d.reference->triangles.rows(); ++t)
      rt.push_back({d.reference->triangles(t, 0), d.reference->triangles(t, 1), d.reference->triangles(t, 2)});
    m["reference"] = {{"vertices", std::move(rv)}, {"faces", std::move(rt)}};
  }
  const qm::QuadMeshWeights& w = d.weights;
  m["weights"] = {{"isometry", w.isometry},           {"conformality", w.conformality},
                  {"conformal_factor", w.conformalFactor}, {"position", w.position},
                  {"fairness_mesh", w.fairnessMesh},  {"fairness_unfolding", w.fairnessUnfolding},
                  {"proximity_point", w.proximityPoint}, {"proximity_plane", w.proximityPlane},
                  {"mapping", w.mapping},             {"normals", w.normals},
                  {"symmetry", w.symmetry}};
  const qm::IsometrySchedule& s = d.schedule;
  m["schedule"] = {{"energy_min", s.energyMin},
                   {"isometry_min", s.isometryMin},
                   {"round_iterations", s.roundIterations},
                   {"rounds", s.rounds},
                   {"fairness_divisor", s.fairnessDivisor}};
  return m;
}

}  // namespace devsurf::proto
