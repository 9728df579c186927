#include "devsurf/models/composite/CompositeFoldConflicts.h"

#include <algorithm>
#include <cmath>
#include <map>


#include "devsurf/models/composite/CompositeTopology.h"

namespace devsurf::models::composite {

namespace {

/// Angles closer than this (radians) to π count as one straight line.
constexpr double kStraightTolerance = 1e-3;
constexpr double kPi = 3.14159265358979323846;

/// One face corner at a vertex: the two creases bounding it and its angle.
struct FoldCorner {
  int edgeA = -1, edgeB = -1;
  double angle = 0.0;
};

}  // namespace

std::vector<FoldConflict> foldConflicts(const CompositeDesign& design) {
  const CompositeTopology topology(design);
  return foldConflicts(design, topology);
}

std::vector<FoldConflict> foldConflicts(const CompositeDesign& design, const CompositeTopology& topology) {
  const int numVertices = topology.numVertices();
  // Non-zero fold target per R edge (its one hinge).
  std::vector<double> target(design.edges.size(), 0.0);
  for (const FoldAngleTarget& t : design.foldAngles)
    if (t.edge >= 0 && static_cast<std::size_t>(t.edge) < target.size() && target[static_cast<std::size_t>(t.edge)] == 0.0)
      target[static_cast<std::size_t>(t.edge)] = t.angleDeg;

  std::vector<std::vector<int>> edgesAt(static_cast<std::size_t>(numVertices));
  for (int e = 0; e < topology.numEdges(); ++e)
    for (int v : topology.edgeVertices(e)) edgesAt[static_cast<std::size_t>(v)].push_back(e);
  std::vector<std::vector<FoldCorner>> cornersAt(static_cast<std::size_t>(numVertices));
  std::vector<bool> bends(static_cast<std::size_t>(numVertices), false);
  for (int f = 0; f < topology.numFaces(); ++f) {
    const FaceInfo& face = topology.face(f);
    const int n = static_cast<int>(face.loop.size());
    for (int k = 0; k < n; ++k) {
      const int v = face.corners[static_cast<std::size_t>(k)];
      if (face.type != FaceType::Planar) {
        for (const OrientedEdge& oe : face.loop)
          for (int w : topology.edgeVertices(oe.edge)) bends[static_cast<std::size_t>(w)] = true;
        break;
      }
      // Corner k: the loop's edge k leaves v, edge k − 1 arrives at it.
      const int out = face.loop[static_cast<std::size_t>(k)].edge;
      const int in = face.loop[static_cast<std::size_t>((k + n - 1) % n)].edge;
      const auto other = [&topology, v](int e) {
        const std::array<int, 2> ends = topology.edgeVertices(e);
        return ends[0] == v ? ends[1] : ends[0];
      };
      const Eigen::Vector3d p = design.vertices.row(v).transpose();
      const Eigen::Vector3d a = design.vertices.row(other(out)).transpose() - p;
      const Eigen::Vector3d b = design.vertices.row(other(in)).transpose() - p;
      const double angle = std::atan2(a.cross(b).norm(), a.dot(b));
      cornersAt[static_cast<std::size_t>(v)].push_back({out, in, angle});
    }
  }

  std::vector<FoldConflict> conflicts;
  for (int v = 0; v < numVertices; ++v) {
    const std::vector<int>& edges = edgesAt[static_cast<std::size_t>(v)];
    if (topology.boundaryVertex()[static_cast<std::size_t>(v)] || edges.empty()) continue;
    {
      // Curved creases too: where exactly three creases fold, one of them curved (any other edge
      // at v smooth, a proposed ruling), their tangent planes at v form a vertex of degree three,
      // which folds only with one of them flat there: a crease that ends on a curved one (a T)
      // cannot fold at that end, and its target pulls against the sheet (4° of −45° at 100 %).
      int folds = 0, straightFolds = 0, curvedFolds = 0;
      bool othersSmooth = true;
      for (int e : edges) {
        if (topology.edge(e).interior() && target[static_cast<std::size_t>(e)] != 0.0) {
          ++folds;
          ++(topology.edgeType(e) == EdgeType::Ruling ? straightFolds : curvedFolds);
        } else if (design.edges[static_cast<std::size_t>(e)].crease != CreaseKind::Smooth) {
          othersSmooth = false;
        }
      }
      if (folds == 3 && othersSmooth && curvedFolds > 0) {
        conflicts.push_back({v, straightFolds > 0
                                    ? "a straight crease ends on a curved one here: three creases meeting at a point fold "
                                      "only with one of them flat there, so it cannot fold (end it at the sheet's edge, "
                                      "continue it across, or make it flat)"
                                    : "three curved creases meet here: a point where three folds meet is rigid and does "
                                      "not fold unless one of them stays flat (make one of them flat, or add a fourth "
                                      "crease)"});
        continue;
      }
    }
    if (bends[static_cast<std::size_t>(v)]) continue;
    const bool allFold = std::all_of(edges.begin(), edges.end(), [&topology, &target](int e) {
      return topology.edge(e).interior() && topology.edgeType(e) == EdgeType::Ruling && target[static_cast<std::size_t>(e)] != 0.0;
    });
    if (!allFold) continue;
    const int n = static_cast<int>(edges.size());
    int valleys = 0;
    for (int e : edges) valleys += target[static_cast<std::size_t>(e)] > 0.0 ? 1 : 0;
    const int mountains = n - valleys;
    // The creases in order around v, with the sector angle after each.
    std::vector<int> order;
    std::vector<double> sector;
    const std::vector<FoldCorner>& corners = cornersAt[static_cast<std::size_t>(v)];
    if (static_cast<int>(corners.size()) == n) {
      int e = corners.front().edgeA;
      for (int step = 0; step < n; ++step) {
        const auto c = std::find_if(corners.begin(), corners.end(), [e](const FoldCorner& k) { return k.edgeA == e; });
        if (c == corners.end()) break;
        order.push_back(e);
        sector.push_back(c->angle);
        e = c->edgeB;
      }
    }
    const bool ordered = static_cast<int>(order.size()) == n;
    const auto straight = [](double angle) { return std::abs(angle - kPi) <= kStraightTolerance; };
    std::string reason;
    if (n == 2) {
      if (ordered && !straight(sector[0]))
        reason = "two creases meet at an angle of " + std::to_string(static_cast<int>(std::lround(sector[0] * 180.0 / kPi))) +
                 "°: a crease cannot bend at a point, so one of them would stretch the sheet (make them one straight "
                 "line, or add a crease through this point)";
      else if (valleys == 1)
        reason = "a straight crease turns from mountain to valley here: a straight line folds one way along all of it";
    } else if (n == 3) {
      reason = "three creases meet here: a point where three folds meet is rigid and does not fold unless one of them "
               "stays flat (make one of them flat, or add a fourth crease)";
    } else if (n == 4 && ordered && straight(sector[0] + sector[1]) && straight(sector[1] + sector[2])) {
      reason = "two straight creases cross here: a flat sheet folds along one of them at a time, never both (make one "
               "of them flat, or end one at the other)";
    } else if (n == 4 && mountains != 1 && valleys != 1) {
      reason = std::to_string(mountains) + " mountain and " + std::to_string(valleys) +
               " valley creases meet here: four creases fold together only with three of one kind and one of the other";
    } else if (n >= 5 && (mountains == 0 || valleys == 0)) {
      reason = "every crease here is a " + std::string(mountains == 0 ? "valley" : "mountain") +
               ": the creases around a point cannot all fold one way";
    }
    if (!reason.empty()) conflicts.push_back({v, std::move(reason)});
  }
  return conflicts;
}

}  // namespace devsurf::models::composite
