#include "devsurf/models/composite/CompositeFromStrips.h"

#include <array>
#include <utility>
#include "devsurf/models/composite/CompositeModel.h"
#include "devsurf/spline/Basis.h"

#include <Eigen/QR>

#include <algorithm>
#include <cmath>
#include <numeric>
#include <queue>
#include <stdexcept>
#include <string>

namespace devsurf::models::composite {

namespace {

using strip::BoundaryPairing;
using strip::Curve;
using strip::StripDesign;

spline::BSplineCurve& curveOf(StripDesign& s, Curve c) { return c == Curve::A ? s.a : s.b; }
Curve other(Curve c) { return c == Curve::A ? Curve::B : Curve::A; }

/// The knots of a clamped curve read from its end: t ↦ begin + end − t.
std::vector<double> stripReversedKnots(const spline::KnotVector& k) {
  const std::vector<double>& t = k.knots();
  std::vector<double> r(t.size());
  for (std::size_t i = 0; i < t.size(); ++i) r[i] = k.domainBegin() + k.domainEnd() - t[t.size() - 1 - i];
  return r;
}

bool sameKnots(const std::vector<double>& x, const std::vector<double>& y) {
  if (x.size() != y.size()) return false;
  for (std::size_t i = 0; i < x.size(); ++i)
    if (std::abs(x[i] - y[i]) > 1e-9 * std::max(1.0, std::abs(x.back() - x.front()))) return false;
  return true;
}

/// Parameters equally spaced over the curve's domain.
std::vector<double> uniformParameters(const spline::KnotVector& k, int count) {
  std::vector<double> u(static_cast<std::size_t>(count));
  for (int i = 0; i < count; ++i)
    u[static_cast<std::size_t>(i)] = k.domainBegin() + (k.domainEnd() - k.domainBegin()) * i / (count - 1);
  return u;
}

/// Parameter of the point closest to p of a curve given by dense samples at parameters u: the
/// nearest sample, refined on the segment to either neighbour.
double closestParameter(const std::vector<double>& u, const Eigen::MatrixXd& samples,
                        const Eigen::Vector3d& p) {
  Eigen::Index best = 0;
  (samples.rowwise() - p.transpose()).rowwise().squaredNorm().minCoeff(&best);
  double bestU = u[static_cast<std::size_t>(best)], bestD = (samples.row(best).transpose() - p).squaredNorm();
  for (const Eigen::Index other : {best - 1, best + 1}) {
    if (other < 0 || other >= samples.rows()) continue;
    const Eigen::Vector3d a = samples.row(best).transpose(), d = samples.row(other).transpose() - a;
    const double t = std::clamp((p - a).dot(d) / std::max(d.squaredNorm(), 1e-300), 0.0, 1.0);
    const double dist = (a + t * d - p).squaredNorm();
    if (dist < bestD) {
      bestD = dist;
      bestU = u[static_cast<std::size_t>(best)] + t * (u[static_cast<std::size_t>(other)] - u[static_cast<std::size_t>(best)]);
    }
  }
  return bestU;
}

/// Least-squares fit of a curve with `knots` through points q_k at parameters t_k, the end
/// control points at the first and last point (a clamped curve interpolates them).
Eigen::MatrixXd fitWithEnds(const spline::KnotVector& knots, const std::vector<double>& t, const Eigen::MatrixXd& q) {
  const int n = knots.numControlPoints();
  const Eigen::MatrixXd N = Eigen::MatrixXd(spline::evaluationMatrix(knots, t, 0));
  Eigen::MatrixXd P(n, 3);
  P.row(0) = q.row(0);
  P.row(n - 1) = q.row(q.rows() - 1);
  const Eigen::MatrixXd rhs = q - N.col(0) * P.row(0) - N.col(n - 1) * P.row(n - 1);
  P.middleRows(1, n - 2) = N.middleCols(1, n - 2).colPivHouseholderQr().solve(rhs);
  return P;
}

/// Strip s with its curve `c` replaced by `shared` (same knots, in s's direction of c) and its
/// other curve refitted so that every ruling keeps its ends: the ruling through shared(u) is s's
/// ruling through the point of its old curve c closest to shared(u). Strips fitted separately
/// parametrize a common boundary differently; averaging control points would shear the rulings
/// (warp 3° on a sphere cap where the strips had 0.002°).
void adoptSharedCurve(StripDesign& s, Curve c, const Eigen::MatrixXd& shared) {
  spline::BSplineCurve& own = curveOf(s, c);
  spline::BSplineCurve& opposite = curveOf(s, other(c));
  constexpr int kDense = 1024, kFit = 96;
  const std::vector<double> dense = uniformParameters(own.knots, kDense);
  const Eigen::MatrixXd ownSamples = own.evaluate(dense, 0);
  spline::BSplineCurve target = own;
  target.points = shared;
  const std::vector<double> t = uniformParameters(own.knots, kFit);
  const Eigen::MatrixXd onShared = target.evaluate(t, 0);
  Eigen::MatrixXd q(kFit, 3);
  for (int k = 0; k < kFit; ++k)
    q.row(k) = opposite.evaluate(closestParameter(dense, ownSamples, onShared.row(k).transpose()), 0).transpose();
  opposite.points = fitWithEnds(opposite.knots, t, q);
  own.points = shared;
}

/// Walks the pairings breadth first from every strip not reached yet, in order:
/// visit(from, to, k, reached) for each pairing k of a strip `from` taken from the queue, `to` its
/// partner and `reached` whether `to` was reached before; a strip first reached is queued.
template <class Visit>
void breadthFirst(int count, const std::vector<BoundaryPairing>& pairings, Visit visit) {
  std::vector<char> reached(static_cast<std::size_t>(count), 0);
  for (int start = 0; start < count; ++start) {
    if (reached[static_cast<std::size_t>(start)]) continue;
    reached[static_cast<std::size_t>(start)] = 1;
    std::queue<int> open;
    open.push(start);
    while (!open.empty()) {
      const int from = open.front();
      open.pop();
      for (std::size_t k = 0; k < pairings.size(); ++k) {
        const BoundaryPairing& p = pairings[k];
        if (p.first != from && p.second != from) continue;
        const int to = p.first == from ? p.second : p.first;
        const bool before = reached[static_cast<std::size_t>(to)];
        visit(from, to, k, before);
        if (!before) {
          reached[static_cast<std::size_t>(to)] = 1;
          open.push(to);
        }
      }
    }
  }
}

/// Union–find over the strips' corners (strip, curve, end) = 4·strip + 2·curve + end.
struct Corners {
  std::vector<int> parent;
  explicit Corners(std::size_t strips) : parent(4 * strips) { std::iota(parent.begin(), parent.end(), 0); }
  static int id(int stripIndex, Curve c, int end) { return 4 * stripIndex + 2 * static_cast<int>(c) + end; }
  int find(int x) { return parent[static_cast<std::size_t>(x)] == x ? x : parent[static_cast<std::size_t>(x)] = find(parent[static_cast<std::size_t>(x)]); }
  void join(int x, int y) { parent[static_cast<std::size_t>(find(x))] = find(y); }
};

}  // namespace

CompositeDesign compositeFromStrips(std::vector<StripDesign> strips, const std::vector<BoundaryPairing>& pairingsIn,
                                    CreaseKind crease) {
  const int count = static_cast<int>(strips.size());
  if (count == 0) throw std::invalid_argument("strips: none");
  for (int i = 0; i < count; ++i) {
    const StripDesign& s = strips[static_cast<std::size_t>(i)];
    if (s.a.knots.kind() != spline::KnotKind::Clamped || s.a.isRational() || s.b.isRational())
      throw std::invalid_argument("strips[" + std::to_string(i) + "]: a composite face needs open, polynomial curves");
  }
  std::vector<BoundaryPairing> pairings = pairingsIn;
  std::vector<std::array<int, 2>> pairedAs(static_cast<std::size_t>(count), {-1, -1});
  for (std::size_t k = 0; k < pairings.size(); ++k) {
    const BoundaryPairing& p = pairings[k];
    const std::string path = "pairings[" + std::to_string(k) + "]";
    if (p.first < 0 || p.first >= count || p.second < 0 || p.second >= count || p.first == p.second)
      throw std::invalid_argument(path + ": expected two different strips of " + std::to_string(count));
    for (const auto& [s, c] : {std::pair{p.first, p.firstCurve}, std::pair{p.second, p.secondCurve}}) {
      int& slot = pairedAs[static_cast<std::size_t>(s)][static_cast<std::size_t>(c)];
      if (slot >= 0)
        throw std::invalid_argument(path + ": curve " + strip::curveName(c) + " of strip " + std::to_string(s) +
                                    " is already paired");
      slot = static_cast<int>(k);
    }
  }

  // Orientation: a face runs a forwards and b backwards, so a shared edge runs opposite ways in its
  // two faces iff (the curves differ) ≠ (they are reversed). Exchanging a strip's a and b turns it.
  std::vector<int> flip(static_cast<std::size_t>(count), 0);
  breadthFirst(count, pairings, [&pairings, &flip](int i, int j, std::size_t k, bool reached) {
    // Consistent when (c_i ⊕ f_i) ⊕ (c_j ⊕ f_j) ⊕ reversed = 1, c the paired curve, f the flip.
    const BoundaryPairing& p = pairings[k];
    const bool iFirst = p.first == i;
    const int ci = static_cast<int>(iFirst ? p.firstCurve : p.secondCurve);
    const int cj = static_cast<int>(iFirst ? p.secondCurve : p.firstCurve);
    const int fj = cj ^ ci ^ flip[static_cast<std::size_t>(i)] ^ 1 ^ (p.reversed ? 1 : 0);
    if (!reached) flip[static_cast<std::size_t>(j)] = fj;
    else if (flip[static_cast<std::size_t>(j)] != fj)
      throw std::invalid_argument("pairings: the strips cannot all be oriented alike (a Möbius band)");
  });
  for (int i = 0; i < count; ++i)
    if (flip[static_cast<std::size_t>(i)] == 1) std::swap(strips[static_cast<std::size_t>(i)].a, strips[static_cast<std::size_t>(i)].b);
  for (BoundaryPairing& p : pairings) {
    if (flip[static_cast<std::size_t>(p.first)] == 1) p.firstCurve = other(p.firstCurve);
    if (flip[static_cast<std::size_t>(p.second)] == 1) p.secondCurve = other(p.secondCurve);
  }
  std::vector<std::array<int, 2>> pairing(static_cast<std::size_t>(count), {-1, -1});
  for (std::size_t k = 0; k < pairings.size(); ++k) {
    pairing[static_cast<std::size_t>(pairings[k].first)][static_cast<std::size_t>(pairings[k].firstCurve)] = static_cast<int>(k);
    pairing[static_cast<std::size_t>(pairings[k].second)][static_cast<std::size_t>(pairings[k].secondCurve)] = static_cast<int>(k);
  }

  // Rulings kept: in breadth-first order from each strip not yet reached, a strip reached through
  // a pairing takes its partner's curve exactly and refits its other curve (adoptSharedCurve).
  // A pairing that closes a ring finds both curves placed: there the control points are averaged.
  breadthFirst(count, pairings, [&pairings, &strips](int i, int j, std::size_t k, bool reached) {
    if (reached) return;
    const BoundaryPairing& p = pairings[k];
    const Curve ci = p.first == i ? p.firstCurve : p.secondCurve, cj = p.first == i ? p.secondCurve : p.firstCurve;
    const spline::BSplineCurve& from = curveOf(strips[static_cast<std::size_t>(i)], ci);
    const spline::BSplineCurve& to = curveOf(strips[static_cast<std::size_t>(j)], cj);
    const std::vector<double> fromKnots = p.reversed ? stripReversedKnots(from.knots) : from.knots.knots();
    if (!sameKnots(to.knots.knots(), fromKnots) || to.points.rows() != from.points.rows())
      throw std::invalid_argument("pairings[" + std::to_string(k) + "]: the paired curves differ in knots");
    adoptSharedCurve(strips[static_cast<std::size_t>(j)], cj,
                     p.reversed ? Eigen::MatrixXd(from.points.colwise().reverse()) : from.points);
  });

  // Vertices: corners joined along the pairings, at their mean.
  Corners corners(static_cast<std::size_t>(count));
  for (const BoundaryPairing& p : pairings)
    for (int end = 0; end < 2; ++end)
      corners.join(Corners::id(p.first, p.firstCurve, end), Corners::id(p.second, p.secondCurve, p.reversed ? 1 - end : end));
  std::vector<int> vertexOf(4 * static_cast<std::size_t>(count), -1);
  std::vector<Eigen::Vector3d> sum;
  std::vector<int> members;
  for (int i = 0; i < count; ++i)
    for (const Curve c : {Curve::A, Curve::B})
      for (int end = 0; end < 2; ++end) {
        const int root = corners.find(Corners::id(i, c, end));
        int& v = vertexOf[static_cast<std::size_t>(root)];
        if (v < 0) {
          v = static_cast<int>(sum.size());
          sum.emplace_back(Eigen::Vector3d::Zero());
          members.push_back(0);
        }
        const spline::BSplineCurve& curve = curveOf(strips[static_cast<std::size_t>(i)], c);
        sum[static_cast<std::size_t>(v)] += curve.points.row(end == 0 ? 0 : curve.points.rows() - 1).transpose();
        ++members[static_cast<std::size_t>(v)];
      }
  auto vertex = [&vertexOf, &corners](int i, Curve c, int end) {
    return vertexOf[static_cast<std::size_t>(corners.find(Corners::id(i, c, end)))];
  };
  CompositeDesign design;
  design.vertices.resize(static_cast<Eigen::Index>(sum.size()), 3);
  for (std::size_t v = 0; v < sum.size(); ++v)
    design.vertices.row(static_cast<Eigen::Index>(v)) = (sum[v] / members[v]).transpose();

  // S edges: one per curve, a paired curve's edge made by the first strip of its pairing.
  std::vector<std::array<int, 2>> edgeOf(static_cast<std::size_t>(count), {-1, -1});
  for (int i = 0; i < count; ++i)
    for (const Curve c : {Curve::A, Curve::B}) {
      const int k = pairing[static_cast<std::size_t>(i)][static_cast<std::size_t>(c)];
      if (k >= 0 && pairings[static_cast<std::size_t>(k)].second == i) continue;  // made by the first
      spline::BSplineCurve curve = curveOf(strips[static_cast<std::size_t>(i)], c);
      CompositeEdge edge;
      edge.v0 = vertex(i, c, 0);
      edge.v1 = vertex(i, c, 1);
      if (edge.v0 == edge.v1)
        throw std::invalid_argument("strips[" + std::to_string(i) + "]: curve " + strip::curveName(c) +
                                    " begins and ends at one corner");
      edge.type = EdgeType::Spline;
      if (k >= 0) {
        const BoundaryPairing& p = pairings[static_cast<std::size_t>(k)];
        spline::BSplineCurve partner = curveOf(strips[static_cast<std::size_t>(p.second)], p.secondCurve);
        const std::vector<double> partnerKnots = p.reversed ? stripReversedKnots(partner.knots) : partner.knots.knots();
        if (!sameKnots(curve.knots.knots(), partnerKnots) || partner.points.rows() != curve.points.rows())
          throw std::invalid_argument("pairings[" + std::to_string(k) + "]: the paired curves differ in knots");
        const Eigen::MatrixXd q = p.reversed ? Eigen::MatrixXd(partner.points.colwise().reverse()) : partner.points;
        curve.points = 0.5 * (curve.points + q);
        edge.crease = crease;
      }
      curve.points.row(0) = design.vertices.row(edge.v0);
      curve.points.row(curve.points.rows() - 1) = design.vertices.row(edge.v1);
      edge.curve = std::move(curve);
      const int id = static_cast<int>(design.edges.size());
      design.edges.push_back(std::move(edge));
      edgeOf[static_cast<std::size_t>(i)][static_cast<std::size_t>(c)] = id;
      if (k >= 0) {
        const BoundaryPairing& p = pairings[static_cast<std::size_t>(k)];
        edgeOf[static_cast<std::size_t>(p.second)][static_cast<std::size_t>(p.secondCurve)] = id;
      }
    }
  // R edges (the end rulings) and the faces a (0→1), ruling at 1, b (1→0), ruling at 0.
  for (int i = 0; i < count; ++i) {
    std::array<int, 2> rulings{};
    for (int end = 0; end < 2; ++end) {
      CompositeEdge ruling;
      ruling.v0 = vertex(i, Curve::A, end);
      ruling.v1 = vertex(i, Curve::B, end);
      if (ruling.v0 == ruling.v1)
        throw std::invalid_argument("strips[" + std::to_string(i) + "]: its ruling at the " +
                                    (end == 0 ? "start" : "end") + " has length zero after pairing");
      rulings[static_cast<std::size_t>(end)] = static_cast<int>(design.edges.size());
      design.edges.push_back(std::move(ruling));
    }
    design.faces.push_back({edgeOf[static_cast<std::size_t>(i)][0], rulings[1], edgeOf[static_cast<std::size_t>(i)][1],
                            rulings[0]});
  }
  CompositeModel::validateDesign(design);
  return design;
}

CompositeDesign disjointUnion(const std::vector<CompositeDesign>& parts) {
  if (parts.empty()) throw std::invalid_argument("disjointUnion: no parts");
  CompositeDesign out;
  Eigen::Index vertexCount = 0;
  for (const CompositeDesign& part : parts) vertexCount += part.vertices.rows();
  out.vertices.resize(vertexCount, 3);
  int vertexOffset = 0, edgeOffset = 0;
  for (std::size_t k = 0; k < parts.size(); ++k) {
    const CompositeDesign& part = parts[k];
    if (part.developmentSamples > 0 || !part.developmentDomain.empty() || !part.developmentSeam.empty() ||
        part.developmentVertices.rows() > 0 || !part.foldAngles.empty() || part.foldAmount != 1.0 ||
        !part.drawing.empty())
      throw std::invalid_argument("parts[" + std::to_string(k) +
                                  "]: a development, fold angles or a drawing describe one sheet; the union has several");
    const auto moved = [vertexOffset, edgeOffset](PointRef p) {
      if (p.isVertex()) p.vertex += vertexOffset;
      else p.edge += edgeOffset;
      return p;
    };
    out.vertices.middleRows(vertexOffset, part.vertices.rows()) = part.vertices;
    for (CompositeEdge edge : part.edges) {
      edge.v0 += vertexOffset;
      edge.v1 += vertexOffset;
      out.edges.push_back(std::move(edge));
    }
    for (std::vector<int> face : part.faces) {
      for (int& e : face) e += edgeOffset;
      out.faces.push_back(std::move(face));
    }
    for (const PointRef& p : part.fixed) out.fixed.push_back(moved(p));
    for (Handle h : part.handles) {
      h.point = moved(h.point);
      out.handles.push_back(h);
    }
    for (const auto& [e0, e1] : part.tangentContinuity) out.tangentContinuity.push_back({e0 + edgeOffset, e1 + edgeOffset});
    vertexOffset += static_cast<int>(part.vertices.rows());
    edgeOffset += static_cast<int>(part.edges.size());
  }
  CompositeModel::validateDesign(out);
  return out;
}

}  // namespace devsurf::models::composite
