// Curved crease patterns to composites (issue 16 item 1): faces from the planar arrangement,
// rulings proposed between the creases so that every face is a strip S R S R, a strip with one
// ruling shrunk to a point S R S, a cone S R R, or a planar polygon R … R (000_… §3.1).
#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <optional>
#include <set>
#include <stdexcept>
#include <string>
#include <utility>

#include <Eigen/Dense>

#include "devsurf/models/composite/CompositeFromCreasePattern.h"
#include "devsurf/models/composite/CompositeHinges.h"
#include "devsurf/models/composite/CompositeTopology.h"
#include "devsurf/spatial/PlanarArrangement.h"
#include "devsurf/spline/Basis.h"

namespace devsurf::models::composite {

namespace {

constexpr int kChordChain = -2;  ///< chain id of a proposed ruling
/// Control points of every S edge at least, and development samples per span at least: a coarser
/// curved fold cannot meet its fold condition and the sheet's isometry together (4 and 2 leave a
/// 0.1 % strain that a release's projections resolve by unfolding a 90° fold to 45°; 6 and 4 keep
/// 80° of it).
constexpr int kMinControlPoints = 6;
constexpr int kMinDevelopmentSamples = 4;

/// How a side of a face may be labelled.
enum class SideKind {
  Curve,     ///< part of a curved stroke: an S edge
  Crease,    ///< a straight interior edge (crease or proposed ruling): an R edge
  Outline,   ///< a straight piece of the sheet's outline: an R or an S edge, as the face needs
};

struct Side {
  std::vector<int> vertices;  ///< pattern vertices in the face's order, ≥ 2
  std::vector<int> edges;     ///< graph edge ids, vertices.size() − 1 of them
  SideKind kind = SideKind::Outline;
};

/// A ruling layout of a face: two ruling positions (a side, or a vertex where the ruling shrinks to a
/// point), the sides between them forming the two S chains.
struct Layout {
  int first = -1, second = -1;  ///< half-indices: vertex j = 2j, side i = 2i + 1; first < second
  std::vector<int> arcA, arcB;  ///< side indices from first to second, and from second round to first
  double cost = 0.0;
  int corners = 0;              ///< joints inside the two chains (each needs a proposed ruling)
};

struct CurvedGraph {
  const io::CreasePattern& pattern;
  std::vector<std::array<int, 2>> ends;   ///< per graph edge
  std::vector<int> chain;                 ///< curve id ≥ 0, −1 single straight edge, kChordChain
  std::vector<bool> interior;             ///< not on the outline
  std::vector<int> patternEdge;           ///< the pattern's edge, −1 for a proposed ruling
  std::map<std::pair<int, int>, int> idOfPair;
  std::vector<std::vector<int>> incident;  ///< per vertex: graph edges
  std::set<int> curvedChains;

  explicit CurvedGraph(const io::CreasePattern& p) : pattern(p), incident(static_cast<std::size_t>(p.numVertices())) {}

  int addEdge(int a, int b, int chainId, bool inside, int source) {
    const int id = static_cast<int>(ends.size());
    ends.push_back({a, b});
    chain.push_back(chainId);
    interior.push_back(inside);
    patternEdge.push_back(source);
    idOfPair[std::minmax(a, b)] = id;
    incident[static_cast<std::size_t>(a)].push_back(id);
    incident[static_cast<std::size_t>(b)].push_back(id);
    return id;
  }
  int edgeBetween(int a, int b) const {
    const auto it = idOfPair.find(std::minmax(a, b));
    return it == idOfPair.end() ? -1 : it->second;
  }
  /// A vertex where a design edge ends: not the inside of one stroke.
  bool isCorner(int v) const {
    const auto& inc = incident[static_cast<std::size_t>(v)];
    if (inc.size() != 2) return true;
    const int c0 = chain[static_cast<std::size_t>(inc[0])], c1 = chain[static_cast<std::size_t>(inc[1])];
    return c0 < 0 || c1 < 0 || c0 != c1;
  }
  Eigen::Vector2d at(int v) const { return pattern.vertices2d.row(v).transpose(); }
};

/// The sides of a face loop, starting at a corner; empty when the loop has none (one closed curve).
std::vector<Side> sidesOf(const CurvedGraph& g, const std::vector<int>& loop) {
  const std::size_t n = loop.size();
  std::size_t start = n;
  for (std::size_t k = 0; k < n; ++k)
    if (g.isCorner(loop[k])) {
      start = k;
      break;
    }
  if (start == n) return {};
  std::vector<Side> sides;
  Side current;
  current.vertices.push_back(loop[start]);
  for (std::size_t step = 1; step <= n; ++step) {
    const int v = loop[(start + step) % n];
    current.edges.push_back(g.edgeBetween(current.vertices.back(), v));
    current.vertices.push_back(v);
    if (g.isCorner(v)) {
      sides.push_back(std::move(current));
      current = Side{};
      current.vertices.push_back(v);
    }
  }
  for (Side& s : sides) {
    const int e = s.edges.front();
    const int c = g.chain[static_cast<std::size_t>(e)];
    if (c >= 0 && g.curvedChains.count(c)) s.kind = SideKind::Curve;
    else if (g.interior[static_cast<std::size_t>(e)]) s.kind = SideKind::Crease;
    else s.kind = SideKind::Outline;
  }
  return sides;
}

/// The cheapest ruling layout of a face with at least one curved side, or nullopt.
std::optional<Layout> bestLayout(const std::vector<Side>& sides) {
  const int k = static_cast<int>(sides.size());
  std::optional<Layout> best;
  const auto isSide = [](int h) { return h % 2 == 1; };
  for (int p = 0; p < 2 * k; ++p)
    for (int q = p + 1; q < 2 * k; ++q) {
      if (!isSide(p) && !isSide(q)) continue;  // two points: a lens, no ruling at all
      if (isSide(p) && sides[static_cast<std::size_t>(p / 2)].kind == SideKind::Curve) continue;
      if (isSide(q) && sides[static_cast<std::size_t>(q / 2)].kind == SideKind::Curve) continue;
      Layout layout;
      layout.first = p;
      layout.second = q;
      bool valid = true;
      for (int i = 0; i < k && valid; ++i) {
        const int h = 2 * i + 1;
        if (h == p || h == q) continue;
        if (sides[static_cast<std::size_t>(i)].kind == SideKind::Crease) valid = false;  // a crease inside a chain
        (h > p && h < q ? layout.arcA : layout.arcB).push_back(i);
      }
      if (!valid) continue;
      // arcB runs from q round to p: reorder the sides after q first.
      std::stable_partition(layout.arcB.begin(), layout.arcB.end(), [q](int i) { return 2 * i + 1 > q; });
      const bool coneA = layout.arcA.empty(), coneB = layout.arcB.empty();
      if (coneA && coneB) continue;
      if (coneA && !(isSide(p) && isSide(q) && q == p + 2)) continue;
      if (coneB && !(isSide(p) && isSide(q) && p == 1 && q == 2 * k - 1)) continue;
      layout.corners = std::max(0, static_cast<int>(layout.arcA.size()) - 1) + std::max(0, static_cast<int>(layout.arcB.size()) - 1);
      layout.cost = layout.corners + (isSide(p) && isSide(q) ? 0.0 : 0.5) + (coneA || coneB ? 0.25 : 0.0);
      // Between equal layouts, keep a curved side whole between the two rulings (a joint next to it
      // ties its proposed ruling to the crease's end, where the fold gives it no room).
      for (const auto* arc : {&layout.arcA, &layout.arcB})
        for (std::size_t j = 1; j < arc->size(); ++j)
          if (sides[static_cast<std::size_t>((*arc)[j - 1])].kind == SideKind::Curve ||
              sides[static_cast<std::size_t>((*arc)[j])].kind == SideKind::Curve)
            layout.cost += 0.1;
      if (!best || layout.cost < best->cost) best = layout;
    }
  return best;
}

/// Vertices of a chain of sides (joined), and the positions of its joints in it.
struct ChainPolyline {
  std::vector<int> vertices;
  std::vector<std::size_t> joints;  ///< indices into vertices of the corners inside the chain
  std::vector<double> t;            ///< normalized arc length per vertex
};

ChainPolyline chainPolyline(const CurvedGraph& g, const std::vector<Side>& sides, const std::vector<int>& arc,
                            int apexVertex) {
  ChainPolyline c;
  if (arc.empty()) {
    c.vertices = {apexVertex};
  } else {
    for (std::size_t a = 0; a < arc.size(); ++a) {
      const Side& s = sides[static_cast<std::size_t>(arc[a])];
      if (a > 0) c.joints.push_back(c.vertices.size() - 1);
      c.vertices.insert(c.vertices.end(), s.vertices.begin() + (a == 0 ? 0 : 1), s.vertices.end());
    }
  }
  c.t.assign(c.vertices.size(), 0.0);
  double length = 0.0;
  for (std::size_t i = 1; i < c.vertices.size(); ++i) {
    length += (g.at(c.vertices[i]) - g.at(c.vertices[i - 1])).norm();
    c.t[i] = length;
  }
  if (length > 0.0)
    for (double& x : c.t) x /= length;
  return c;
}

double cross2(const Eigen::Vector2d& a, const Eigen::Vector2d& b) { return a.x() * b.y() - a.y() * b.x(); }

bool segmentsTouch(const Eigen::Vector2d& p, const Eigen::Vector2d& q, const Eigen::Vector2d& r, const Eigen::Vector2d& s,
                   double eps) {
  const auto orient = [](const Eigen::Vector2d& a, const Eigen::Vector2d& b, const Eigen::Vector2d& c) {
    return cross2(b - a, c - a);
  };
  const auto distToSegment = [](const Eigen::Vector2d& x, const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
    const Eigen::Vector2d ab = b - a;
    const double len2 = ab.squaredNorm();
    const double t = len2 > 0 ? std::clamp((x - a).dot(ab) / len2, 0.0, 1.0) : 0.0;
    return (a + t * ab - x).norm();
  };
  const double d1 = orient(p, q, r), d2 = orient(p, q, s), d3 = orient(r, s, p), d4 = orient(r, s, q);
  if (((d1 > 0 && d2 < 0) || (d1 < 0 && d2 > 0)) && ((d3 > 0 && d4 < 0) || (d3 < 0 && d4 > 0))) return true;
  return distToSegment(r, p, q) < eps || distToSegment(s, p, q) < eps || distToSegment(p, r, s) < eps ||
         distToSegment(q, r, s) < eps;
}

bool insideLoop(const CurvedGraph& g, const std::vector<int>& loop, const Eigen::Vector2d& x) {
  bool inside = false;
  for (std::size_t k = 0, j = loop.size() - 1; k < loop.size(); j = k++) {
    const Eigen::Vector2d a = g.at(loop[k]), b = g.at(loop[j]);
    if ((a.y() > x.y()) != (b.y() > x.y()) && x.x() < (b.x() - a.x()) * (x.y() - a.y()) / (b.y() - a.y()) + a.x())
      inside = !inside;
  }
  return inside;
}

/// Whether the segment a–b runs inside the face without touching its boundary elsewhere.
bool chordFits(const CurvedGraph& g, const std::vector<int>& loop, int a, int b, double eps) {
  if (a == b || g.edgeBetween(a, b) >= 0) return false;
  const Eigen::Vector2d pa = g.at(a), pb = g.at(b);
  if ((pa - pb).norm() < 10 * eps) return false;
  for (std::size_t k = 0; k < loop.size(); ++k) {
    const int u = loop[k], w = loop[(k + 1) % loop.size()];
    if (u == a || u == b || w == a || w == b) continue;
    if (segmentsTouch(pa, pb, g.at(u), g.at(w), eps)) return false;
  }
  return insideLoop(g, loop, 0.5 * (pa + pb));
}

/// A proposed ruling from a joint of one chain to the other chain, or nullopt.
std::optional<std::pair<int, int>> proposeRuling(const CurvedGraph& g, const std::vector<int>& loop, const ChainPolyline& from,
                                                 const ChainPolyline& to, double eps) {
  for (std::size_t joint : from.joints) {
    const double t = from.t[joint];
    std::vector<std::pair<double, int>> candidates;  // (score, vertex)
    if (to.vertices.size() == 1) {
      candidates.emplace_back(0.0, to.vertices[0]);
    } else {
      for (std::size_t i = 1; i + 1 < to.vertices.size(); ++i) {
        const bool isJoint = std::find(to.joints.begin(), to.joints.end(), i) != to.joints.end();
        const double dt = std::abs(to.t[i] - t);
        candidates.emplace_back(isJoint && dt <= 0.25 ? dt - 1.0 : dt, to.vertices[i]);  // joints first when near
      }
    }
    std::sort(candidates.begin(), candidates.end());
    for (const auto& [score, v] : candidates)
      if (chordFits(g, loop, from.vertices[joint], v, eps)) return std::make_pair(from.vertices[joint], v);
  }
  return std::nullopt;
}

/// The vertices of a stroke in order along it (its pattern edges only, not proposed rulings).
std::vector<int> chainPath(const CurvedGraph& g, int chainId) {
  std::map<int, std::vector<int>> next;
  for (std::size_t e = 0; e < g.ends.size(); ++e)
    if (g.chain[e] == chainId) {
      next[g.ends[e][0]].push_back(g.ends[e][1]);
      next[g.ends[e][1]].push_back(g.ends[e][0]);
    }
  if (next.empty()) return {};
  int start = next.begin()->first;
  for (const auto& [v, ns] : next)
    if (ns.size() == 1) {
      start = v;
      break;
    }
  std::vector<int> path{start};
  std::set<int> seen{start};
  while (true) {
    int step = -1;
    for (int w : next[path.back()])
      if (!seen.count(w)) {
        step = w;
        break;
      }
    if (step < 0) break;
    path.push_back(step);
    seen.insert(step);
  }
  return path;
}

int startVertexOfPosition(const std::vector<Side>& sides, int half, bool endOfIt) {
  const int k = static_cast<int>(sides.size());
  if (half % 2 == 0) return sides[static_cast<std::size_t>((half / 2) % k)].vertices.front();
  const Side& s = sides[static_cast<std::size_t>(half / 2)];
  return endOfIt ? s.vertices.back() : s.vertices.front();
}

/// Least-squares cubic with m ≥ 5 control points through a polyline (chord-length parameters),
/// interpolating its end points with the given unit tangent directions there (so two pieces of one
/// crease meet with one tangent).
spline::BSplineCurve fitCrease(const std::vector<Eigen::Vector2d>& pts, int m, const Eigen::Vector2d& startTangent,
                               const Eigen::Vector2d& endTangent) {
  const int n = static_cast<int>(pts.size());
  std::vector<double> t(static_cast<std::size_t>(n), 0.0);
  for (int i = 1; i < n; ++i) t[i] = t[i - 1] + (pts[i] - pts[i - 1]).norm();
  const double length = t.back();
  for (double& x : t) x = length > 0 ? x / length : 0.0;
  spline::BSplineCurve curve;
  curve.knots = spline::KnotVector::clampedUniform(3, m);
  curve.points = Eigen::MatrixXd::Zero(m, 3);
  const auto alongPolyline = [&pts, &t, n](double s) {
    for (int i = 1; i < n; ++i)
      if (t[i] >= s) {
        const double span = t[i] - t[i - 1];
        const double w = span > 0 ? (s - t[i - 1]) / span : 0.0;
        return Eigen::Vector2d((1 - w) * pts[i - 1] + w * pts[i]);
      }
    return pts.back();
  };
  const Eigen::Vector2d p0 = pts.front(), p1 = pts.back();
  if (n < m + 2) {
    // Few points (a straight piece): control points at the Greville abscissae along the polyline.
    for (int j = 0; j < m; ++j) {
      double g = 0.0;  // (u_{j+1} + u_{j+2} + u_{j+3}) / 3, u_i = clamp((i − 3) / (m − 3), 0, 1)
      for (int i = j + 1; i <= j + 3; ++i) g += std::clamp((i - 3.0) / (m - 3), 0.0, 1.0) / 3.0;
      curve.points.row(j).head<2>() = alongPolyline(g).transpose();
    }
    return curve;
  }
  // Unknowns: a, b (second and second-to-last control points p0 + a t0, p1 − b t1) and the 2D
  // control points 2 … m − 3.
  const Eigen::MatrixXd N(spline::evaluationMatrix(curve.knots, t, 0));
  const int inner = m - 4;
  Eigen::MatrixXd A = Eigen::MatrixXd::Zero(2 * n, 2 + 2 * inner);
  Eigen::VectorXd rhs(2 * n);
  for (int i = 0; i < n; ++i) {
    const Eigen::Vector2d fixedPart = (N(i, 0) + N(i, 1)) * p0 + (N(i, m - 1) + N(i, m - 2)) * p1;
    for (int c = 0; c < 2; ++c) {
      A(2 * i + c, 0) = N(i, 1) * startTangent(c);
      A(2 * i + c, 1) = -N(i, m - 2) * endTangent(c);
      for (int j = 0; j < inner; ++j) A(2 * i + c, 2 + 2 * j + c) = N(i, 2 + j);
      rhs(2 * i + c) = pts[i](c) - fixedPart(c);
    }
  }
  const Eigen::VectorXd x = A.colPivHouseholderQr().solve(rhs);
  const double a = std::max(x(0), 1e-3 * length), b = std::max(x(1), 1e-3 * length);
  curve.points.row(0).head<2>() = p0.transpose();
  curve.points.row(1).head<2>() = (p0 + a * startTangent).transpose();
  for (int j = 0; j < inner; ++j) curve.points.row(2 + j).head<2>() = x.segment<2>(2 + 2 * j).transpose();
  curve.points.row(m - 2).head<2>() = (p1 - b * endTangent).transpose();
  curve.points.row(m - 1).head<2>() = p1.transpose();
  return curve;
}

}  // namespace

bool hasCurvedCreases(const io::CreasePattern& pattern) {
  std::map<int, std::vector<int>> verticesOfChain;
  for (const io::CreaseEdge& e : pattern.edges)
    if (e.curve >= 0) {
      verticesOfChain[e.curve].push_back(e.v0);
      verticesOfChain[e.curve].push_back(e.v1);
    }
  if (verticesOfChain.empty() || pattern.numVertices() == 0) return false;
  const double diagonal = (pattern.vertices2d.colwise().maxCoeff() - pattern.vertices2d.colwise().minCoeff()).norm();
  for (const auto& [id, vs] : verticesOfChain) {
    Eigen::MatrixX2d pts(static_cast<Eigen::Index>(vs.size()), 2);
    for (std::size_t i = 0; i < vs.size(); ++i) pts.row(static_cast<Eigen::Index>(i)) = pattern.vertices2d.row(vs[i]);
    const Eigen::RowVector2d centre = pts.colwise().mean();
    const Eigen::MatrixX2d centred = pts.rowwise() - centre;
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> pca(centred.transpose() * centred);
    if (std::sqrt(std::max(0.0, pca.eigenvalues()(0)) / static_cast<double>(vs.size())) > 1e-6 * diagonal) return true;
  }
  return false;
}

CreasePatternComposite compositeFromCurvedCreasePattern(const io::CreasePattern& pattern, int developmentSamples) {
  pattern.validate();
  if (pattern.faces.empty()) throw std::invalid_argument("crease pattern: no faces");
  if (developmentSamples < 1) throw std::invalid_argument("crease pattern: developmentSamples must be ≥ 1");
  if (pattern.hasFoldedState())
    throw std::invalid_argument("crease pattern: curved creases are read from a flat drawing (no folded state)");
  CreasePatternComposite result;
  const int n = pattern.numVertices();
  const double diagonal = (pattern.vertices2d.colwise().maxCoeff() - pattern.vertices2d.colwise().minCoeff()).norm();
  const double eps = 1e-9 * std::max(diagonal, 1.0);

  // The graph of the edges the faces use; chains that are curved.
  CurvedGraph g(pattern);
  std::map<std::pair<int, int>, int> faceCount;
  for (const auto& f : pattern.faces)
    for (std::size_t k = 0; k < f.size(); ++k) ++faceCount[std::minmax(f[k], f[(k + 1) % f.size()])];
  std::map<int, std::vector<int>> verticesOfChain;
  for (std::size_t e = 0; e < pattern.edges.size(); ++e) {
    const io::CreaseEdge& edge = pattern.edges[e];
    const auto key = std::minmax(edge.v0, edge.v1);
    if (!faceCount.count(key) || g.edgeBetween(edge.v0, edge.v1) >= 0) continue;
    g.addEdge(edge.v0, edge.v1, edge.curve, faceCount[key] == 2, static_cast<int>(e));
    if (edge.curve >= 0) {
      verticesOfChain[edge.curve].push_back(edge.v0);
      verticesOfChain[edge.curve].push_back(edge.v1);
    }
  }
  for (const auto& [key, count] : faceCount)
    if (g.edgeBetween(key.first, key.second) < 0) g.addEdge(key.first, key.second, -1, count == 2, -1);
  for (const auto& [id, vs] : verticesOfChain) {
    Eigen::MatrixX2d pts(static_cast<Eigen::Index>(vs.size()), 2);
    for (std::size_t i = 0; i < vs.size(); ++i) pts.row(static_cast<Eigen::Index>(i)) = pattern.vertices2d.row(vs[i]);
    const Eigen::MatrixX2d centred = pts.rowwise() - pts.colwise().mean();
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> pca(centred.transpose() * centred);
    if (std::sqrt(std::max(0.0, pca.eigenvalues()(0)) / static_cast<double>(vs.size())) > 1e-6 * diagonal)
      g.curvedChains.insert(id);
  }
  for (std::size_t e = 0; e < pattern.edges.size(); ++e)
    if (pattern.edges[e].assignment == io::EdgeAssignment::Cut)
      result.notes.push_back({"edges[" + std::to_string(e) + "]",
                              "a cut (C): the composite has no slits, so its faces stay joined there"});

  std::vector<bool> drawnCorner(static_cast<std::size_t>(n), false);
  for (int v = 0; v < n; ++v) drawnCorner[static_cast<std::size_t>(v)] = !g.incident[static_cast<std::size_t>(v)].empty() && g.isCorner(v);

  // Propose rulings, one at a time, until every face has a layout without joints in its chains.
  std::vector<std::vector<int>> loops = pattern.faces;
  std::vector<int> originOf(loops.size());
  for (std::size_t f = 0; f < loops.size(); ++f) originOf[f] = static_cast<int>(f);
  const auto faceName = [&originOf](std::size_t f) { return "faces[" + std::to_string(originOf[f]) + "]"; };
  const int maxRulings = 64 + 8 * static_cast<int>(pattern.faces.size());
  int proposed = 0;
  const auto splitFace = [&g, &loops, &originOf, &proposed, maxRulings](std::size_t f, int a, int b) {
    if (++proposed > maxRulings)
      throw std::invalid_argument("crease pattern: more than " + std::to_string(maxRulings) +
                                  " rulings proposed without a valid layout; simplify the curved creases");
    g.addEdge(a, b, kChordChain, true, -1);
    const std::vector<int>& loop = loops[f];
    const auto ia = static_cast<std::size_t>(std::find(loop.begin(), loop.end(), a) - loop.begin());
    const auto ib = static_cast<std::size_t>(std::find(loop.begin(), loop.end(), b) - loop.begin());
    std::vector<int> one, two;
    for (std::size_t k = ia;; k = (k + 1) % loop.size()) {
      one.push_back(loop[k]);
      if (k == ib) break;
    }
    for (std::size_t k = ib;; k = (k + 1) % loop.size()) {
      two.push_back(loop[k]);
      if (k == ia) break;
    }
    loops[f] = std::move(one);
    loops.push_back(std::move(two));
    originOf.push_back(originOf[f]);
  };
  // The two chains of a face's layout, side by side from its first ruling to its second.
  const auto chainsOf = [&g](const std::vector<Side>& sides, const Layout& layout) {
    const ChainPolyline a = chainPolyline(g, sides, layout.arcA, startVertexOfPosition(sides, layout.second, false));
    ChainPolyline b = chainPolyline(g, sides, layout.arcB, startVertexOfPosition(sides, layout.first, false));
    std::reverse(b.vertices.begin(), b.vertices.end());  // B runs from the second position round to the first
    for (std::size_t& j : b.joints) j = b.vertices.size() - 1 - j;
    std::reverse(b.t.begin(), b.t.end());
    for (double& x : b.t) x = 1.0 - x;
    return std::make_pair(a, b);
  };
  const auto resolveJoints = [&]() {
    for (bool changed = true; changed;) {
      changed = false;
      for (std::size_t f = 0; f < loops.size() && !changed; ++f) {
        const std::vector<Side> sides = sidesOf(g, loops[f]);
        if (sides.empty())
          throw std::invalid_argument(faceName(f) + ": bounded by one closed curve; a curved face needs two creases or "
                                                    "outline pieces between straight ends");
        const bool curved = std::any_of(sides.begin(), sides.end(), [](const Side& s) { return s.kind == SideKind::Curve; });
        if (!curved) continue;
        const std::optional<Layout> layout = bestLayout(sides);
        if (!layout)
          throw std::invalid_argument(faceName(f) + ": no ruling layout (a face needs straight ends between its curved "
                                                    "sides: S R S R, S R S or S R R)");
        if (layout->corners == 0) continue;
        const auto [a, b] = chainsOf(sides, *layout);
        std::optional<std::pair<int, int>> chord = proposeRuling(g, loops[f], a, b, eps);
        if (!chord) chord = proposeRuling(g, loops[f], b, a, eps);
        if (!chord)
          throw std::invalid_argument(faceName(f) + ": no straight ruling fits inside it from a corner of its curved "
                                                    "sides to the opposite side");
        splitFace(f, chord->first, chord->second);
        changed = true;
      }
    }
  };
  resolveJoints();
  // A fold target only at a curved crease's ends lets the solver meet it by bending the crease
  // sharply there: one more ruling across the middle of every strip beside a folding crease
  // gives it a hinge halfway along too.
  const std::size_t strips = loops.size();
  for (std::size_t f = 0; f < strips; ++f) {
    const std::vector<Side> sides = sidesOf(g, loops[f]);
    const std::optional<Layout> layout = bestLayout(sides);
    if (!layout || layout->arcA.size() != 1 || layout->arcB.size() != 1) continue;
    bool folding = false;
    for (const Side& s : sides)
      if (s.kind == SideKind::Curve) {
        const int source = g.patternEdge[static_cast<std::size_t>(s.edges.front())];
        const auto a = source >= 0 ? pattern.edges[static_cast<std::size_t>(source)].assignment : io::EdgeAssignment::Flat;
        folding = folding || a == io::EdgeAssignment::Mountain || a == io::EdgeAssignment::Valley;
      }
    if (!folding) continue;
    auto [a, b] = chainsOf(sides, *layout);
    if (a.vertices.size() < 3 || b.vertices.size() < 3) continue;
    a.joints = {a.vertices.size() / 2};  // a joint halfway along A, partnered halfway along B
    b.joints.clear();
    if (const auto chord = proposeRuling(g, loops[f], a, b, eps)) splitFace(f, chord->first, chord->second);
  }
  resolveJoints();
  if (proposed > 0)
    result.notes.push_back({"faces", std::to_string(proposed) + " ruling(s) proposed inside the faces so that every face "
                                                                "is a strip, a cone or planar"});

  // The design: corners become vertices, sides become edges.
  CompositeDesign& d = result.design;
  result.designVertexOf.assign(static_cast<std::size_t>(n), -1);
  std::vector<std::vector<Side>> sidesOfFace;
  std::vector<std::optional<Layout>> layoutOfFace;
  for (std::size_t f = 0; f < loops.size(); ++f) {
    sidesOfFace.push_back(sidesOf(g, loops[f]));
    const bool curved = std::any_of(sidesOfFace.back().begin(), sidesOfFace.back().end(),
                                    [](const Side& s) { return s.kind == SideKind::Curve; });
    layoutOfFace.push_back(curved ? bestLayout(sidesOfFace.back()) : std::nullopt);
    for (const Side& s : sidesOfFace.back()) result.designVertexOf[static_cast<std::size_t>(s.vertices.front())] = 0;
  }
  int used = 0;
  for (int v = 0; v < n; ++v)
    if (result.designVertexOf[static_cast<std::size_t>(v)] == 0) result.designVertexOf[static_cast<std::size_t>(v)] = used++;
  d.vertices.resize(used, 3);
  for (int v = 0; v < n; ++v)
    if (const int to = result.designVertexOf[static_cast<std::size_t>(v)]; to >= 0)
      d.vertices.row(to) << pattern.vertices2d(v, 0), pattern.vertices2d(v, 1), 0.0;

  result.designEdgeOf.assign(pattern.edges.size(), -1);
  std::map<std::pair<int, int>, int> designEdgeOfSide;  // (min, max) of the side's end graph edges
  std::vector<std::vector<int>> graphEdgesOfDesignEdge;
  std::vector<std::vector<int>> polylineOfDesignEdge;
  double largestArea = -1.0;
  std::size_t largestFace = 0;
  // One spline space for every S edge (a strip's two curves share theirs, 000_… §3.1): enough
  // control points for the most detailed curve.
  int controlPoints = kMinControlPoints;
  for (const auto& sides : sidesOfFace)
    for (const Side& s : sides)
      if (s.kind == SideKind::Curve) controlPoints = std::max(controlPoints, std::min(8, static_cast<int>(s.vertices.size()) / 3 + 1));
  for (std::size_t f = 0; f < loops.size(); ++f) {
    const std::vector<Side>& sides = sidesOfFace[f];
    const std::optional<Layout>& layout = layoutOfFace[f];
    std::vector<int> face;
    for (std::size_t i = 0; i < sides.size(); ++i) {
      const Side& s = sides[i];
      const auto key = std::minmax(s.edges.front(), s.edges.back());
      if (const auto it = designEdgeOfSide.find(key); it != designEdgeOfSide.end()) {
        face.push_back(it->second);
        continue;
      }
      const int h = 2 * static_cast<int>(i) + 1;
      const bool ruling = s.kind == SideKind::Crease ||
                          (s.kind == SideKind::Outline && (!layout || h == layout->first || h == layout->second));
      CompositeEdge edge;
      edge.v0 = result.designVertexOf[static_cast<std::size_t>(s.vertices.front())];
      edge.v1 = result.designVertexOf[static_cast<std::size_t>(s.vertices.back())];
      edge.type = ruling ? EdgeType::Ruling : EdgeType::Spline;
      const int firstSource = g.patternEdge[static_cast<std::size_t>(s.edges.front())];
      const bool inside = g.interior[static_cast<std::size_t>(s.edges.front())];
      if (!ruling) {
        std::vector<Eigen::Vector2d> pts;
        for (int v : s.vertices) pts.push_back(g.at(v));
        // Tangents: through the vertex's neighbours on its stroke when the stroke goes on (a cut
        // by a proposed ruling), else along the side's first or last piece.
        const auto tangentAt = [&g](int v, int inward, int chainId, bool atStart) {
          Eigen::Vector2d other = g.at(inward);
          for (int ge : g.incident[static_cast<std::size_t>(v)]) {
            if (g.chain[static_cast<std::size_t>(ge)] != chainId) continue;
            const auto& en = g.ends[static_cast<std::size_t>(ge)];
            const int w = en[0] == v ? en[1] : en[0];
            if (w != inward) return Eigen::Vector2d((atStart ? g.at(inward) - g.at(w) : g.at(w) - g.at(inward)).normalized());
          }
          return Eigen::Vector2d((atStart ? other - g.at(v) : g.at(v) - other).normalized());
        };
        const int chainId = g.chain[static_cast<std::size_t>(s.edges.front())];
        edge.curve = fitCrease(pts, controlPoints, tangentAt(s.vertices.front(), s.vertices[1], chainId, true),
                               tangentAt(s.vertices.back(), s.vertices[s.vertices.size() - 2], chainId, false));
        if (inside && firstSource >= 0) {
          const io::EdgeAssignment a = pattern.edges[static_cast<std::size_t>(firstSource)].assignment;
          edge.crease = a == io::EdgeAssignment::Mountain || a == io::EdgeAssignment::Valley ? CreaseKind::Fold
                        : a == io::EdgeAssignment::Flat                                     ? CreaseKind::Smooth
                                                                                             : CreaseKind::None;
        }
      } else if (g.chain[static_cast<std::size_t>(s.edges.front())] == kChordChain) {
        edge.crease = CreaseKind::Smooth;  // a proposed ruling: the paper does not fold there
      }
      const int id = static_cast<int>(d.edges.size());
      d.edges.push_back(std::move(edge));
      designEdgeOfSide[key] = id;
      graphEdgesOfDesignEdge.push_back(s.edges);
      polylineOfDesignEdge.push_back(s.vertices);
      for (int ge : s.edges)
        if (const int source = g.patternEdge[static_cast<std::size_t>(ge)]; source >= 0)
          result.designEdgeOf[static_cast<std::size_t>(source)] = id;
      face.push_back(id);
    }
    const double area = spatial::loopSignedArea2(pattern.vertices2d, loops[f]);
    if (area > largestArea) {
      largestArea = area;
      largestFace = f;
    }
    d.faces.push_back(std::move(face));
  }
  for (const Side& s : sidesOfFace[largestFace])
    d.fixed.push_back(PointRef::ofVertex(result.designVertexOf[static_cast<std::size_t>(s.vertices.front())]));

  // A crease cut into pieces by proposed rulings stays smooth through the cuts.
  for (int v = 0; v < n; ++v) {
    if (result.designVertexOf[static_cast<std::size_t>(v)] < 0) continue;
    std::vector<int> onCurve;
    for (int ge : g.incident[static_cast<std::size_t>(v)]) {
      const int c = g.chain[static_cast<std::size_t>(ge)];
      if (c >= 0 && g.curvedChains.count(c)) onCurve.push_back(ge);
    }
    if (onCurve.size() != 2 || g.chain[static_cast<std::size_t>(onCurve[0])] != g.chain[static_cast<std::size_t>(onCurve[1])])
      continue;
    std::array<int, 2> pair{-1, -1};
    for (std::size_t e = 0; e < graphEdgesOfDesignEdge.size(); ++e)
      for (int k = 0; k < 2; ++k)
        if (std::find(graphEdgesOfDesignEdge[e].begin(), graphEdgesOfDesignEdge[e].end(), onCurve[static_cast<std::size_t>(k)]) !=
            graphEdgesOfDesignEdge[e].end())
          pair[static_cast<std::size_t>(k)] = static_cast<int>(e);
    if (pair[0] >= 0 && pair[1] >= 0 && pair[0] != pair[1] && d.edges[static_cast<std::size_t>(pair[0])].type == EdgeType::Spline &&
        d.edges[static_cast<std::size_t>(pair[1])].type == EdgeType::Spline)
      d.tangentContinuity.push_back(pair);
  }

  // The development is the drawing: its own corners pinned (outline corners, stroke ends and
  // meetings), every curved side kept on its curve. The ends of proposed rulings are not pinned:
  // they slide along their stroke, so a ruling can turn as the fold needs (pinned, a proposed
  // ruling that no folded state has would hold the sheet flat).
  d.developmentSamples = std::max(developmentSamples, kMinDevelopmentSamples);
  for (int v = 0; v < n; ++v)
    if (const int to = result.designVertexOf[static_cast<std::size_t>(v)]; to >= 0 && drawnCorner[static_cast<std::size_t>(v)])
      d.developmentDomain.corners.push_back({to, pattern.vertices2d.row(v).transpose()});
  std::set<int> chainsOnDomain;
  for (std::size_t e = 0; e < d.edges.size(); ++e) {
    const int firstGraphEdge = graphEdgesOfDesignEdge[e].front();
    const bool inside = g.interior[static_cast<std::size_t>(firstGraphEdge)];
    if (d.edges[e].type != EdgeType::Spline) {
      // A straight piece of the outline: its samples stay on it (a boundary edge's samples go
      // to the nearest domain curve, which must be its own).
      if (inside) continue;
      DomainCurve line;
      line.points.resize(2, 2);
      line.points.row(0) = pattern.vertices2d.row(polylineOfDesignEdge[e].front());
      line.points.row(1) = pattern.vertices2d.row(polylineOfDesignEdge[e].back());
      d.developmentDomain.boundary.push_back(std::move(line));
      continue;
    }
    if (inside) {
      // A drawn crease: its whole stroke, once, as the fitted splines of its pieces end to end
      // (so that the sheet starts isometric to its development; the model holds it softly).
      const int chainId = g.chain[static_cast<std::size_t>(firstGraphEdge)];
      if (!chainsOnDomain.insert(chainId).second) continue;
      const std::vector<int> path = chainPath(g, chainId);
      std::map<int, int> positionOnPath;
      for (std::size_t i = 0; i < path.size(); ++i) positionOnPath[path[i]] = static_cast<int>(i);
      std::vector<std::pair<int, std::size_t>> pieces;  // (position of the piece's lower end, edge)
      for (std::size_t o = 0; o < d.edges.size(); ++o) {
        if (d.edges[o].type != EdgeType::Spline) continue;
        if (g.chain[static_cast<std::size_t>(graphEdgesOfDesignEdge[o].front())] != chainId) continue;
        const int a = positionOnPath[polylineOfDesignEdge[o].front()], b = positionOnPath[polylineOfDesignEdge[o].back()];
        pieces.emplace_back(std::min(a, b), o);
      }
      std::sort(pieces.begin(), pieces.end());
      constexpr int kPiecePoints = 64;
      std::vector<Eigen::Vector2d> pts;
      for (const auto& [lower, o] : pieces) {
        const bool forward = positionOnPath[polylineOfDesignEdge[o].front()] == lower;
        for (int i = pts.empty() ? 0 : 1; i <= kPiecePoints; ++i) {
          const double u = static_cast<double>(forward ? i : kPiecePoints - i) / kPiecePoints;
          pts.push_back(d.edges[o].curve.evaluate(u).head<2>());
        }
      }
      DomainCurve curve;
      curve.points.resize(static_cast<Eigen::Index>(pts.size()), 2);
      for (std::size_t i = 0; i < pts.size(); ++i) curve.points.row(static_cast<Eigen::Index>(i)) = pts[i].transpose();
      d.developmentDomain.boundary.push_back(std::move(curve));
      continue;
    }
    // A curved piece of the outline: the fitted spline itself (256 points), so that the sheet
    // starts isometric to its development (the outline is held hard).
    DomainCurve curve;
    const spline::BSplineCurve& fitted = d.edges[e].curve;
    constexpr int kDomainPoints = 256;
    curve.points.resize(kDomainPoints + 1, 2);
    for (int i = 0; i <= kDomainPoints; ++i)
      curve.points.row(i) = fitted.evaluate(static_cast<double>(i) / kDomainPoints).head<2>().transpose();
    d.developmentDomain.boundary.push_back(std::move(curve));
  }

  // Fold-angle targets: every hinge of a crease with an angle (flat mountain and valley creases
  // without one aim at a full fold, as Origami Simulator reads them).
  const CompositeTopology topology(d);
  bool guessed = false;
  for (std::size_t e = 0; e < d.edges.size(); ++e) {
    const int source = g.patternEdge[static_cast<std::size_t>(graphEdgesOfDesignEdge[e].front())];
    if (source < 0) continue;
    const io::CreaseEdge& pe = pattern.edges[static_cast<std::size_t>(source)];
    std::optional<double> angle = pe.foldAngle;
    if (!angle && (pe.assignment == io::EdgeAssignment::Mountain || pe.assignment == io::EdgeAssignment::Valley)) {
      angle = pe.assignment == io::EdgeAssignment::Mountain ? -180.0 : 180.0;
      guessed = true;
    }
    if (!angle || *angle == 0.0) continue;
    // A curved crease folds in a one-parameter family: its fold angle varies along it as its
    // curvature does, so it gets one target, at a hinge inside it (a proposed ruling's end) when
    // it has one — targets at its ends too ask for one angle at three places, which the sheet meets
    // only by stretching (15 % locally, measured) — else at its ends.
    const int chainId = g.chain[static_cast<std::size_t>(graphEdgesOfDesignEdge[e].front())];
    const auto insideStroke = [&g, chainId](int v) {
      int along = 0;
      for (int ge : g.incident[static_cast<std::size_t>(v)]) along += g.chain[static_cast<std::size_t>(ge)] == chainId ? 1 : 0;
      return along == 2;
    };
    const bool curved = d.edges[e].type == EdgeType::Spline;
    bool strokeHasInnerHinge = false;
    if (curved && chainId >= 0)
      for (std::size_t o = 0; o < d.edges.size() && !strokeHasInnerHinge; ++o)
        if (g.chain[static_cast<std::size_t>(graphEdgesOfDesignEdge[o].front())] == chainId && d.edges[o].type == EdgeType::Spline)
          for (int v : {polylineOfDesignEdge[o].front(), polylineOfDesignEdge[o].back()})
            strokeHasInnerHinge = strokeHasInnerHinge || insideStroke(v);
    for (int end : {0, 1}) {
      if (!curved && end == 1) break;
      if (!hasFoldHinge(topology, static_cast<int>(e), end)) continue;
      const int v = end == 0 ? polylineOfDesignEdge[e].front() : polylineOfDesignEdge[e].back();
      if (curved && strokeHasInnerHinge && !insideStroke(v)) continue;
      d.foldAngles.push_back({static_cast<int>(e), end, *angle});
    }
  }
  if (guessed)
    result.notes.push_back({"edges_foldAngle", "not given for every crease: mountain and valley creases without one aim "
                                               "at a full fold (∓180°)"});
  d.foldAmount = d.foldAngles.empty() ? 1.0 : 0.0;
  return result;
}

}  // namespace devsurf::models::composite
