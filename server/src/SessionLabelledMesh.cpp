// Editing the labelled mesh of a composite (issue 16 item 3, 000_… §4.1 "editing the labelled
// mesh"): relabelling edges R ↔ S, splitting a face along a new ruling between two of its corners,
// cutting a chain of strips across along a new ruling through their curves, merging the two
// faces of an edge, and a vertex added on a ruling or removed between two. Each is one rebuild and one undo step, journalled; the
// composite's own checks (CompositeTopology: the face types S R S R, S R S, S R R, R … R and the
// shared spline spaces) decide whether the result is a composite, and a refusal quotes them and
// changes nothing. Composites made from a drawing change through their drawing instead.
#include <algorithm>
#include <set>

#include "devsurf/models/composite/CompositeHinges.h"
#include "devsurf/models/composite/CompositeRulingSplit.h"
#include "devsurf/models/composite/CompositeTopology.h"
#include "devsurf/server/Session.h"
#include "devsurf/spline/BSplineCurve.h"

namespace devsurf::server {

namespace {

using nlohmann::json;
namespace composite = models::composite;

/// A straight S edge from vertex a to b in the given spline space (linear precision: control
/// points at the Greville abscissae's fractions of the chord make the curve the chord itself,
/// parametrized in proportion).
spline::BSplineCurve straightCurve(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const spline::KnotVector& knots) {
  spline::BSplineCurve c;
  c.knots = knots;
  const std::vector<double> g = spline::grevilleAbscissae(knots);
  const double u0 = knots.domainBegin(), u1 = knots.domainEnd();
  c.points.resize(static_cast<Eigen::Index>(g.size()), 3);
  for (std::size_t k = 0; k < g.size(); ++k) {
    const double s = (g[k] - u0) / (u1 - u0);
    c.points.row(static_cast<Eigen::Index>(k)) = ((1.0 - s) * a + s * b).transpose();
  }
  return c;
}

/// The knot vector reversed (t ↦ t_begin + t_end − t).
spline::KnotVector reversedKnots(const spline::KnotVector& k) {
  std::vector<double> t = k.knots();
  const double sum = k.domainBegin() + k.domainEnd();
  std::reverse(t.begin(), t.end());
  for (double& x : t) x = sum - x;
  return spline::KnotVector::clamped(k.degree(), t, k.numControlPoints());
}

/// Spline spaces to try for an edge becoming S: those of the S edges across its faces (the other
/// curve of a strip-to-be), then of every S edge, each both ways; a clamped uniform cubic with six
/// control points last (as a crease-pattern import makes them).
std::vector<spline::KnotVector> candidateSpaces(const composite::CompositeDesign& d, const std::vector<int>& facesOfEdge) {
  std::vector<spline::KnotVector> spaces;
  const auto add = [&spaces](const spline::KnotVector& k) {
    spaces.push_back(k);
    spaces.push_back(reversedKnots(k));
  };
  for (int f : facesOfEdge)
    for (int e : d.faces[static_cast<std::size_t>(f)])
      if (d.edges[static_cast<std::size_t>(e)].type == composite::EdgeType::Spline) add(d.edges[static_cast<std::size_t>(e)].curve.knots);
  for (const composite::CompositeEdge& e : d.edges)
    if (e.type == composite::EdgeType::Spline) add(e.curve.knots);
  spaces.push_back(spline::KnotVector::clampedUniform(3, 6));
  return spaces;
}

/// The faces of each edge (one or two).
std::vector<std::vector<int>> facesOfEdges(const composite::CompositeDesign& d) {
  std::vector<std::vector<int>> faces(d.edges.size());
  for (std::size_t f = 0; f < d.faces.size(); ++f)
    for (int e : d.faces[f]) faces[static_cast<std::size_t>(e)].push_back(static_cast<int>(f));
  return faces;
}

/// The vertex where edges a and b of a face loop meet.
int sharedVertex(const composite::CompositeDesign& d, int a, int b) {
  const composite::CompositeEdge& ea = d.edges[static_cast<std::size_t>(a)];
  const composite::CompositeEdge& eb = d.edges[static_cast<std::size_t>(b)];
  return ea.v0 == eb.v0 || ea.v0 == eb.v1 ? ea.v0 : ea.v1;
}

/// Removes edge `gone` from the design: later edges move down one, and every reference follows
/// (faces, fold targets, tangent pairs, the development's seam, points on S edges).
void eraseEdge(composite::CompositeDesign& d, int gone) {
  d.edges.erase(d.edges.begin() + gone);
  const auto shifted = [gone](int e) { return e > gone ? e - 1 : e; };
  for (std::vector<int>& face : d.faces)
    for (int& e : face) e = shifted(e);
  d.foldAngles.erase(std::remove_if(d.foldAngles.begin(), d.foldAngles.end(),
                                    [gone](const composite::FoldAngleTarget& t) { return t.edge == gone; }),
                     d.foldAngles.end());
  for (composite::FoldAngleTarget& t : d.foldAngles) t.edge = shifted(t.edge);
  d.tangentContinuity.erase(std::remove_if(d.tangentContinuity.begin(), d.tangentContinuity.end(),
                                           [gone](const std::array<int, 2>& p) { return p[0] == gone || p[1] == gone; }),
                            d.tangentContinuity.end());
  for (std::array<int, 2>& p : d.tangentContinuity) p = {shifted(p[0]), shifted(p[1])};
  d.developmentSeam.erase(std::remove(d.developmentSeam.begin(), d.developmentSeam.end(), gone), d.developmentSeam.end());
  for (int& e : d.developmentSeam) e = shifted(e);
  for (composite::PointRef& r : d.fixed)
    if (r.edge >= 0) r.edge = shifted(r.edge);
  for (composite::Handle& h : d.handles)
    if (h.point.edge >= 0) h.point.edge = shifted(h.point.edge);
}

/// Drops the fixed points and handles on the interior control points of edge e (it has none now).
void dropPointsOnEdge(composite::CompositeDesign& d, int e) {
  d.fixed.erase(std::remove_if(d.fixed.begin(), d.fixed.end(), [e](const composite::PointRef& r) { return r.edge == e; }),
                d.fixed.end());
  d.handles.erase(std::remove_if(d.handles.begin(), d.handles.end(), [e](const composite::Handle& h) { return h.point.edge == e; }),
                  d.handles.end());
}

}  // namespace

bool Session::refusedUnlessComposite(int participant, const json& edit, bool replaying) {
  if (isComposite()) return false;
  refuse(participant, edit, replaying, "invalid",
         std::string("applies to composite sessions; this session edits a ") + proto::modelKind(solver_->currentScene().model), "type");
  return true;
}

bool Session::applyLabelledMeshEdit(int participant, const json& edit, bool replaying) {
  const std::string type = edit.at("type").get<std::string>();
  auto reject = refuser(participant, edit, replaying);
  if (refusedUnlessComposite(participant, edit, replaying)) return false;
  const proto::Scene before = persistentScene();
  composite::CompositeDesign design = std::get<composite::CompositeDesign>(before.model);
  if (!design.drawing.empty())
    return reject("invalid",
                  "this composite is made from its drawing: split and merge faces by drawing and erasing creases on "
                  "the crease board, and bend a straight crease by reshaping it",
                  "type");
  const int numEdges = static_cast<int>(design.edges.size());
  const std::vector<std::vector<int>> facesOf = facesOfEdges(design);
  // The composite's own verdict on the edited design, as the scene path it names.
  const auto verdict = [](const composite::CompositeDesign& d) -> std::string {
    try {
      const composite::CompositeTopology topology(d);
    } catch (const std::invalid_argument& e) {
      return e.what();
    }
    return {};
  };

  if (type == "relabel_edge") {
    const composite::EdgeType to = edit.at("label").get<std::string>() == "S" ? composite::EdgeType::Spline : composite::EdgeType::Ruling;
    std::set<int> edges;
    const json& list = edit.at("edges");
    for (std::size_t k = 0; k < list.size(); ++k) {
      const int e = list[k].get<int>();
      const std::string path = "edges[" + std::to_string(k) + "]";
      if (e < 0 || e >= numEdges)
        return reject("invalid", "no edge " + std::to_string(e) + " (the composite has " + std::to_string(numEdges) + ")", path);
      if (design.edges[static_cast<std::size_t>(e)].type == to)
        return reject("invalid", "edge " + std::to_string(e) + " is " + composite::edgeTypeName(to) + " already", path);
      edges.insert(e);
    }
    for (int e : edges) {
      composite::CompositeEdge& edge = design.edges[static_cast<std::size_t>(e)];
      if (to != composite::EdgeType::Ruling) continue;
      edge.type = composite::EdgeType::Ruling;
      edge.curve = spline::BSplineCurve{};
      if (edge.crease != composite::CreaseKind::Smooth) edge.crease = composite::CreaseKind::None;
      dropPointsOnEdge(design, e);
      design.tangentContinuity.erase(std::remove_if(design.tangentContinuity.begin(), design.tangentContinuity.end(),
                                                    [e](const std::array<int, 2>& p) { return p[0] == e || p[1] == e; }),
                                     design.tangentContinuity.end());
    }
    if (to == composite::EdgeType::Spline) {
      // The new curves are straight, in one spline space (a strip's two curves must share theirs),
      // each in either direction: the first space and directions the composite takes.
      std::vector<int> facesOfNew;
      for (int e : edges)
        for (int f : facesOf[static_cast<std::size_t>(e)]) facesOfNew.push_back(f);
      const std::vector<int> list(edges.begin(), edges.end());
      const int m = static_cast<int>(list.size());
      const int masks = m <= 6 ? 1 << m : 2;
      std::string firstWhy;
      bool placed = false;
      for (const spline::KnotVector& space : candidateSpaces(design, facesOfNew)) {
        const spline::KnotVector reversed = reversedKnots(space);
        for (int mask = 0; mask < masks && !placed; ++mask) {
          for (int k = 0; k < m; ++k) {
            composite::CompositeEdge& edge = design.edges[static_cast<std::size_t>(list[static_cast<std::size_t>(k)])];
            edge.type = composite::EdgeType::Spline;
            const bool flip = m <= 6 ? (mask >> k) & 1 : mask == 1;
            edge.curve = straightCurve(design.vertices.row(edge.v0).transpose(), design.vertices.row(edge.v1).transpose(),
                                       flip ? reversed : space);
          }
          const std::string why = verdict(design);
          if (firstWhy.empty()) firstWhy = why;
          placed = why.empty();
        }
        if (placed) break;
      }
      if (!placed) return reject("invalid", "the composite does not take this labelling: " + firstWhy, "edges");
    }
    // Fold targets follow the hinges: an R edge folds about itself (end 0), an S edge at each end
    // where both its faces have a ruling.
    std::vector<composite::FoldAngleTarget> targets;
    const std::string why = verdict(design);
    if (!why.empty()) return reject("invalid", "the composite does not take this labelling: " + why, "edges");
    const composite::CompositeTopology topology(design);
    for (const composite::FoldAngleTarget& t : design.foldAngles) {
      if (!edges.count(t.edge)) {
        targets.push_back(t);
        continue;
      }
      if (t.end != 0) continue;  // one angle per crease carried over
      for (int end : {0, 1})
        if ((to == composite::EdgeType::Spline || end == 0) && composite::hasFoldHinge(topology, t.edge, end))
          targets.push_back({t.edge, end, t.angleDeg});
    }
    design.foldAngles = std::move(targets);
  } else if (type == "split_face") {
    const int f = edit.at("face").get<int>();
    if (f < 0 || f >= static_cast<int>(design.faces.size()))
      return reject("invalid", "no face " + std::to_string(f) + " (the composite has " + std::to_string(design.faces.size()) + ")", "face");
    const std::vector<int> loop = design.faces[static_cast<std::size_t>(f)];
    const int n = static_cast<int>(loop.size());
    // corner[k]: the vertex where loop edges k − 1 and k meet.
    std::vector<int> corner(static_cast<std::size_t>(n));
    for (int k = 0; k < n; ++k) corner[static_cast<std::size_t>(k)] = sharedVertex(design, loop[static_cast<std::size_t>((k + n - 1) % n)], loop[static_cast<std::size_t>(k)]);
    const int va = edit.at("vertices")[0].get<int>(), vb = edit.at("vertices")[1].get<int>();
    const auto ka = std::find(corner.begin(), corner.end(), va), kb = std::find(corner.begin(), corner.end(), vb);
    if (ka == corner.end()) return reject("invalid", "vertex " + std::to_string(va) + " is not a corner of face " + std::to_string(f), "vertices[0]");
    if (kb == corner.end()) return reject("invalid", "vertex " + std::to_string(vb) + " is not a corner of face " + std::to_string(f), "vertices[1]");
    const int i = static_cast<int>(ka - corner.begin()), j = static_cast<int>(kb - corner.begin());
    if (i == j || (i + 1) % n == j || (j + 1) % n == i)
      return reject("invalid", "vertices " + std::to_string(va) + " and " + std::to_string(vb) +
                                   " are joined by an edge of the face already; a new edge joins two corners that are not neighbours",
                    "vertices");
    for (const composite::CompositeEdge& e : design.edges)
      if ((e.v0 == va && e.v1 == vb) || (e.v0 == vb && e.v1 == va))
        return reject("invalid", "an edge joins vertices " + std::to_string(va) + " and " + std::to_string(vb) + " already", "vertices");
    composite::splitFaceLoop(design, f, i, j);
    if (const std::string why = verdict(design); !why.empty())
      return reject("invalid", "the two halves are not valid faces: " + why, "vertices");
  } else if (type == "split_along_ruling") {
    // A new ruling across a strip at a fraction of its curve, carried through every strip whose
    // curves share that spline space (a chain of strips is cut across as one).
    try {
      design = composite::splitAlongRuling(design, solver_->compositeModel().topology(), edit.at("edge").get<int>(),
                                           edit.value("at", 0.5));
    } catch (const std::invalid_argument& e) {
      const std::string what = e.what();
      const std::size_t colon = what.find(": ");
      return reject("invalid", what.substr(colon + 2), what.substr(0, colon));
    }
  } else if (type == "split_edge") {
    // A vertex on a ruling: the edge becomes two (the faces on it get a corner there), so a face
    // can then be split from that point.
    const int e = edit.at("edge").get<int>();
    if (e < 0 || e >= numEdges)
      return reject("invalid", "no edge " + std::to_string(e) + " (the composite has " + std::to_string(numEdges) + ")", "edge");
    const composite::CompositeEdge was = design.edges[static_cast<std::size_t>(e)];
    if (was.type == composite::EdgeType::Spline)
      return reject("invalid",
                    "edge " + std::to_string(e) + " is a curve (S): a point on it is a cut across its strips (split_along_ruling, \"Cut across\")",
                    "edge");
    const double at = edit.value("at", 0.5);
    const int w = static_cast<int>(design.vertices.rows());
    design.vertices.conservativeResize(w + 1, 3);
    design.vertices.row(w) = (1.0 - at) * design.vertices.row(was.v0) + at * design.vertices.row(was.v1);
    const std::vector<composite::CompositeEdge> edgesBefore = design.edges;
    composite::CompositeEdge first = was, second = was;
    first.v1 = w;
    second.v0 = w;
    design.edges[static_cast<std::size_t>(e)] = first;
    const int added = static_cast<int>(design.edges.size());
    design.edges.push_back(second);
    composite::insertSecondHalves(design, edgesBefore, {{e, added}});
    const std::vector<composite::FoldAngleTarget> targets = design.foldAngles;
    for (const composite::FoldAngleTarget& t : targets)
      if (t.edge == e) design.foldAngles.push_back({added, t.end, t.angleDeg});  // both halves fold as one
    if (std::find(design.developmentSeam.begin(), design.developmentSeam.end(), e) != design.developmentSeam.end())
      design.developmentSeam.push_back(added);
    if (const std::string why = verdict(design); !why.empty())
      return reject("invalid", "the faces on the edge do not take a corner there: " + why, "edge");
  } else if (type == "remove_vertex") {
    // The opposite: a vertex where exactly two rulings meet goes, and they become one.
    const int v = edit.at("vertex").get<int>();
    const int numVertices = static_cast<int>(design.vertices.rows());
    if (v < 0 || v >= numVertices)
      return reject("invalid", "no vertex " + std::to_string(v) + " (the composite has " + std::to_string(numVertices) + ")", "vertex");
    std::vector<int> at;
    for (int e = 0; e < numEdges; ++e)
      if (design.edges[static_cast<std::size_t>(e)].v0 == v || design.edges[static_cast<std::size_t>(e)].v1 == v) at.push_back(e);
    if (at.size() != 2)
      return reject("invalid", "vertex " + std::to_string(v) + " is on " + std::to_string(at.size()) +
                                   " edges; a vertex goes only where two edges meet (they become one)",
                    "vertex");
    const composite::CompositeEdge& x = design.edges[static_cast<std::size_t>(at[0])];
    const composite::CompositeEdge& y = design.edges[static_cast<std::size_t>(at[1])];
    if (x.type != composite::EdgeType::Ruling || y.type != composite::EdgeType::Ruling)
      return reject("invalid", "vertex " + std::to_string(v) + " ends a curve (S edge): only a vertex between two rulings goes", "vertex");
    const int a = x.v0 == v ? x.v1 : x.v0, b = y.v0 == v ? y.v1 : y.v0;
    for (const composite::CompositeEdge& e : design.edges)
      if ((e.v0 == a && e.v1 == b) || (e.v0 == b && e.v1 == a))
        return reject("invalid", "vertices " + std::to_string(a) + " and " + std::to_string(b) + " are joined by an edge already", "vertex");
    for (const composite::PointRef& r : design.fixed)
      if (r.vertex == v) return reject("invalid", "vertex " + std::to_string(v) + " is fixed: unfix it first", "vertex");
    // The first edge spans both, the second goes (later edges move down one), then the vertex.
    composite::CompositeEdge& kept = design.edges[static_cast<std::size_t>(at[0])];
    kept.v0 = a;
    kept.v1 = b;
    for (std::vector<int>& loop : design.faces) loop.erase(std::remove(loop.begin(), loop.end(), at[1]), loop.end());
    design.handles.erase(std::remove_if(design.handles.begin(), design.handles.end(),
                                        [v](const composite::Handle& h) { return h.point.vertex == v; }),
                         design.handles.end());
    eraseEdge(design, at[1]);
    const auto shifted = [v](int u) { return u > v ? u - 1 : u; };
    for (composite::CompositeEdge& e : design.edges) {
      e.v0 = shifted(e.v0);
      e.v1 = shifted(e.v1);
    }
    for (composite::PointRef& r : design.fixed)
      if (r.vertex >= 0) r.vertex = shifted(r.vertex);
    for (composite::Handle& h : design.handles)
      if (h.point.vertex >= 0) h.point.vertex = shifted(h.point.vertex);
    auto& corners = design.developmentDomain.corners;
    corners.erase(std::remove_if(corners.begin(), corners.end(), [v](const composite::DomainCorner& c) { return c.vertex == v; }),
                  corners.end());
    for (composite::DomainCorner& c : corners) c.vertex = shifted(c.vertex);
    Eigen::MatrixX3d vertices(numVertices - 1, 3);
    for (int u = 0, row = 0; u < numVertices; ++u)
      if (u != v) vertices.row(row++) = design.vertices.row(u);
    design.vertices = std::move(vertices);
    if (const std::string why = verdict(design); !why.empty())
      return reject("invalid", "the faces around it do not take one edge there: " + why, "vertex");
  } else {  // merge_faces
    const int e = edit.at("edge").get<int>();
    if (e < 0 || e >= numEdges)
      return reject("invalid", "no edge " + std::to_string(e) + " (the composite has " + std::to_string(numEdges) + ")", "edge");
    const std::vector<int>& faces = facesOf[static_cast<std::size_t>(e)];
    if (faces.size() != 2) return reject("invalid", "edge " + std::to_string(e) + " is on the boundary: it has one face", "edge");
    const std::vector<int> a = design.faces[static_cast<std::size_t>(faces[0])], b = design.faces[static_cast<std::size_t>(faces[1])];
    // a from after e round to before e, then b the same way: one loop without e.
    const auto around = [e](const std::vector<int>& loop) {
      const auto at = std::find(loop.begin(), loop.end(), e);
      std::vector<int> out(at + 1, loop.end());
      out.insert(out.end(), loop.begin(), at);
      return out;
    };
    std::vector<int> merged = around(a);
    const std::vector<int> rest = around(b);
    merged.insert(merged.end(), rest.begin(), rest.end());
    // The union must be a disc: no vertex twice on its boundary (two faces meeting at more than e).
    std::vector<int> corners;
    for (std::size_t k = 0; k < merged.size(); ++k)
      corners.push_back(sharedVertex(design, merged[(k + merged.size() - 1) % merged.size()], merged[k]));
    std::sort(corners.begin(), corners.end());
    if (std::adjacent_find(corners.begin(), corners.end()) != corners.end())
      return reject("invalid", "faces " + std::to_string(faces[0]) + " and " + std::to_string(faces[1]) +
                                   " share more than edge " + std::to_string(e) + ": their union would not be one face",
                    "edge");
    const int keep = std::min(faces[0], faces[1]), drop = std::max(faces[0], faces[1]);
    design.faces[static_cast<std::size_t>(keep)] = std::move(merged);
    design.faces.erase(design.faces.begin() + drop);
    dropPointsOnEdge(design, e);
    eraseEdge(design, e);
    if (const std::string why = verdict(design); !why.empty())
      return reject("invalid", "the two faces do not make one valid face: " + why, "edge");
  }
  design.developmentVertices.resize(0, 2);  // its sampling changed: the development starts from the surface
  proto::Scene next = before;
  next.model = std::move(design);
  const char* field = type == "relabel_edge" ? "edges" : type == "split_face" ? "vertices" : type == "remove_vertex" ? "vertex" : "edge";
  return rebuildForEdit(participant, edit, replaying, before, next, field);
}

}  // namespace devsurf::server
