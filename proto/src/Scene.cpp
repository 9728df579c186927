#include "devsurf/proto/Scene.h"
#include "devsurf/proto/QuadMeshScene.h"

#include "devsurf/proto/BoundedJson.h"

#include <cmath>
#include <cstdint>
#include <limits>
#include <map>
#include <sstream>
#include <mutex>

namespace devsurf::proto {
namespace {

using nlohmann::json;
using models::strip::ControlPointRef;
using models::strip::Curve;
using models::strip::Handle;
using models::strip::NormalRepresentation;
using models::strip::StripDesign;

const std::pair<const char*, const char*> kEmbeddedSchemas[] = {
#include "devsurf/proto/EmbeddedSchemas.inc"
};

/// Splits "b.knots: must equal a.knots" into path and message and prefixes the path.
SceneError semanticError(const std::string& prefix, const std::string& what, const std::string& rule) {
  const std::size_t colon = what.find(": ");
  if (colon == std::string::npos) return SceneError(prefix, rule, what);
  const std::string path = what.substr(0, colon);
  return SceneError(prefix.empty() ? path : prefix + "." + path, rule, what.substr(colon + 2));
}

Eigen::Vector3d point3(const json& j) { return {j[0].get<double>(), j[1].get<double>(), j[2].get<double>()}; }

json point3Json(const Eigen::Vector3d& p) { return json::array({p.x(), p.y(), p.z()}); }

Curve curveRef(const json& j) { return j.get<std::string>() == "a" ? Curve::A : Curve::B; }

bool sameKnots(const std::vector<double>& x, const std::vector<double>& y) {
  if (x.size() != y.size()) return false;
  for (std::size_t i = 0; i < x.size(); ++i)
    if (std::abs(x[i] - y[i]) > 1e-15 * std::max(1.0, std::abs(x[i]))) return false;
  return true;
}

/// Count of indexFromJson for an index whose range is checked later, against what it names: any
/// int is taken here.
constexpr std::int64_t kAnyIndex = -1;

/// An index into a list of `count` elements: an integer in [0, count) (a number that does not
/// fit an int, a negative one or one past the end names `path`); count kAnyIndex: any int.
int indexFromJson(const json& j, const std::string& path, std::int64_t count, const std::string& what) {
  if (!j.is_number_integer() && !j.is_number_unsigned())
    throw SceneError(path, "type", "must be an integer index");
  const bool negative = j.is_number_integer() && !j.is_number_unsigned() && j.get<std::int64_t>() < 0;
  const std::uint64_t value = negative ? 0 : j.get<std::uint64_t>();
  if (count == kAnyIndex) {
    if (negative) throw SceneError(path, "index", "negative index " + j.dump());
    if (value > static_cast<std::uint64_t>(std::numeric_limits<int>::max()))
      throw SceneError(path, "index", what + " " + j.dump() + " does not exist (an index is at most " +
                                          std::to_string(std::numeric_limits<int>::max()) + ")");
    return static_cast<int>(value);
  }
  if (negative || value >= static_cast<std::uint64_t>(std::max<std::int64_t>(count, 0)))
    throw SceneError(path, "index", (negative ? std::string("negative index ") + j.dump() : what + " " + j.dump() + " does not exist") +
                                        " (" + std::to_string(count) + " " +
                                        (count == 1 ? what : what == "vertex" ? std::string("vertices") : what + "s") + ")");
  return static_cast<int>(value);
}

StripDesign stripFromJson(const json& m) {
  StripDesign d;
  d.a = curveFromJson(m.at("a"), "model.a");
  d.b = curveFromJson(m.at("b"), "model.b");
  if (m.contains("normals")) {
    const json& n = m["normals"];
    if (n.at("type") == "spline") {
      d.normals.type = NormalRepresentation::Type::Spline;
      d.normals.degree = n.value("degree", 3);
      d.normals.points = n.value("points", 0);
    }
  }
  if (m.contains("approximation")) {
    // 000_… §4.2: reference points with normals (from `devsurf fit`, or a thinned cloud).
    const json& t = m["approximation"];
    const json& points = t.at("points");
    const json& normals = t.at("normals");
    if (normals.size() != points.size())
      throw SceneError("model.approximation.normals", "size",
                       "expected one normal per point (" + std::to_string(points.size()) + "), got " +
                           std::to_string(normals.size()));
    models::strip::ApproximationTarget target;
    target.points.resize(static_cast<Eigen::Index>(points.size()), 3);
    target.normals.resize(static_cast<Eigen::Index>(points.size()), 3);
    for (std::size_t j = 0; j < points.size(); ++j) {
      target.points.row(static_cast<Eigen::Index>(j)) = point3(points[j]).transpose();
      target.normals.row(static_cast<Eigen::Index>(j)) = point3(normals[j]).transpose();
    }
    const json weights = t.value("weights", json::object());
    target.pointWeight = weights.value("point", target.pointWeight);
    target.tangencyWeight = weights.value("tangency", target.tangencyWeight);
    target.tangentPlaneWeight = weights.value("tangent_plane", target.tangentPlaneWeight);
    target.overhangWeight = weights.value("overhang", target.overhangWeight);
    target.overhangReach = t.value("overhang_reach", target.overhangReach);
    d.approximation = std::move(target);
  }
  const json fixed = m.value("fixed", json::array());
  for (std::size_t i = 0; i < fixed.size(); ++i) {
    // Any int here (StripModel::validateDesign checks the range against the curve, after the
    // counts of both curves); a number that does not fit an int is refused now.
    d.fixed.push_back({curveRef(fixed[i].at("curve")),
                       indexFromJson(fixed[i].at("index"), "model.fixed[" + std::to_string(i) + "].index",
                                     kAnyIndex, "control point")});
  }
  return d;
}

namespace composite = models::composite;

std::string indexPath(const std::string& list, std::size_t i) { return list + "[" + std::to_string(i) + "]"; }

/// {"vertex": i} or {"edge": e, "index": k}; `path` names the object for errors. Each index is
/// checked to be an int before it is read (a vertex 2^31 read as an int was negative, and the
/// point was then taken for an edge point without an edge).
composite::PointRef compositePointFromJson(const json& j, const std::string& path) {
  const bool vertex = j.contains("vertex"), edge = j.contains("edge"), index = j.contains("index");
  if (vertex && !edge && !index)
    return composite::PointRef::ofVertex(indexFromJson(j.at("vertex"), path + ".vertex", kAnyIndex, "vertex"));
  if (!vertex && edge && index)
    return composite::PointRef::ofEdgePoint(indexFromJson(j.at("edge"), path + ".edge", kAnyIndex, "edge"),
                                            indexFromJson(j.at("index"), path + ".index", kAnyIndex, "control point"));
  if (!vertex && edge) throw SceneError(path + ".index", "required", "is required with \"edge\"");
  if (!vertex && index) throw SceneError(path + ".edge", "required", "is required with \"index\"");
  throw SceneError(path, "point", "give either \"vertex\" or \"edge\" with \"index\"");
}

json compositePointJson(const composite::PointRef& r) {
  if (r.isVertex()) return {{"vertex", r.vertex}};
  return {{"edge", r.edge}, {"index", r.index}};
}

composite::CreaseKind creaseFromName(const std::string& name) {
  if (name == "fold") return composite::CreaseKind::Fold;
  if (name == "geodesic") return composite::CreaseKind::Geodesic;
  if (name == "smooth") return composite::CreaseKind::Smooth;
  if (name == "straight") return composite::CreaseKind::Straight;
  return composite::CreaseKind::None;
}

std::vector<io::CreaseStroke> drawingFromJson(const json& j) {
  std::vector<io::CreaseStroke> strokes;
  const json& list = j.at("strokes");
  for (std::size_t i = 0; i < list.size(); ++i) {
    const json& js = list[i];
    const std::string path = indexPath("model.drawing.strokes", i);
    io::CreaseStroke s;
    for (const json& p : js.at("points")) s.points.emplace_back(p[0].get<double>(), p[1].get<double>());
    s.closed = js.value("closed", false);
    s.curved = js.value("curved", false);
    if (s.points.size() < (s.closed ? 3u : 2u))
      throw SceneError(path + ".points", "count", std::string("a ") + (s.closed ? "closed " : "") + "stroke needs at least " +
                                                      (s.closed ? "3" : "2") + " points, got " + std::to_string(s.points.size()));
    s.assignment = io::parseFoldAssignment(js.at("assignment").get<std::string>());
    if (js.contains("fold_angle")) s.foldAngle = js["fold_angle"].get<double>();
    strokes.push_back(std::move(s));
  }
  return strokes;
}

json drawingToJson(const std::vector<io::CreaseStroke>& strokes) {
  json list = json::array();
  for (const io::CreaseStroke& s : strokes) {
    json points = json::array();
    for (const Eigen::Vector2d& p : s.points) points.push_back({p.x(), p.y()});
    json js = {{"points", std::move(points)}, {"assignment", std::string(1, io::foldAssignmentLetter(s.assignment))}};
    if (s.closed) js["closed"] = true;
    if (s.curved) js["curved"] = true;
    if (s.foldAngle) js["fold_angle"] = *s.foldAngle;
    list.push_back(std::move(js));
  }
  return {{"strokes", std::move(list)}};
}

composite::CompositeDesign compositeFromJson(const json& m, double handleWeight) {
  composite::CompositeDesign d;
  const json& vertices = m.at("vertices");
  const int nv = static_cast<int>(vertices.size());
  d.vertices.resize(nv, 3);
  for (int v = 0; v < nv; ++v) d.vertices.row(v) = point3(vertices[static_cast<std::size_t>(v)]).transpose();
  const json& edges = m.at("edges");
  for (std::size_t e = 0; e < edges.size(); ++e) {
    const json& je = edges[e];
    const std::string path = indexPath("model.edges", e);
    composite::CompositeEdge edge;
    edge.v0 = indexFromJson(je.at("v")[0], path + ".v[0]", nv, "vertex");
    edge.v1 = indexFromJson(je.at("v")[1], path + ".v[1]", nv, "vertex");
    edge.crease = creaseFromName(je.value("crease", "none"));
    if (je.at("type").get<std::string>() == "R") {
      edge.type = composite::EdgeType::Ruling;
      for (const char* key : {"points", "degree", "knots"})
        if (je.contains(key))
          throw SceneError(path + "." + key, "ruling", "an R edge (ruling) is straight and has no spline");
    } else {
      edge.type = composite::EdgeType::Spline;
      const int degree = je.value("degree", 3);
      const json points = je.value("points", json::array());
      const int n = static_cast<int>(points.size()) + 2;
      spline::BSplineCurve& c = edge.curve;
      c.points.resize(n, 3);
      c.points.row(0) = d.vertices.row(edge.v0);
      for (int i = 1; i + 1 < n; ++i) c.points.row(i) = point3(points[static_cast<std::size_t>(i - 1)]).transpose();
      c.points.row(n - 1) = d.vertices.row(edge.v1);
      try {
        if (je.contains("knots"))
          c.knots = spline::KnotVector::clamped(degree, je["knots"].get<std::vector<double>>(), n);
        else
          c.knots = spline::KnotVector::clampedUniform(degree, n);
      } catch (const std::invalid_argument& e) {
        const std::string what = e.what();
        if (what.rfind("knots", 0) == 0) throw semanticError(path, what, "knots");
        throw SceneError(path + ".points", "count",
                         "a degree-" + std::to_string(degree) + " edge needs at least " + std::to_string(degree - 1) +
                             " interior control points, got " + std::to_string(n - 2));
      }
    }
    d.edges.push_back(std::move(edge));
  }
  const std::int64_t ne = static_cast<std::int64_t>(d.edges.size());
  const json& faces = m.at("faces");
  for (std::size_t f = 0; f < faces.size(); ++f) {
    std::vector<int> face;
    for (std::size_t k = 0; k < faces[f].size(); ++k)
      face.push_back(indexFromJson(faces[f][k], indexPath(indexPath("model.faces", f), k), ne, "edge"));
    d.faces.push_back(std::move(face));
  }
  // A point {vertex} or {edge, index}: the vertex, the edge and the control point must exist.
  auto point = [&d, nv, ne](const json& j, const std::string& path) {
    // The ranges first, so that an index past the end is named with the count it exceeds.
    if (j.is_object() && j.contains("vertex")) indexFromJson(j.at("vertex"), path + ".vertex", nv, "vertex");
    if (j.is_object() && j.contains("edge")) indexFromJson(j.at("edge"), path + ".edge", ne, "edge");
    const composite::PointRef r = compositePointFromJson(j, path);
    if (r.isVertex()) {
      indexFromJson(j.at("vertex"), path + ".vertex", nv, "vertex");
    } else {
      const int e = indexFromJson(j.at("edge"), path + ".edge", ne, "edge");
      const composite::CompositeEdge& edge = d.edges[static_cast<std::size_t>(e)];
      if (edge.type != composite::EdgeType::Spline)
        throw SceneError(path + ".edge", "ruling", "edge " + std::to_string(e) + " is a ruling and has no control points");
      // The range against the edge's control points: CompositeModel::validateDesign ("7 is out of
      // range (edge 6 has 6 control points)"); here only that it fits an int.
      indexFromJson(j.at("index"), path + ".index", kAnyIndex, "control point");
    }
    return r;
  };
  const json fixed = m.value("fixed", json::array());
  for (std::size_t i = 0; i < fixed.size(); ++i) d.fixed.push_back(point(fixed[i], indexPath("model.fixed", i)));
  const json handles = m.value("handles", json::array());
  for (std::size_t i = 0; i < handles.size(); ++i)
    d.handles.push_back({point(handles[i], indexPath("model.handles", i)), point3(handles[i].at("position")),
                         handles[i].value("weight", handleWeight)});
  const json continuity = m.value("tangent_continuity", json::array());
  for (std::size_t i = 0; i < continuity.size(); ++i) {
    const std::string path = indexPath("model.tangent_continuity", i);
    d.tangentContinuity.push_back({indexFromJson(continuity[i].at(0), path + "[0]", ne, "edge"),
                                   indexFromJson(continuity[i].at(1), path + "[1]", ne, "edge")});
  }
  const json foldAngles = m.value("fold_angles", json::array());
  for (std::size_t i = 0; i < foldAngles.size(); ++i) {
    const std::string path = indexPath("model.fold_angles", i);
    d.foldAngles.push_back({indexFromJson(foldAngles[i].at("edge"), path + ".edge", ne, "edge"), foldAngles[i].value("end", 0),
                            foldAngles[i].at("angle").get<double>()});
  }
  d.foldAmount = m.value("fold_amount", 1.0);
  if (m.contains("drawing")) d.drawing = drawingFromJson(m["drawing"]);
  if (m.contains("development")) {
    const json& dev = m["development"];
    d.developmentSamples = dev.at("samples").get<int>();
    if (dev.contains("domain")) {
      const json& domain = dev["domain"];
      auto point2 = [](const json& j) { return Eigen::Vector2d(j[0].get<double>(), j[1].get<double>()); };
      for (const json& c : domain.value("boundary", json::array())) {
        composite::DomainCurve curve;
        const json& pts = c.at("points");
        curve.points.resize(static_cast<Eigen::Index>(pts.size()), 2);
        for (std::size_t i = 0; i < pts.size(); ++i) curve.points.row(static_cast<Eigen::Index>(i)) = point2(pts[i]).transpose();
        curve.closed = c.value("closed", false);
        d.developmentDomain.boundary.push_back(std::move(curve));
      }
      const json corners = domain.value("corners", json::array());
      for (std::size_t i = 0; i < corners.size(); ++i)
        d.developmentDomain.corners.push_back(
            {indexFromJson(corners[i].at("vertex"), indexPath("model.development.domain.corners", i) + ".vertex", nv, "vertex"),
             point2(corners[i].at("at"))});
    }
    const json seam = dev.value("seam", json::array());
    for (std::size_t i = 0; i < seam.size(); ++i)
      d.developmentSeam.push_back(indexFromJson(seam[i], indexPath("model.development.seam", i), ne, "edge"));
    if (dev.contains("vertices")) {
      const json& vs = dev["vertices"];
      d.developmentVertices.resize(static_cast<Eigen::Index>(vs.size()), 2);
      for (std::size_t i = 0; i < vs.size(); ++i)
        d.developmentVertices.row(static_cast<Eigen::Index>(i)) << vs[i][0].get<double>(), vs[i][1].get<double>();
    }
  }
  return d;
}

json compositeToJson(const composite::CompositeDesign& d) {
  json m;
  m["kind"] = "composite";
  json vertices = json::array();
  for (Eigen::Index v = 0; v < d.vertices.rows(); ++v) vertices.push_back(point3Json(d.vertices.row(v).transpose()));
  m["vertices"] = std::move(vertices);
  json edges = json::array();
  for (const composite::CompositeEdge& e : d.edges) {
    json je = {{"v", {e.v0, e.v1}}, {"type", composite::edgeTypeName(e.type)}};
    if (e.type == composite::EdgeType::Spline) {
      const spline::BSplineCurve& c = e.curve;
      je["degree"] = c.degree();
      json pts = json::array();
      for (Eigen::Index i = 1; i + 1 < c.points.rows(); ++i) pts.push_back(point3Json(c.points.row(i).transpose()));
      je["points"] = std::move(pts);
      if (!sameKnots(c.knots.knots(),
                     spline::KnotVector::clampedUniform(c.degree(), c.knots.numControlPoints()).knots()))
        je["knots"] = c.knots.knots();
    }
    if (e.crease != composite::CreaseKind::None) je["crease"] = composite::creaseKindName(e.crease);
    edges.push_back(std::move(je));
  }
  m["edges"] = std::move(edges);
  m["faces"] = d.faces;
  json fixed = json::array();
  for (const composite::PointRef& r : d.fixed) fixed.push_back(compositePointJson(r));
  if (!fixed.empty()) m["fixed"] = std::move(fixed);
  json handles = json::array();
  for (const composite::Handle& h : d.handles) {
    json jh = compositePointJson(h.point);
    jh["position"] = point3Json(h.position);
    jh["weight"] = h.weight;
    handles.push_back(std::move(jh));
  }
  if (!handles.empty()) m["handles"] = std::move(handles);
  if (!d.tangentContinuity.empty()) {
    json pairs = json::array();
    for (const auto& p : d.tangentContinuity) pairs.push_back({p[0], p[1]});
    m["tangent_continuity"] = std::move(pairs);
  }
  if (!d.foldAngles.empty()) {
    json targets = json::array();
    for (const composite::FoldAngleTarget& t : d.foldAngles) {
      json jt = {{"edge", t.edge}, {"angle", t.angleDeg}};
      if (t.end != 0) jt["end"] = t.end;
      targets.push_back(std::move(jt));
    }
    m["fold_angles"] = std::move(targets);
  }
  if (d.foldAmount != 1.0) m["fold_amount"] = d.foldAmount;
  if (!d.drawing.empty()) m["drawing"] = drawingToJson(d.drawing);
  if (d.developmentSamples > 0) {
    json dev = {{"samples", d.developmentSamples}};
    if (!d.developmentDomain.empty()) {
      json domain = json::object();
      json boundary = json::array();
      for (const composite::DomainCurve& c : d.developmentDomain.boundary) {
        json pts = json::array();
        for (Eigen::Index i = 0; i < c.points.rows(); ++i) pts.push_back({c.points(i, 0), c.points(i, 1)});
        boundary.push_back({{"points", std::move(pts)}, {"closed", c.closed}});
      }
      if (!boundary.empty()) domain["boundary"] = std::move(boundary);
      json corners = json::array();
      for (const composite::DomainCorner& c : d.developmentDomain.corners)
        corners.push_back({{"vertex", c.vertex}, {"at", {c.at.x(), c.at.y()}}});
      if (!corners.empty()) domain["corners"] = std::move(corners);
      dev["domain"] = std::move(domain);
    }
    if (!d.developmentSeam.empty()) dev["seam"] = d.developmentSeam;
    if (d.developmentVertices.rows() > 0) {
      json vs = json::array();
      for (Eigen::Index i = 0; i < d.developmentVertices.rows(); ++i)
        vs.push_back({d.developmentVertices(i, 0), d.developmentVertices(i, 1)});
      dev["vertices"] = std::move(vs);
    }
    m["development"] = std::move(dev);
  }
  return m;
}

namespace quasi = models::quasi_strip;
namespace conical = models::conical_strip;

/// The model's field names (QuasiStripModel's messages) as the scene spells them.
std::string quasiStripFieldPath(const std::string& what) {
  static const std::pair<const char*, const char*> kNames[] = {
      {"endPoints.weight", "fix_end_points.weight"}, {"extension.c1Begin", "extension.c1_begin"},
      {"extension.c1End", "extension.c1_end"},       {"extension.c2Begin", "extension.c2_begin"},
      {"extension.c2End", "extension.c2_end"},       {"extension.tolerance", "extension.tolerance"},
      {"extension.maxRounds", "extension.max_rounds"}, {"extension.maxLength", "extension.max_length"},
      {"options.lambda1/lambda2", "lambda1"}};
  for (const auto& [model, scene] : kNames)
    if (what.rfind(model, 0) == 0) return scene + what.substr(std::string(model).size());
  return what;
}

QuasiStripScene quasiStripFromJson(const json& m) {
  QuasiStripScene q;
  quasi::QuasiStripDesign& d = q.design;
  d.c1 = curveFromJson(m.at("c1"), "model.c1");
  d.c2 = curveFromJson(m.at("c2"), "model.c2");
  const json mapping = m.value("mapping", json::object());
  d.mapping.degree = mapping.value("degree", d.mapping.degree);
  d.mapping.coefficients = mapping.value("coefficients", d.mapping.coefficients);
  d.samples = m.value("samples", d.samples);
  if (m.contains("fix_end_points")) {
    d.endPoints.enabled = true;
    d.endPoints.weight = m["fix_end_points"].value("weight", d.endPoints.weight);
  }
  if (m.contains("extension")) {
    const json& x = m["extension"];
    d.extension.c1Begin = x.value("c1_begin", 0.0);
    d.extension.c1End = x.value("c1_end", 0.0);
    d.extension.c2Begin = x.value("c2_begin", 0.0);
    d.extension.c2End = x.value("c2_end", 0.0);
    d.extension.automatic = x.value("automatic", d.extension.automatic);
    d.extension.maxRounds = x.value("max_rounds", d.extension.maxRounds);
    d.extension.tolerance = x.value("tolerance", d.extension.tolerance);
    d.extension.maxLength = x.value("max_length", d.extension.maxLength);
  }
  q.options.method = m.value("method", "bspline") == "discrete" ? quasi::MappingMethod::Discrete
                                                                : quasi::MappingMethod::BSpline;
  q.options.optimizer = m.value("optimizer", "lbfgs") == "guided_projection" ? quasi::Optimizer::GuidedProjection
                                                                             : quasi::Optimizer::Lbfgs;
  q.options.lambda1 = m.value("lambda1", q.options.lambda1);
  q.options.lambda2 = m.value("lambda2", q.options.lambda2);
  q.maxIterations = m.value("max_iterations", 0);
  return q;
}

json quasiStripToJson(const QuasiStripScene& q) {
  const quasi::QuasiStripDesign& d = q.design;
  json m;
  m["kind"] = "quasi_strip";
  m["c1"] = curveToJson(d.c1);
  m["c2"] = curveToJson(d.c2);
  m["mapping"] = {{"degree", d.mapping.degree}, {"coefficients", d.mapping.coefficients}};
  m["samples"] = d.samples;
  m["method"] = q.options.method == quasi::MappingMethod::Discrete ? "discrete" : "bspline";
  m["optimizer"] = q.options.optimizer == quasi::Optimizer::GuidedProjection ? "guided_projection" : "lbfgs";
  if (d.endPoints.enabled) m["fix_end_points"] = {{"weight", d.endPoints.weight}};
  const quasi::CurveExtension& x = d.extension;
  const quasi::CurveExtension defaults;
  if (x.c1Begin != 0.0 || x.c1End != 0.0 || x.c2Begin != 0.0 || x.c2End != 0.0 || x.automatic != defaults.automatic ||
      x.maxRounds != defaults.maxRounds || x.tolerance != defaults.tolerance || x.maxLength != defaults.maxLength)
    m["extension"] = {{"c1_begin", x.c1Begin},   {"c1_end", x.c1End},         {"c2_begin", x.c2Begin},
                      {"c2_end", x.c2End},       {"automatic", x.automatic}, {"max_rounds", x.maxRounds},
                      {"tolerance", x.tolerance}, {"max_length", x.maxLength}};
  m["lambda1"] = q.options.lambda1;
  m["lambda2"] = q.options.lambda2;
  if (q.maxIterations > 0) m["max_iterations"] = q.maxIterations;
  return m;
}

conical::ConicalStripDesign conicalStripFromJson(const json& m) {
  conical::ConicalStripDesign d;
  d.p = curveFromJson(m.at("p"), "model.p");
  d.q = curveFromJson(m.at("q"), "model.q");
  d.np = m.value("np", d.np);
  d.nq = m.value("nq", d.nq);
  d.h3 = m.value("h3", d.h3);
  d.h4 = m.value("h4", d.h4);
  d.ra = m.value("ra", d.ra);
  d.objective = m.value("objective", "normal_variation") == "bending_energy" ? conical::Objective::BendingEnergy
                                                                              : conical::Objective::NormalVariation;
  d.g1 = m.value("g1", d.g1);
  return d;
}

json conicalStripToJson(const conical::ConicalStripDesign& d) {
  return {{"kind", "conical_strip"}, {"p", curveToJson(d.p)}, {"q", curveToJson(d.q)},
          {"np", d.np},              {"nq", d.nq},            {"h3", d.h3},
          {"h4", d.h4},              {"ra", d.ra},            {"objective", conical::objectiveName(d.objective)},
          {"g1", d.g1}};
}

}  // namespace

SceneError::SceneError(std::string path, std::string rule, const std::string& message)
    : std::runtime_error((path.empty() ? std::string("(root)") : path) + ": " + message),
      path_(std::move(path)),
      rule_(std::move(rule)) {}

engine::SolverOptions SolverSettings::solverOptions() const {
  engine::SolverOptions o;
  o.maxIterations = iterations;
  o.fairness = fairness;
  o.fairnessDecay = fairnessDecay;
  o.regularization = regularization;
  o.timeBudgetMs = timeBudgetMs;
  o.residualTolerance = residualTolerance;
  o.relativeChangeTolerance = relativeChangeTolerance;
  o.hardTolerance = hardTolerance;
  o.stepControl.enabled = stepControl;
  o.stepControl.hardBand = hardBand;
  return o;
}

models::strip::StripOptions SolverSettings::stripOptions() const {
  models::strip::StripOptions o;
  o.developabilityWeight = developabilityWeight;
  o.unitNormalWeight = unitNormalWeight;
  o.normalize = normalize;
  o.linearSolver = engine::linearSolverKindFromName(linearSolver);
  return o;
}

models::composite::CompositeOptions SolverSettings::compositeOptions() const {
  models::composite::CompositeOptions o;
  o.softening = softening;
  o.normalSplines = normalSplines;
  o.creaseNormals = creaseNormals == "free"     ? models::composite::CreaseNormals::Free
                    : creaseNormals == "ruling" ? models::composite::CreaseNormals::Ruling
                                                : models::composite::CreaseNormals::Auto;
  o.developmentSolve = developmentSolve == "alternating" ? models::composite::DevelopmentSolve::Alternating
                                                        : models::composite::DevelopmentSolve::Coupled;
  o.developabilityWeight = developabilityWeight;
  o.unitNormalWeight = unitNormalWeight;
  o.normalize = normalize;
  o.linearSolver = engine::linearSolverKindFromName(linearSolver);
  return o;
}

const SchemaRegistry& schemaRegistry() {
  static const SchemaRegistry registry = [] {
    SchemaRegistry r;
    for (const auto& [name, text] : kEmbeddedSchemas) {
      const std::string n(name);
      if (n.size() > 12 && n.compare(n.size() - 12, 12, ".schema.json") == 0) r.add(n, json::parse(text));
    }
    return r;
  }();
  return registry;
}

const json& embeddedDocument(const std::string& name) {
  static const std::map<std::string, json> documents = [] {
    std::map<std::string, json> d;
    for (const auto& [n, text] : kEmbeddedSchemas) d.emplace(n, json::parse(text));
    return d;
  }();
  const auto it = documents.find(name);
  if (it == documents.end()) throw std::out_of_range("no embedded document " + name);
  return it->second;
}

spline::BSplineCurve curveFromJson(const json& j, const std::string& path) {
  spline::BSplineCurve c;
  const int degree = j.at("degree").get<int>();
  const json& pts = j.at("points");
  const int n = static_cast<int>(pts.size());
  const bool closed = j.value("closed", false);
  c.points.resize(n, 3);
  for (int i = 0; i < n; ++i) c.points.row(i) = point3(pts[static_cast<std::size_t>(i)]).transpose();
  try {
    if (closed) {
      if (j.contains("knots"))
        throw SceneError(path + ".knots", "closed", "closed curves use uniform periodic knots; omit knots");
      c.knots = spline::KnotVector::periodicUniform(degree, n);
    } else if (j.contains("knots")) {
      c.knots = spline::KnotVector::clamped(degree, j["knots"].get<std::vector<double>>(), n);
    } else {
      c.knots = spline::KnotVector::clampedUniform(degree, n);
    }
  } catch (const std::invalid_argument& e) {
    const std::string what = e.what();
    // Knot-vector messages start with "knots:"; a count problem is about the points.
    if (what.rfind("knots", 0) == 0) throw semanticError(path, what, "knots");
    throw SceneError(path + ".points", "count",
                     "a degree-" + std::to_string(degree) + " curve needs at least " +
                         std::to_string(degree + 1) + " control points, got " + std::to_string(n));
  }
  if (j.contains("weights")) {
    const auto w = j["weights"].get<std::vector<double>>();
    if (static_cast<int>(w.size()) != n)
      throw SceneError(path + ".weights", "count",
                       "expected " + std::to_string(n) + " weights (one per control point), got " +
                           std::to_string(w.size()));
    c.weights = Eigen::Map<const Eigen::VectorXd>(w.data(), static_cast<Eigen::Index>(w.size()));
  }
  return c;
}

json curveToJson(const spline::BSplineCurve& c) {
  json j;
  j["degree"] = c.degree();
  json pts = json::array();
  for (Eigen::Index i = 0; i < c.points.rows(); ++i)
    pts.push_back(json::array({c.points(i, 0), c.points(i, 1), c.points(i, 2)}));
  j["points"] = std::move(pts);
  if (c.knots.kind() == spline::KnotKind::Periodic) {
    j["closed"] = true;
  } else if (!sameKnots(c.knots.knots(),
                        spline::KnotVector::clampedUniform(c.degree(), c.knots.numControlPoints()).knots())) {
    j["knots"] = c.knots.knots();
  }
  if (c.isRational()) j["weights"] = std::vector<double>(c.weights.data(), c.weights.data() + c.weights.size());
  return j;
}

const char* modelKind(const ModelData& model) {
  switch (model.index()) {
    case 0: return "strip";
    case 1: return "composite";
    case 2: return "quasi_strip";
    case 3: return "conical_strip";
    default: return "quad_mesh";
  }
}

double millimetresPerUnit(const std::string& units) {
  if (units == "mm") return 1.0;
  if (units == "cm") return 10.0;
  if (units == "m") return 1000.0;
  if (units == "in") return 25.4;
  throw std::invalid_argument("units: expected mm, cm, m or in, got \"" + units + "\"");
}

namespace {

/// Every number of the model and of the solver settings is finite, every coordinate (a member of
/// "points", "vertices", "position", "at", "boundary" arrays) within ±kMaxCoordinate, and so is
/// every other number written with a fraction or an exponent (weights, tolerances, budgets): a
/// coordinate of 1e200 squares to infinity in the first norm and turns a whole design into NaN, and
/// a weight of 1e300 does the same to the first step ("the solve produced a non-finite value").
/// Integers elsewhere are indices and counts, which the schema and the model check with their own
/// words ("vertex 3000000000 does not exist").
void checkModelNumbers(const json& j, const std::string& path, bool coordinates) {
  if (j.is_number_float()) {
    const double x = j.get<double>();
    if (!std::isfinite(x)) throw SceneError(path, "finite", "must be a finite number");
    if (coordinates && std::abs(x) > kMaxCoordinate)
      throw SceneError(path, "range", "coordinate " + j.dump() + " is outside ±1e9 (scene units)");
    if (std::abs(x) > kMaxCoordinate) throw SceneError(path, "range", j.dump() + " is outside ±1e9");
  } else if (j.is_number_integer() && coordinates) {
    const double x = j.get<double>();
    if (std::abs(x) > kMaxCoordinate)
      throw SceneError(path, "range", "coordinate " + j.dump() + " is outside ±1e9 (scene units)");
  } else if (j.is_array()) {
    for (std::size_t i = 0; i < j.size(); ++i) checkModelNumbers(j[i], path + "[" + std::to_string(i) + "]", coordinates);
  } else if (j.is_object()) {
    for (const auto& [key, value] : j.items()) {
      const bool inner = coordinates || key == "points" || key == "vertices" || key == "position" || key == "at" ||
                         key == "boundary" || key == "target";
      checkModelNumbers(value, path + "." + key, inner);
    }
  }
}

void collectControlPoints(const json& j, bool inside, Eigen::Vector3d& lo, Eigen::Vector3d& hi, int& count);

/// Every handle of the model ("handles"[i].position) within kMaxReach × the diagonal of the
/// control points from their centre, as a session refuses a drag or a handle farther away: a
/// handle a hundred million units off is a typo, and would pull the design out of any scale.
void checkHandleReach(const json& model) {
  if (!model.is_object() || !model.contains("handles") || !model["handles"].is_array()) return;
  Eigen::Vector3d lo = Eigen::Vector3d::Zero(), hi = Eigen::Vector3d::Zero();
  int count = 0;
  collectControlPoints(model, false, lo, hi, count);
  if (count == 0) return;
  const Eigen::Vector3d centre = 0.5 * (lo + hi);
  const double reach = kMaxReach * std::max((hi - lo).norm(), 1e-9);
  const json& handles = model["handles"];
  for (std::size_t i = 0; i < handles.size(); ++i) {
    const json& h = handles[i];
    if (!h.is_object() || !h.contains("position")) continue;
    const json& p = h["position"];
    if (!p.is_array() || p.size() != 3 || !p[0].is_number() || !p[1].is_number() || !p[2].is_number()) continue;
    const double distance =
        (Eigen::Vector3d(p[0].get<double>(), p[1].get<double>(), p[2].get<double>()) - centre).norm();
    if (distance > reach) {
      std::ostringstream why;
      why.precision(3);
      why << "the handle is " << distance << " from the model's centre; it must lie within " << reach << " ("
          << kMaxReach << "× the model's size)";
      throw SceneError("model.handles[" + std::to_string(i) + "].position", "range", why.str());
    }
  }
}

}  // namespace

Scene sceneFromJson(const json& given, const ResourceLimits& limits) {
  // A quad_mesh model written in the spelling before issue 13's contract is read as the contract's.
  const bool shorthand = given.is_object() && given.contains("model") && given["model"].is_object() &&
                         given["model"].value("kind", json()) == "quad_mesh";
  json rewritten;
  if (shorthand) {
    rewritten = given;
    acceptLegacyQuadMeshSpelling(rewritten["model"]);
  }
  const json& document = shorthand ? rewritten : given;
  const std::vector<SchemaError> errors = schemaRegistry().validate(document, "scene.schema.json", 1);
  if (!errors.empty()) throw SceneError(errors[0].path, errors[0].rule, errors[0].message);
  if (document.contains("model")) checkModelNumbers(document["model"], "model", false);
  if (document.contains("solver")) checkModelNumbers(document["solver"], "solver", false);

  Scene scene;
  scene.name = document.value("name", "");
  scene.summary = document.value("summary", "");
  scene.description = document.value("description", "");
  scene.units = document.value("units", scene.units);
  const json solver = document.value("solver", json::object());
  SolverSettings& s = scene.solver;
  s.iterations = solver.value("iterations", s.iterations);
  s.fairness = solver.value("fairness", s.fairness);
  s.fairnessDecay = solver.value("fairness_decay", s.fairnessDecay);
  s.regularization = solver.value("regularization", s.regularization);
  s.unitNormalWeight = solver.value("unit_normal_weight", s.unitNormalWeight);
  s.developabilityWeight = solver.value("developability_weight", s.developabilityWeight);
  s.handleWeight = solver.value("handle_weight", s.handleWeight);
  s.timeBudgetMs = solver.value("time_budget_ms", s.timeBudgetMs);
  s.residualTolerance = solver.value("residual_tolerance", s.residualTolerance);
  s.relativeChangeTolerance = solver.value("relative_change_tolerance", s.relativeChangeTolerance);
  s.linearSolver = solver.value("linear_solver", s.linearSolver);
  s.normalize = solver.value("normalize", s.normalize);
  s.stepControl = solver.value("step_control", s.stepControl);
  s.hardBand = solver.value("hard_band", s.hardBand);
  s.hardTolerance = solver.value("hard_tolerance", s.hardTolerance);
  s.normalSplines = solver.value("normal_splines", s.normalSplines);
  s.creaseNormals = solver.value("crease_normals", s.creaseNormals);
  if (s.creaseNormals != "auto" && s.creaseNormals != "ruling" && s.creaseNormals != "free")
    throw SceneError("solver.crease_normals", "enum", "must be \"auto\", \"ruling\" or \"free\"");
  s.developmentSolve = solver.value("development_solve", s.developmentSolve);
  if (s.developmentSolve != "coupled" && s.developmentSolve != "alternating")
    throw SceneError("solver.development_solve", "enum", "must be \"coupled\" or \"alternating\"");
  if (solver.contains("softening")) {
    for (std::size_t i = 0; i < 4; ++i) s.softening[i] = solver["softening"][i].get<double>();
    const auto& x = s.softening;
    if (!(0.0 <= x[0] && x[0] <= x[1] && x[1] <= x[2] && x[2] <= x[3] && x[3] <= 1.0))
      throw SceneError("solver.softening", "order", "breakpoints must satisfy 0 ≤ ξ1 ≤ ξ2 ≤ ξ3 ≤ ξ4 ≤ 1");
  }
  if (s.linearSolver == "cholmod" && !engine::cholmodAvailable())
    throw SceneError("solver.linear_solver", "enum", "cholmod is not available in this build");

  const json& model = document.at("model");
  const std::string kind = model.at("kind").get<std::string>();
  if (kind == "strip") {
    StripDesign d = stripFromJson(model);
    const json handles = model.value("handles", json::array());
    for (std::size_t i = 0; i < handles.size(); ++i) {
      const json& h = handles[i];
      const int index = indexFromJson(h.at("index"), "model.handles[" + std::to_string(i) + "].index",
                                      kAnyIndex, "control point");
      d.handles.push_back({{curveRef(h.at("curve")), index}, point3(h.at("position")), h.value("weight", s.handleWeight)});
    }
    scene.model = std::move(d);
    checkResourceLimits(scene, limits);
    try {
      models::strip::StripModel::validateDesign(std::get<StripDesign>(scene.model));
    } catch (const std::invalid_argument& e) {
      throw semanticError("model", e.what(), "model");
    }
  } else if (kind == "composite") {
    scene.model = compositeFromJson(model, s.handleWeight);
    checkResourceLimits(scene, limits);
    try {
      composite::CompositeModel::validateDesign(std::get<composite::CompositeDesign>(scene.model));
    } catch (const std::invalid_argument& e) {
      throw semanticError("model", e.what(), "model");
    }
  } else if (kind == "quasi_strip") {
    scene.model = quasiStripFromJson(model);
    checkResourceLimits(scene, limits);
    const QuasiStripScene& q = std::get<QuasiStripScene>(scene.model);
    // The model validates the curves, mapping and samples as it is built; without the engine (no
    // guided projection, no polish) building it is cheap.
    quasi::QuasiStripOptions checkOptions = q.options;
    checkOptions.optimizer = quasi::Optimizer::Lbfgs;
    checkOptions.polishIterations = 0;
    try {
      quasi::QuasiStripModel check(q.design, checkOptions);
    } catch (const std::invalid_argument& e) {
      throw semanticError("model", quasiStripFieldPath(e.what()), "model");
    }
  } else if (kind == "conical_strip") {
    scene.model = conicalStripFromJson(model);
    checkResourceLimits(scene, limits);
    try {
      conical::ConicalStripModel check(std::get<conical::ConicalStripDesign>(scene.model));  // validates the curves and parameters
    } catch (const std::invalid_argument& e) {
      throw semanticError("model", e.what(), "model");
    }
  } else if (kind == "quad_mesh") {
    scene.model = quadMeshFromJson(model);
    checkResourceLimits(scene, limits);
    const auto& d = std::get<models::quad_mesh::QuadMeshDesign>(scene.model);
    try {
      models::quad_mesh::QuadMeshModel::validateDesign(d);
    } catch (const std::invalid_argument& e) {
      throw semanticError("model", e.what(), "model");
    }
    try {
      models::quad_mesh::QuadMeshTopology check(static_cast<int>(d.mesh.rows()), d.faces);
    } catch (const std::invalid_argument& e) {
      // The topology names a face as faces[f]; in a scene the faces are model.mesh.faces.
      const std::string message = e.what();
      throw semanticError("model", message.rfind("faces[", 0) == 0 ? "mesh." + message : message, "model");
    }
  } else {
    throw SceneError("model.kind", "enum", "unknown kind \"" + kind + "\"");
  }
  checkHandleReach(model);
  return scene;
}

Scene sceneFromText(const std::string& text, const ResourceLimits& limits) {
  json document;
  try {
    document = parseBoundedJson(text);
  } catch (const JsonTooDeep& e) {
    throw SceneError("", "depth", e.what());
  } catch (const JsonSyntaxError& e) {
    throw SceneError("", "json", std::string("not valid JSON: ") + e.what());
  }
  return sceneFromJson(document, limits);
}

json sceneToJson(const Scene& scene) {
  json j;
  j["format"] = "devsurf-scene";
  j["version"] = 1;
  if (!scene.name.empty()) j["name"] = scene.name;
  if (!scene.summary.empty()) j["summary"] = scene.summary;
  if (!scene.description.empty()) j["description"] = scene.description;
  if (scene.units != "mm") j["units"] = scene.units;
  if (const auto* c = std::get_if<composite::CompositeDesign>(&scene.model)) {
    j["model"] = compositeToJson(*c);
  } else if (const auto* q = std::get_if<QuasiStripScene>(&scene.model)) {
    j["model"] = quasiStripToJson(*q);
  } else if (const auto* cs = std::get_if<conical::ConicalStripDesign>(&scene.model)) {
    j["model"] = conicalStripToJson(*cs);
  } else if (const auto* qm = std::get_if<models::quad_mesh::QuadMeshDesign>(&scene.model)) {
    j["model"] = quadMeshToJson(*qm);
  } else {
    const StripDesign& d = std::get<StripDesign>(scene.model);
    json m;
    m["kind"] = "strip";
    m["a"] = curveToJson(d.a);
    m["b"] = curveToJson(d.b);
    if (d.normals.type == NormalRepresentation::Type::Spline)
      m["normals"] = {{"type", "spline"}, {"degree", d.normals.degree}, {"points", d.normals.points}};
    else
      m["normals"] = {{"type", "vectors"}};
    json fixed = json::array();
    for (const ControlPointRef& f : d.fixed) fixed.push_back({{"curve", models::strip::curveName(f.curve)}, {"index", f.index}});
    if (!fixed.empty()) m["fixed"] = fixed;
    json handles = json::array();
    for (const Handle& h : d.handles)
      handles.push_back({{"curve", models::strip::curveName(h.point.curve)},
                         {"index", h.point.index},
                         {"position", point3Json(h.position)},
                         {"weight", h.weight}});
    if (!handles.empty()) m["handles"] = handles;
    if (d.approximation) {
      const models::strip::ApproximationTarget& t = *d.approximation;
      json points = json::array(), normals = json::array();
      for (Eigen::Index k = 0; k < t.points.rows(); ++k) {
        points.push_back(point3Json(t.points.row(k).transpose()));
        normals.push_back(point3Json(t.normals.row(k).transpose()));
      }
      m["approximation"] = {{"points", std::move(points)},
                            {"normals", std::move(normals)},
                            {"weights", {{"point", t.pointWeight},
                                         {"tangency", t.tangencyWeight},
                                         {"tangent_plane", t.tangentPlaneWeight}}}};
      if (t.overhangWeight > 0.0) m["approximation"]["weights"]["overhang"] = t.overhangWeight;
      if (t.overhangReach > 0.0) m["approximation"]["overhang_reach"] = t.overhangReach;
    }
    j["model"] = std::move(m);
  }
  const SolverSettings& s = scene.solver;
  j["solver"] = {{"iterations", s.iterations},
                 {"fairness", s.fairness},
                 {"fairness_decay", s.fairnessDecay},
                 {"regularization", s.regularization},
                 {"unit_normal_weight", s.unitNormalWeight},
                 {"developability_weight", s.developabilityWeight},
                 {"handle_weight", s.handleWeight},
                 {"time_budget_ms", s.timeBudgetMs},
                 {"residual_tolerance", s.residualTolerance},
                 {"relative_change_tolerance", s.relativeChangeTolerance},
                 {"linear_solver", s.linearSolver},
                 {"normalize", s.normalize},
                 {"step_control", s.stepControl},
                 {"hard_band", s.hardBand},
                 {"hard_tolerance", s.hardTolerance},
                 {"softening", s.softening},
                 {"normal_splines", s.normalSplines},
                 {"crease_normals", s.creaseNormals},
                 {"development_solve", s.developmentSolve}};
  return j;
}

namespace {

void collectControlPoints(const json& j, bool inside, Eigen::Vector3d& lo, Eigen::Vector3d& hi, int& count) {
  if (j.is_array()) {
    if (inside && j.size() == 3 && j[0].is_number() && j[1].is_number() && j[2].is_number()) {
      const Eigen::Vector3d p(j[0].get<double>(), j[1].get<double>(), j[2].get<double>());
      lo = count == 0 ? p : lo.cwiseMin(p);
      hi = count == 0 ? p : hi.cwiseMax(p);
      ++count;
      return;
    }
    for (const json& e : j) collectControlPoints(e, inside, lo, hi, count);
  } else if (j.is_object()) {
    for (const auto& [key, value] : j.items())
      if (key != "handles" && key != "development" && key != "unfolding")
        collectControlPoints(value, inside || key == "points" || key == "vertices", lo, hi, count);
  }
}

}  // namespace

SceneExtent sceneExtent(const Scene& scene) {
  Eigen::Vector3d lo = Eigen::Vector3d::Zero(), hi = Eigen::Vector3d::Zero();
  int count = 0;
  collectControlPoints(sceneToJson(scene).at("model"), false, lo, hi, count);
  return {0.5 * (lo + hi), (hi - lo).norm()};
}

}  // namespace devsurf::proto
