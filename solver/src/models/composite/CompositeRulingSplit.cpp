#include "devsurf/models/composite/CompositeRulingSplit.h"

#include <algorithm>
#include <array>
#include <cassert>
#include <cmath>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "devsurf/spline/BSplineCurve.h"

namespace devsurf::models::composite {

namespace {

/// A clamped curve cut at parameter u into the part before and the part after, both exact (knot
/// u raised to multiplicity degree), each reparametrized onto [0, 1] so that halves of curves
/// sharing a spline space share theirs again (CompositeTopology compares knot values).
std::pair<spline::BSplineCurve, spline::BSplineCurve> cutCurveAt(const spline::BSplineCurve& curve, double u) {
  const int p = curve.degree();
  // A cut within rounding of a knot is at that knot (a reversed curve's 1 − 1/3 is not 2/3).
  const double span = curve.knots.domainEnd() - curve.knots.domainBegin();
  for (double x : curve.knots.knots())
    if (std::abs(x - u) <= 1e-10 * span) {
      u = x;
      break;
    }
  const int s = curve.knots.multiplicity(u);
  const spline::BSplineCurve raised = s < p ? spline::insertKnot(curve, u, p - s) : curve;
  const std::vector<double>& t = raised.knots.knots();
  const auto first = std::find(t.begin(), t.end(), u);
  assert(first != t.end() && "the inserted knot is in the knot vector");
  const int i = static_cast<int>(first - t.begin());  // t[i … i + p − 1] = u
  if (i + p > static_cast<int>(t.size()) || std::count(t.begin(), t.end(), u) != p)
    throw std::logic_error("cutting a curve: knot " + std::to_string(u) + " did not reach multiplicity " + std::to_string(p));
  const int k = i - 1;                                  // C(u) = P_k
  const int n = static_cast<int>(raised.points.rows());
  const auto normalized = [p](std::vector<double> knots, int count) {
    const double a = knots.front(), b = knots.back();
    for (double& x : knots) x = (x - a) / (b - a);
    knots.front() = 0.0;
    knots.back() = 1.0;
    return spline::KnotVector::clamped(p, std::move(knots), count);
  };
  std::vector<double> left(t.begin(), t.begin() + i), right(static_cast<std::size_t>(p + 1), u);
  left.insert(left.end(), static_cast<std::size_t>(p + 1), u);
  right.insert(right.end(), t.begin() + i + p, t.end());
  spline::BSplineCurve a, b;
  a.points = raised.points.topRows(k + 1);
  b.points = raised.points.bottomRows(n - k);
  a.knots = normalized(std::move(left), k + 1);
  b.knots = normalized(std::move(right), n - k);
  return {std::move(a), std::move(b)};
}

/// The vertex where edges x and y of a face loop meet.
int loopCorner(const CompositeDesign& d, int x, int y) {
  const CompositeEdge& a = d.edges[static_cast<std::size_t>(x)];
  const CompositeEdge& b = d.edges[static_cast<std::size_t>(y)];
  return a.v0 == b.v0 || a.v0 == b.v1 ? a.v0 : a.v1;
}

}  // namespace

void insertSecondHalves(CompositeDesign& design, const std::vector<CompositeEdge>& before, const std::map<int, int>& secondHalf) {
  for (std::vector<int>& loop : design.faces) {
    std::vector<int> next;
    const int n = static_cast<int>(loop.size());
    for (int k = 0; k < n; ++k) {
      const int e = loop[static_cast<std::size_t>(k)];
      const auto half = secondHalf.find(e);
      if (half == secondHalf.end()) {
        next.push_back(e);
        continue;
      }
      // The loop enters e at the vertex it shares with the previous edge (old endpoints).
      const CompositeEdge& was = before[static_cast<std::size_t>(e)];
      const CompositeEdge& prev = before[static_cast<std::size_t>(loop[static_cast<std::size_t>((k + n - 1) % n)])];
      const bool entersAtV0 = prev.v0 == was.v0 || prev.v1 == was.v0;
      next.push_back(entersAtV0 ? e : half->second);
      next.push_back(entersAtV0 ? half->second : e);
    }
    loop = std::move(next);
  }
}

int splitFaceLoop(CompositeDesign& design, int face, int i, int j) {
  const std::vector<int> loop = design.faces[static_cast<std::size_t>(face)];
  const int n = static_cast<int>(loop.size());
  assert(i != j && (i + 1) % n != j && (j + 1) % n != i && "the corners are not neighbours");
  CompositeEdge ruling;
  ruling.v0 = loopCorner(design, loop[static_cast<std::size_t>((i + n - 1) % n)], loop[static_cast<std::size_t>(i)]);
  ruling.v1 = loopCorner(design, loop[static_cast<std::size_t>((j + n - 1) % n)], loop[static_cast<std::size_t>(j)]);
  ruling.type = EdgeType::Ruling;
  const int added = static_cast<int>(design.edges.size());
  design.edges.push_back(ruling);
  // Corner i to corner j along the loop, then the new edge back; and j to i, then the new edge.
  std::vector<int> first, second;
  for (int k = i; k != j; k = (k + 1) % n) first.push_back(loop[static_cast<std::size_t>(k)]);
  first.push_back(added);
  for (int k = j; k != i; k = (k + 1) % n) second.push_back(loop[static_cast<std::size_t>(k)]);
  second.push_back(added);
  design.faces[static_cast<std::size_t>(face)] = std::move(first);
  design.faces.push_back(std::move(second));
  return added;
}

std::map<int, bool> linkedSplineEdges(const CompositeTopology& topology, int edge) {
  std::map<int, bool> reversedOf{{edge, false}};
  std::vector<int> queue{edge};
  while (!queue.empty()) {
    const int e = queue.back();
    queue.pop_back();
    for (int f = 0; f < topology.numFaces(); ++f) {
      const FaceInfo& face = topology.face(f);
      if (face.a.edge < 0 || face.b.edge < 0) continue;
      for (const auto& [mine, other] : {std::pair{face.a, face.b}, std::pair{face.b, face.a}}) {
        if (mine.edge != e || reversedOf.count(other.edge)) continue;
        // Both run with the strip's u: relative to `edge`, other is reversed when exactly one of
        // (e against edge, e against u, other against u) flips.
        reversedOf[other.edge] = reversedOf[e] != (mine.reversed != other.reversed);
        queue.push_back(other.edge);
      }
    }
  }
  return reversedOf;
}

CompositeDesign splitAlongRuling(const CompositeDesign& design, const CompositeTopology& topology, int edge, double at) {
  const int numEdges = static_cast<int>(design.edges.size());
  if (edge < 0 || edge >= numEdges)
    throw std::invalid_argument("edge: no edge " + std::to_string(edge) + " (the composite has " + std::to_string(numEdges) + ")");
  if (design.edges[static_cast<std::size_t>(edge)].type != EdgeType::Spline)
    throw std::invalid_argument("edge: edge " + std::to_string(edge) +
                                " is a ruling (R); a new ruling crosses the curves (S edges) of a strip");
  if (!std::isfinite(at) || at <= 0.0 || at >= 1.0)
    throw std::invalid_argument("at: the cut is a fraction of the edge strictly between 0 and 1");

  CompositeDesign d = design;
  const std::map<int, bool> linked = linkedSplineEdges(topology, edge);
  const spline::KnotVector& space = design.edges[static_cast<std::size_t>(edge)].curve.knots;
  const double u = space.domainBegin() + at * (space.domainEnd() - space.domainBegin());

  // 1. Cut every linked curve: e keeps its first half, its second half becomes a new edge, the
  //    cut point a new vertex. Parameters of the old curves are remembered for the points on them.
  std::map<int, int> secondHalf, cutVertex;  // old edge → new edge, new vertex
  std::map<int, double> cutParameter;        // old edge → u in its own direction
  std::map<int, spline::KnotVector> oldKnots;
  for (const auto& [e, reversed] : linked) {
    const CompositeEdge old = d.edges[static_cast<std::size_t>(e)];
    const double ue = reversed ? old.curve.knots.domainBegin() + old.curve.knots.domainEnd() - u : u;
    const double begin = old.curve.knots.domainBegin(), end = old.curve.knots.domainEnd();
    if (std::abs(ue - begin) <= 1e-9 * (end - begin) || std::abs(end - ue) <= 1e-9 * (end - begin))
      throw std::invalid_argument("at: the cut falls on an end of edge " + std::to_string(e) + " (a vertex already)");
    auto [first, second] = cutCurveAt(old.curve, ue);
    const int p = old.curve.degree();
    if (first.points.rows() < p + 1 || second.points.rows() < p + 1)
      throw std::invalid_argument("at: edge " + std::to_string(e) + " cut there leaves a piece with fewer than " +
                                  std::to_string(p + 1) + " control points");
    const int w = static_cast<int>(d.vertices.rows());
    d.vertices.conservativeResize(w + 1, 3);
    d.vertices.row(w) = first.points.bottomRows(1);
    CompositeEdge a = old, b = old;
    a.v1 = w;
    a.curve = std::move(first);
    b.v0 = w;
    b.curve = std::move(second);
    d.edges[static_cast<std::size_t>(e)] = std::move(a);
    secondHalf[e] = static_cast<int>(d.edges.size());
    cutVertex[e] = w;
    cutParameter[e] = ue;
    oldKnots[e] = old.curve.knots;
    d.edges.push_back(std::move(b));
  }

  // 2. Face loops: the two halves take the old edge's place, in the loop's direction.
  insertSecondHalves(d, design.edges, secondHalf);

  // 3. Every face on a cut curve becomes two: a new ruling from the cut point to the other curve's
  //    cut point (strips) or to the apex (cones). Faces are listed once, in their original order.
  const int numFaces = static_cast<int>(design.faces.size());
  for (int f = 0; f < numFaces; ++f) {
    const FaceInfo& info = topology.face(f);
    if (info.a.edge < 0 || !cutVertex.count(info.a.edge)) continue;
    int from = cutVertex.at(info.a.edge), to = -1;
    if (info.b.edge >= 0) {
      if (!cutVertex.count(info.b.edge)) continue;
      to = cutVertex.at(info.b.edge);
    } else {
      to = info.apex;
    }
    if (to < 0) continue;
    std::vector<int> loop = d.faces[static_cast<std::size_t>(f)];
    const int n = static_cast<int>(loop.size());
    std::vector<int> corner(static_cast<std::size_t>(n));
    for (int k = 0; k < n; ++k)
      corner[static_cast<std::size_t>(k)] = loopCorner(d, loop[static_cast<std::size_t>((k + n - 1) % n)], loop[static_cast<std::size_t>(k)]);
    const auto ia = std::find(corner.begin(), corner.end(), from), ib = std::find(corner.begin(), corner.end(), to);
    if (ia == corner.end() || ib == corner.end())
      throw std::logic_error("faces[" + std::to_string(f) + "]: a cut point is not a corner of its face");
    splitFaceLoop(d, f, static_cast<int>(ia - corner.begin()), static_cast<int>(ib - corner.begin()));
  }

  // 4. What referred to the second part of a cut edge follows it.
  for (FoldAngleTarget& t : d.foldAngles)
    if (t.end == 1 && secondHalf.count(t.edge)) t.edge = secondHalf.at(t.edge);
  for (std::array<int, 2>& pair : d.tangentContinuity) {
    const std::array<int, 2> old = pair;
    for (int side = 0; side < 2; ++side) {
      const auto half = secondHalf.find(old[static_cast<std::size_t>(side)]);
      if (half == secondHalf.end()) continue;
      const CompositeEdge& was = design.edges[static_cast<std::size_t>(half->first)];
      const CompositeEdge& other = design.edges[static_cast<std::size_t>(old[static_cast<std::size_t>(1 - side)])];
      if (other.v0 == was.v1 || other.v1 == was.v1) pair[static_cast<std::size_t>(side)] = half->second;  // they meet at the old v1
    }
  }
  for (const auto& [e, half] : secondHalf)
    if (std::find(d.developmentSeam.begin(), d.developmentSeam.end(), e) != d.developmentSeam.end())
      d.developmentSeam.push_back(half);
  // The two halves of a cut curve stay one smooth curve: cut by knot insertion they meet with one
  // tangent, and the pair keeps it so under later solves (a crease cut across does not get a
  // corner at its new ruling), and the exports write the halves as one crease.
  for (const auto& [e, half] : secondHalf) d.tangentContinuity.push_back({e, half});
  // Control points addressed by index: the nearest control point (by Greville abscissa, in the old
  // curve's parameter) of the half the point lies on; the cut point itself is a vertex of neither.
  const auto follow = [&d, &secondHalf, &cutParameter, &oldKnots](PointRef& r) {
    if (r.isVertex() || !secondHalf.count(r.edge)) return;
    const double g = spline::grevilleAbscissae(oldKnots.at(r.edge))[static_cast<std::size_t>(r.index)];
    const double cut = cutParameter.at(r.edge);
    const spline::KnotVector& old = oldKnots.at(r.edge);
    const bool second = g > cut;
    const int e = second ? secondHalf.at(r.edge) : r.edge;
    // The half's own parameter on [0, 1].
    const double s = second ? (g - cut) / (old.domainEnd() - cut) : (g - old.domainBegin()) / (cut - old.domainBegin());
    const std::vector<double> targets = spline::grevilleAbscissae(d.edges[static_cast<std::size_t>(e)].curve.knots);
    int best = 0;
    for (int j = 1; j < static_cast<int>(targets.size()); ++j)
      if (std::abs(targets[static_cast<std::size_t>(j)] - s) < std::abs(targets[static_cast<std::size_t>(best)] - s)) best = j;
    r.edge = e;
    r.index = std::clamp(best, 1, static_cast<int>(targets.size()) - 2);
  };
  for (PointRef& r : d.fixed) follow(r);
  for (Handle& h : d.handles) follow(h.point);
  d.developmentVertices.resize(0, 2);  // its sampling changed: the development starts from the surface

  try {
    const CompositeTopology check(d);
  } catch (const std::invalid_argument& e) {
    throw std::invalid_argument(std::string("edge: the composite does not take this cut: ") + e.what());
  }
  return d;
}

}  // namespace devsurf::models::composite
