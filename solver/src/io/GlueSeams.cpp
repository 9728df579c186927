#include "devsurf/io/GlueSeams.h"

#include <algorithm>
#include <cmath>
#include <deque>
#include <limits>
#include <map>
#include <numeric>
#include <stdexcept>
#include <string>
#include <utility>

namespace devsurf::io {
namespace {

/// Disjoint sets over 0..n−1 (the glue classes of vertices, the seams of glue pairs).
class DisjointSets {
 public:
  explicit DisjointSets(int n) : parent_(static_cast<std::size_t>(n)) {
    std::iota(parent_.begin(), parent_.end(), 0);
  }
  int find(int i) {
    while (parent_[static_cast<std::size_t>(i)] != i) {
      parent_[static_cast<std::size_t>(i)] =
          parent_[static_cast<std::size_t>(parent_[static_cast<std::size_t>(i)])];
      i = parent_[static_cast<std::size_t>(i)];
    }
    return i;
  }
  void join(int a, int b) {
    a = find(a);
    b = find(b);
    if (a != b) parent_[static_cast<std::size_t>(std::max(a, b))] = std::min(a, b);
  }

 private:
  std::vector<int> parent_;
};

}  // namespace

GlueSeams findGlueSeams(int vertexCount, const std::vector<PolygonFace>& faces,
                        const std::vector<std::array<int, 2>>& gluePairs,
                        const Eigen::MatrixXd& unfolding) {
  validatePolygonFaces(faces, vertexCount);
  if (unfolding.rows() > 0 && unfolding.rows() != vertexCount)
    throw std::invalid_argument("the unfolding has " + std::to_string(unfolding.rows()) +
                                " vertices, not " + std::to_string(vertexCount));
  // Angle sums of the material at each vertex in M′ (the corner rule of seams).
  std::vector<double> angleSum(static_cast<std::size_t>(vertexCount), 0.0);
  if (unfolding.rows() > 0) {
    for (const PolygonFace& face : faces) {
      const int n = cornerCount(face);
      for (int c = 0; c < n; ++c) {
        const int v = face[static_cast<std::size_t>(c)];
        const Eigen::VectorXd p = unfolding.row(v).transpose();
        const Eigen::VectorXd a = unfolding.row(face[static_cast<std::size_t>((c + 1) % n)]).transpose() - p;
        const Eigen::VectorXd b = unfolding.row(face[static_cast<std::size_t>((c + n - 1) % n)]).transpose() - p;
        const double denominator = a.norm() * b.norm();
        if (denominator > 0.0)
          angleSum[static_cast<std::size_t>(v)] += std::acos(std::clamp(a.dot(b) / denominator, -1.0, 1.0));
      }
    }
  }
  auto seamGoesOn = [&unfolding, &angleSum](int v, int w) {
    if (unfolding.rows() == 0) return true;
    const double total = angleSum[static_cast<std::size_t>(v)] + angleSum[static_cast<std::size_t>(w)];
    return std::abs(total - 2.0 * M_PI) <= 0.25 * M_PI;
  };
  GlueSeams out;
  std::vector<PolygonEdge>& edges = out.edges;

  // Edges, each once.
  std::map<std::pair<int, int>, int> edgeIndex;
  for (std::size_t f = 0; f < faces.size(); ++f) {
    const int n = cornerCount(faces[f]);
    for (int c = 0; c < n; ++c) {
      const int a = faces[f][static_cast<std::size_t>(c)];
      const int b = faces[f][static_cast<std::size_t>((c + 1) % n)];
      const auto [it, added] =
          edgeIndex.emplace(std::make_pair(std::min(a, b), std::max(a, b)), static_cast<int>(edges.size()));
      if (added) {
        PolygonEdge e;
        e.v0 = a;
        e.v1 = b;
        e.faceCount = 1;
        e.face = static_cast<int>(f);
        edges.push_back(e);
      } else if (++edges[static_cast<std::size_t>(it->second)].faceCount > 2) {
        throw std::invalid_argument("face " + std::to_string(f) + ": edge (" + std::to_string(a) +
                                    ", " + std::to_string(b) + ") has more than two faces");
      }
    }
  }

  // Glue classes of vertices.
  DisjointSets glued(vertexCount);
  for (std::size_t p = 0; p < gluePairs.size(); ++p) {
    const auto [i, j] = gluePairs[p];
    if (i < 0 || i >= vertexCount || j < 0 || j >= vertexCount)
      throw std::invalid_argument("glue pair " + std::to_string(p) + " has a vertex index outside [0, " +
                                  std::to_string(vertexCount) + ")");
    if (i == j) throw std::invalid_argument("glue pair " + std::to_string(p) + " glues vertex " +
                                            std::to_string(i) + " to itself");
    glued.join(i, j);
  }

  // Glued boundary edges: same pair of glue classes.
  std::map<std::pair<int, int>, std::vector<int>> byClasses;
  for (std::size_t e = 0; e < edges.size(); ++e) {
    if (edges[e].faceCount != 1) continue;
    const int a = glued.find(edges[e].v0), b = glued.find(edges[e].v1);
    if (a == b) continue;  // both ends glued to each other: a cut
    byClasses[{std::min(a, b), std::max(a, b)}].push_back(static_cast<int>(e));
  }
  std::vector<std::array<int, 2>> pairs;  // glued edge pairs, the lower edge first
  for (const auto& [key, list] : byClasses) {
    for (std::size_t k = 0; k + 1 < list.size(); k += 2) {
      edges[static_cast<std::size_t>(list[k])].gluedTo = list[k + 1];
      edges[static_cast<std::size_t>(list[k + 1])].gluedTo = list[k];
      pairs.push_back({list[k], list[k + 1]});
    }
  }
  std::sort(pairs.begin(), pairs.end());

  // Glued boundary edges at each vertex.
  std::vector<std::vector<int>> gluedAt(static_cast<std::size_t>(vertexCount));
  for (std::size_t e = 0; e < edges.size(); ++e) {
    if (edges[e].gluedTo < 0) continue;
    gluedAt[static_cast<std::size_t>(edges[e].v0)].push_back(static_cast<int>(e));
    gluedAt[static_cast<std::size_t>(edges[e].v1)].push_back(static_cast<int>(e));
  }
  auto sharedVertex = [&edges](int e, int f) {
    const PolygonEdge& a = edges[static_cast<std::size_t>(e)];
    const PolygonEdge& b = edges[static_cast<std::size_t>(f)];
    if (a.v0 == b.v0 || a.v0 == b.v1) return a.v0;
    if (a.v1 == b.v0 || a.v1 == b.v1) return a.v1;
    return -1;
  };

  // Seams: walk the chains breadth-first from the lowest pair, assigning sides as we go.
  for (std::size_t start = 0; start < pairs.size(); ++start) {
    if (edges[static_cast<std::size_t>(pairs[start][0])].seam >= 0) continue;
    const int seam = out.seamCount++;
    std::deque<int> queue;  // edges whose side is set and whose neighbours are to be looked at
    auto assign = [&edges, &queue, seam](int e, int side) {
      PolygonEdge& a = edges[static_cast<std::size_t>(e)];
      PolygonEdge& b = edges[static_cast<std::size_t>(a.gluedTo)];
      a.seam = b.seam = seam;
      a.side = side;
      b.side = 1 - side;
      queue.push_back(e);
    };
    assign(pairs[start][0], 0);
    while (!queue.empty()) {
      const int e = queue.front();
      queue.pop_front();
      const int partner = edges[static_cast<std::size_t>(e)].gluedTo;
      const int side = edges[static_cast<std::size_t>(e)].side;
      for (const int v : {edges[static_cast<std::size_t>(e)].v0, edges[static_cast<std::size_t>(e)].v1}) {
        for (const int f : gluedAt[static_cast<std::size_t>(v)]) {
          if (f == e || f == partner || edges[static_cast<std::size_t>(f)].seam >= 0) continue;
          const int fPartner = edges[static_cast<std::size_t>(f)].gluedTo;
          const int w = sharedVertex(partner, fPartner);
          if (w < 0 || glued.find(w) != glued.find(v) || !seamGoesOn(v, w)) continue;
          assign(f, side);
        }
      }
    }
  }
  return out;
}

std::vector<SeamLabel> seamLabelPositions(const GlueSeams& seams, const std::vector<PolygonFace>& faces,
                                          const Eigen::MatrixXd& unfolding, double inset) {
  const Eigen::MatrixXd& V = unfolding;
  auto midpoint = [&V](const PolygonEdge& e) -> Eigen::Vector2d {
    return 0.5 * (V.row(e.v0).head<2>() + V.row(e.v1).head<2>()).transpose();
  };
  std::vector<SeamLabel> labels;
  for (int seam = 0; seam < seams.seamCount; ++seam) {
    for (int side = 0; side < 2; ++side) {
      Eigen::Vector2d mean = Eigen::Vector2d::Zero();
      int count = 0;
      for (const PolygonEdge& e : seams.edges)
        if (e.seam == seam && e.side == side) {
          mean += midpoint(e);
          ++count;
        }
      if (count == 0) continue;
      mean /= count;
      const PolygonEdge* best = nullptr;
      double bestDistance = std::numeric_limits<double>::infinity();
      for (const PolygonEdge& e : seams.edges) {
        if (e.seam != seam || e.side != side) continue;
        const double d = (midpoint(e) - mean).squaredNorm();
        if (d < bestDistance) {
          bestDistance = d;
          best = &e;
        }
      }
      const Eigen::Vector2d a = V.row(best->v0).head<2>().transpose();
      const Eigen::Vector2d b = V.row(best->v1).head<2>().transpose();
      const PolygonFace& face = faces[static_cast<std::size_t>(best->face)];
      Eigen::Vector2d centre = Eigen::Vector2d::Zero();
      for (int c = 0; c < cornerCount(face); ++c) centre += V.row(face[static_cast<std::size_t>(c)]).head<2>().transpose();
      centre /= cornerCount(face);
      const Eigen::Vector2d mid = 0.5 * (a + b);
      const Eigen::Vector2d edge = b - a;
      Eigen::Vector2d inward(-edge.y(), edge.x());
      if (inward.dot(centre - mid) < 0.0) inward = -inward;
      const double length = inward.norm();
      labels.push_back({seam, side, length > 0.0 ? Eigen::Vector2d(mid + inward / length * inset) : mid});
    }
  }
  return labels;
}

}  // namespace devsurf::io
