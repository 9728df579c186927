#include "devsurf/io/CreasePattern.h"

#include <cmath>
#include <deque>
#include <map>
#include <set>
#include <stdexcept>
#include <utility>

#include <Eigen/Geometry>

namespace devsurf::io {
namespace {

constexpr double kCreasePatternPi = 3.14159265358979323846;

[[noreturn]] void failPattern(const std::string& what) {
  throw std::invalid_argument("CreasePattern: " + what);
}

std::string edgeName(std::size_t e) { return "edge " + std::to_string(e); }

/// Newell normal of a vertex loop (not normalised).
Eigen::Vector3d newellNormal(const Eigen::MatrixX3d& v, const std::vector<int>& loop) {
  Eigen::Vector3d n = Eigen::Vector3d::Zero();
  for (std::size_t k = 0; k < loop.size(); ++k) {
    const Eigen::Vector3d a = v.row(loop[k]).transpose();
    const Eigen::Vector3d b = v.row(loop[(k + 1) % loop.size()]).transpose();
    n += 0.5 * a.cross(b);
  }
  return n;
}

double signedArea2d(const Eigen::MatrixX2d& v, const std::vector<int>& loop) {
  double a = 0.0;
  for (std::size_t k = 0; k < loop.size(); ++k) {
    const int i = loop[k], j = loop[(k + 1) % loop.size()];
    a += v(i, 0) * v(j, 1) - v(j, 0) * v(i, 1);
  }
  return 0.5 * a;
}

}  // namespace

void CreasePattern::validate() const {
  const Eigen::Index n = vertices2d.rows();
  if (!vertices2d.allFinite()) failPattern("vertices2d has a non-finite coordinate");
  if (vertices3d.rows() != 0 && vertices3d.rows() != n)
    failPattern("vertices3d has " + std::to_string(vertices3d.rows()) + " rows, expected 0 or " +
         std::to_string(n));
  if (!vertices3d.allFinite()) failPattern("vertices3d has a non-finite coordinate");
  if (!(unitToMm > 0.0) || !std::isfinite(unitToMm)) failPattern("unitToMm must be finite and > 0");

  for (std::size_t e = 0; e < edges.size(); ++e) {
    const CreaseEdge& ed = edges[e];
    if (ed.v0 < 0 || ed.v0 >= n || ed.v1 < 0 || ed.v1 >= n)
      failPattern(edgeName(e) + " has a vertex index out of range");
    if (ed.v0 == ed.v1) failPattern(edgeName(e) + " joins a vertex to itself");
    if (ed.curve < -1) failPattern(edgeName(e) + " has a curve id below -1");
    if (ed.foldAngle) {
      const double a = *ed.foldAngle;
      if (!std::isfinite(a) || a < -180.0 || a > 180.0)
        failPattern(edgeName(e) + " has a fold angle outside [-180, 180]");
      switch (ed.assignment) {
        case EdgeAssignment::Mountain:
          if (a > 0.0) failPattern(edgeName(e) + " is a mountain fold with a positive (valley) angle");
          break;
        case EdgeAssignment::Valley:
          if (a < 0.0) failPattern(edgeName(e) + " is a valley fold with a negative (mountain) angle");
          break;
        default:
          if (a != 0.0)
            failPattern(edgeName(e) + " is a " + assignmentName(ed.assignment) +
                 " edge with a non-zero fold angle");
      }
    }
  }

  for (std::size_t f = 0; f < faces.size(); ++f) {
    const auto& loop = faces[f];
    if (loop.size() < 3) failPattern("face " + std::to_string(f) + " has fewer than 3 vertices");
    for (int v : loop)
      if (v < 0 || v >= n) failPattern("face " + std::to_string(f) + " has a vertex index out of range");
    if (!(signedArea2d(vertices2d, loop) > 0.0))
      failPattern("face " + std::to_string(f) + " is not counter-clockwise in the development");
  }

  if (!rulings.allFinite()) failPattern("rulings has a non-finite coordinate");

  std::set<int> ids;
  for (const CreaseCurve& c : curves) {
    const std::string name = "curve " + std::to_string(c.id);
    if (c.id < 0) failPattern("a curve has a negative id");
    if (!ids.insert(c.id).second) failPattern(name + " is listed twice");
    if (c.degree < 1) failPattern(name + " has degree < 1");
    const auto m = static_cast<std::size_t>(c.controlPoints.rows());
    if (m < static_cast<std::size_t>(c.degree) + 1) failPattern(name + " has too few control points");
    if (c.knots.size() != m + static_cast<std::size_t>(c.degree) + 1)
      failPattern(name + " needs controlPoints + degree + 1 knots");
    for (std::size_t k = 0; k < c.knots.size(); ++k) {
      if (!std::isfinite(c.knots[k])) failPattern(name + " has a non-finite knot");
      if (k > 0 && c.knots[k] < c.knots[k - 1]) failPattern(name + " has decreasing knots");
    }
    if (!c.controlPoints.allFinite()) failPattern(name + " has a non-finite control point");
    if (!c.weights.empty()) {
      if (c.weights.size() != m) failPattern(name + " needs one weight per control point");
      for (double w : c.weights)
        if (!(w > 0.0) || !std::isfinite(w)) failPattern(name + " has a weight that is not positive");
    }
  }
}

char foldAssignmentLetter(EdgeAssignment a) {
  switch (a) {
    case EdgeAssignment::Boundary: return 'B';
    case EdgeAssignment::Mountain: return 'M';
    case EdgeAssignment::Valley: return 'V';
    case EdgeAssignment::Flat: return 'F';
    case EdgeAssignment::Cut: return 'C';
  }
  return 'F';
}

EdgeAssignment parseFoldAssignment(const std::string& letter) {
  if (letter == "B") return EdgeAssignment::Boundary;
  if (letter == "M") return EdgeAssignment::Mountain;
  if (letter == "V") return EdgeAssignment::Valley;
  if (letter == "F" || letter == "U" || letter == "J") return EdgeAssignment::Flat;
  if (letter == "C") return EdgeAssignment::Cut;
  throw std::invalid_argument("unknown FOLD edge assignment \"" + letter + "\"");
}

const char* assignmentName(EdgeAssignment a) {
  switch (a) {
    case EdgeAssignment::Boundary: return "boundary";
    case EdgeAssignment::Mountain: return "mountain";
    case EdgeAssignment::Valley: return "valley";
    case EdgeAssignment::Flat: return "flat";
    case EdgeAssignment::Cut: return "cut";
  }
  return "flat";
}

std::vector<std::optional<double>> measuredFoldAngles(const CreasePattern& p) {
  std::vector<std::optional<double>> out(p.edges.size());
  if (!p.hasFoldedState()) return out;
  const auto n = p.vertices3d.rows();

  // Directed edge (a, b) of a face loop → face, or −1 when several faces use it (non-manifold).
  std::map<std::pair<int, int>, int> faceOf;
  for (std::size_t f = 0; f < p.faces.size(); ++f) {
    const auto& loop = p.faces[f];
    for (std::size_t k = 0; k < loop.size(); ++k) {
      const auto key = std::make_pair(loop[k], loop[(k + 1) % loop.size()]);
      auto [it, inserted] = faceOf.emplace(key, static_cast<int>(f));
      if (!inserted) it->second = -1;
    }
  }
  std::vector<std::optional<Eigen::Vector3d>> normals(p.faces.size());
  auto normal = [&](int f) -> const std::optional<Eigen::Vector3d>& {
    auto& slot = normals[static_cast<std::size_t>(f)];
    if (!slot) {
      for (int v : p.faces[static_cast<std::size_t>(f)])
        if (v < 0 || v >= n) return slot;
      const Eigen::Vector3d nn = newellNormal(p.vertices3d, p.faces[static_cast<std::size_t>(f)]);
      if (nn.norm() > 0.0) slot = nn.normalized();
    }
    return slot;
  };

  for (std::size_t e = 0; e < p.edges.size(); ++e) {
    const CreaseEdge& ed = p.edges[e];
    if (ed.v0 < 0 || ed.v0 >= n || ed.v1 < 0 || ed.v1 >= n) continue;
    const auto left = faceOf.find({ed.v0, ed.v1});
    const auto right = faceOf.find({ed.v1, ed.v0});
    if (left == faceOf.end() || right == faceOf.end() || left->second < 0 || right->second < 0 ||
        left->second == right->second)
      continue;
    const auto& nl = normal(left->second);
    const auto& nr = normal(right->second);
    const Eigen::Vector3d dir = (p.vertices3d.row(ed.v1) - p.vertices3d.row(ed.v0)).transpose();
    if (!nl || !nr || !(dir.norm() > 0.0)) continue;
    // Valley: the right face turns towards the left face's normal side, so nR × nL points along
    // the edge direction v0→v1.
    const double s = nr->cross(*nl).dot(dir.normalized());
    const double c = nl->dot(*nr);
    out[e] = std::atan2(s, c) * 180.0 / kCreasePatternPi;
  }
  return out;
}

std::vector<std::optional<double>> exportedFoldAngles(const CreasePattern& p) {
  std::vector<std::optional<double>> out(p.edges.size());
  std::vector<std::optional<double>> measured;
  for (std::size_t e = 0; e < p.edges.size(); ++e) {
    const CreaseEdge& ed = p.edges[e];
    if (ed.foldAngle) {
      out[e] = ed.foldAngle;
      continue;
    }
    if (ed.assignment != EdgeAssignment::Mountain && ed.assignment != EdgeAssignment::Valley) {
      out[e] = 0.0;
      continue;
    }
    if (measured.empty()) measured = measuredFoldAngles(p);
    if (measured[e]) {
      const double mag = std::abs(*measured[e]);
      out[e] = ed.assignment == EdgeAssignment::Mountain ? -mag : mag;
    }
  }
  return out;
}

std::vector<EdgeChain> edgeChains(const CreasePattern& p) {
  // Groups in order of first appearance.
  std::map<std::pair<int, int>, std::size_t> groupIndex;
  std::vector<std::vector<int>> groups;
  for (std::size_t e = 0; e < p.edges.size(); ++e) {
    const auto key = std::make_pair(static_cast<int>(p.edges[e].assignment), p.edges[e].curve);
    auto [it, inserted] = groupIndex.emplace(key, groups.size());
    if (inserted) groups.emplace_back();
    groups[it->second].push_back(static_cast<int>(e));
  }

  std::vector<EdgeChain> chains;
  std::vector<char> used(p.edges.size(), 0);
  for (const auto& group : groups) {
    std::map<int, std::vector<int>> incident;  // vertex → group edges, ascending
    for (int e : group) {
      incident[p.edges[e].v0].push_back(e);
      incident[p.edges[e].v1].push_back(e);
    }
    auto other = [&](int e, int v) { return p.edges[e].v0 == v ? p.edges[e].v1 : p.edges[e].v0; };
    // The next edge of the chain through vertex v after edge `from`, or −1 when the chain stops.
    auto next = [&](int v, int from) {
      const auto& inc = incident[v];
      if (inc.size() != 2) return -1;
      const int e = inc[0] == from ? inc[1] : inc[0];
      return used[e] ? -1 : e;
    };

    for (int start : group) {
      if (used[start]) continue;
      used[start] = 1;
      EdgeChain chain;
      chain.assignment = p.edges[start].assignment;
      chain.curve = p.edges[start].curve;
      std::deque<int> verts{p.edges[start].v0, p.edges[start].v1};
      std::deque<int> edges{start};

      for (int cur = verts.back(), from = start;;) {  // forward from v1
        const int e = next(cur, from);
        if (e < 0) break;
        used[e] = 1;
        edges.push_back(e);
        const int v = other(e, cur);
        if (v == verts.front()) {
          chain.closed = true;
          break;
        }
        verts.push_back(v);
        cur = v;
        from = e;
      }
      if (!chain.closed) {
        for (int cur = verts.front(), from = start;;) {  // backward from v0
          const int e = next(cur, from);
          if (e < 0) break;
          used[e] = 1;
          const int v = other(e, cur);
          if (v == verts.back()) {  // the closing edge joins the last vertex back to the first
            edges.push_back(e);
            chain.closed = true;
            break;
          }
          edges.push_front(e);
          verts.push_front(v);
          cur = v;
          from = e;
        }
      }
      chain.vertices.assign(verts.begin(), verts.end());
      chain.edges.assign(edges.begin(), edges.end());
      chains.push_back(std::move(chain));
    }
  }
  return chains;
}

}  // namespace devsurf::io
