// Adding and removing control points of a composite's S edges (issue 16 item 3, 000_… §4.1): a
// strip's two curves share one spline space, so a knot goes into (or out of) every S edge linked
// to the edge through strip faces, in the direction of each strip's rulings. Insertion keeps every
// curve exactly (Boehm); removal approximates each curve in the smaller space (least squares, ends
// kept), after which the session solves as for "solve".
#include <algorithm>
#include <cmath>
#include <map>
#include <set>

#include "devsurf/models/composite/CompositeRulingSplit.h"
#include "devsurf/models/composite/CompositeTopology.h"
#include "devsurf/server/Session.h"
#include "devsurf/spline/BSplineCurve.h"

namespace devsurf::server {

namespace {

using nlohmann::json;
namespace composite = models::composite;

/// Index of the Greville abscissa in `to` nearest the one of control point `i` in `from`.
int nearestControlPoint(const spline::KnotVector& from, const spline::KnotVector& to, int i) {
  const double g = spline::grevilleAbscissae(from)[static_cast<std::size_t>(i)];
  const std::vector<double> targets = spline::grevilleAbscissae(to);
  int best = 0;
  for (int j = 1; j < static_cast<int>(targets.size()); ++j)
    if (std::abs(targets[static_cast<std::size_t>(j)] - g) < std::abs(targets[static_cast<std::size_t>(best)] - g)) best = j;
  return best;
}

}  // namespace

bool Session::applyControlPointEdit(int participant, const json& edit, bool replaying) {
  const std::string type = edit.at("type").get<std::string>();
  auto reject = refuser(participant, edit, replaying);
  if (refusedUnlessComposite(participant, edit, replaying)) return false;
  const proto::Scene before = persistentScene();
  composite::CompositeDesign design = std::get<composite::CompositeDesign>(before.model);
  const composite::CompositeTopology& topology = solver_->compositeModel().topology();
  const int edge = edit.at("edge").get<int>();
  if (edge < 0 || edge >= static_cast<int>(design.edges.size()))
    return reject("invalid", "no edge " + std::to_string(edge) + " (the composite has " + std::to_string(design.edges.size()) + ")",
                  "edge");
  if (design.edges[static_cast<std::size_t>(edge)].type != composite::EdgeType::Spline)
    return reject("invalid", "edge " + std::to_string(edge) + " is a ruling (R): it is straight and has no control points", "edge");
  const spline::BSplineCurve& curve = design.edges[static_cast<std::size_t>(edge)].curve;
  const int n = static_cast<int>(curve.points.rows()), p = curve.degree();
  const int index = edit.at("index").get<int>();
  const bool adding = type == "add_control_point";
  if (adding ? (index < 0 || index > n - 2) : (index < 1 || index > n - 2))
    return reject("invalid",
                  adding ? "a new control point goes between points index and index + 1, index in [0, " + std::to_string(n - 2) + "]"
                         : "interior control points are 1 … " + std::to_string(n - 2) + " (the ends are the edge's vertices)",
                  "index");
  const std::vector<double> greville = spline::grevilleAbscissae(curve.knots);
  double knot = 0.0;  // in `edge`'s own direction
  if (adding) {
    knot = 0.5 * (greville[static_cast<std::size_t>(index)] + greville[static_cast<std::size_t>(index + 1)]);
  } else {
    const std::vector<double>& t = curve.knots.knots();
    if (n <= p + 1)
      return reject("invalid", "edge " + std::to_string(edge) + " has the fewest control points a degree-" + std::to_string(p) +
                                   " curve can have (" + std::to_string(p + 1) + ")",
                    "index");
    double best = INFINITY;
    for (int k = p + 1; k < n; ++k)  // interior knots
      if (std::abs(t[static_cast<std::size_t>(k)] - greville[static_cast<std::size_t>(index)]) < best) {
        best = std::abs(t[static_cast<std::size_t>(k)] - greville[static_cast<std::size_t>(index)]);
        knot = t[static_cast<std::size_t>(k)];
      }
  }
  const std::map<int, bool> linked = composite::linkedSplineEdges(topology, edge);
  std::map<int, spline::KnotVector> oldKnots;
  try {
    for (const auto& [e, reversed] : linked) {
      spline::BSplineCurve& c = design.edges[static_cast<std::size_t>(e)].curve;
      oldKnots[e] = c.knots;
      const double u = reversed ? c.knots.domainBegin() + c.knots.domainEnd() - knot : knot;
      if (adding) {
        c = spline::insertKnot(c, u);
      } else {
        std::vector<double> t = c.knots.knots();
        const auto it = std::min_element(t.begin() + p + 1, t.end() - p - 1,
                                         [u](double a, double b) { return std::abs(a - u) < std::abs(b - u); });
        t.erase(it);
        c = spline::approximateInSpace(c, spline::KnotVector::clamped(p, t, c.knots.numControlPoints() - 1));
      }
    }
  } catch (const std::invalid_argument& e) {
    return reject("invalid", std::string("the spline space does not take this change: ") + e.what(), "index");
  }
  // Points addressed by control-point index follow their curve: the nearest control point of the
  // new space (by Greville abscissa).
  auto remap = [&design, &oldKnots](composite::PointRef& r) {
    if (r.isVertex()) return;
    const auto it = oldKnots.find(r.edge);
    if (it == oldKnots.end()) return;
    r.index = nearestControlPoint(it->second, design.edges[static_cast<std::size_t>(r.edge)].curve.knots, r.index);
  };
  for (composite::PointRef& r : design.fixed) remap(r);
  for (composite::Handle& h : design.handles) remap(h.point);
  design.developmentVertices.resize(0, 2);  // its sampling changed: the development starts from the surface
  proto::Scene next = before;
  next.model = std::move(design);
  return rebuildForEdit(participant, edit, replaying, before, next, "index");
}

}  // namespace devsurf::server
