#include "devsurf/models/composite/CurvedCreaseLayout.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include <Eigen/Dense>

#include "devsurf/spatial/PlanarArrangement.h"
#include "devsurf/spline/Basis.h"

namespace devsurf::models::composite::curved {

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

namespace {

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

}  // namespace

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
  return spatial::pointInLoop(g.pattern.vertices2d, loop, 0.5 * (pa + pb));
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

bool rulingsCross(const CurvedGraph& g, const ChainPolyline& a, const ChainPolyline& b) {
  const auto pointAt = [&g](const ChainPolyline& c, double t) {
    if (c.vertices.size() == 1) return g.at(c.vertices[0]);
    const auto it = std::upper_bound(c.t.begin(), c.t.end(), t);
    const std::size_t i = std::min<std::size_t>(static_cast<std::size_t>(std::max<std::ptrdiff_t>(it - c.t.begin(), 1)), c.t.size() - 1);
    const double span = c.t[i] - c.t[i - 1];
    const double w = span > 0.0 ? std::clamp((t - c.t[i - 1]) / span, 0.0, 1.0) : 0.0;
    return Eigen::Vector2d((1.0 - w) * g.at(c.vertices[i - 1]) + w * g.at(c.vertices[i]));
  };
  constexpr int kRulings = 64;
  double size = 0.0;
  for (const ChainPolyline* c : {&a, &b})
    for (int v : c->vertices) size = std::max(size, (g.at(v) - g.at(a.vertices.front())).norm());
  const double tiny = 1e-9 * std::max(size, 1e-300);
  // Two neighbouring rulings cross when each one's ends lie strictly on both sides of the other.
  const auto side = [tiny](const Eigen::Vector2d& p, const Eigen::Vector2d& q, const Eigen::Vector2d& x) {
    const double d = cross2(q - p, x - p) / std::max((q - p).norm(), 1e-300);
    return d > tiny ? 1 : d < -tiny ? -1 : 0;
  };
  for (int k = 0; k < kRulings; ++k) {
    const double t0 = static_cast<double>(k) / kRulings, t1 = static_cast<double>(k + 1) / kRulings;
    const Eigen::Vector2d a0 = pointAt(a, t0), a1 = pointAt(a, t1), b0 = pointAt(b, t0), b1 = pointAt(b, t1);
    if ((a0 - b0).norm() <= tiny || (a1 - b1).norm() <= tiny) continue;  // a ruling shrunk to a point
    if (side(a0, b0, a1) * side(a0, b0, b1) < 0 && side(a1, b1, a0) * side(a1, b1, b0) < 0) return true;
  }
  return false;
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

}  // namespace devsurf::models::composite::curved
