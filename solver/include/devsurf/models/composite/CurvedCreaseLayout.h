#pragma once

#include <cassert>// Proposing rulings in a curved crease pattern's faces (issue 16 item 1): the pieces of
// compositeFromCurvedCreasePattern — a face's sides, its ruling layouts, proposed rulings inside it,
// and the spline of a curved side. Pattern vertices and edges of io::CreasePattern throughout.

#include <array>
#include <map>
#include <optional>
#include <set>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "devsurf/io/CreasePattern.h"
#include "devsurf/spline/BSplineCurve.h"

namespace devsurf::models::composite::curved {

constexpr int kChordChain = -2;  ///< chain id of a proposed ruling

/// How a side of a face may be labelled.
enum class SideKind {
  Curve,     ///< part of a curved stroke: an S edge
  Crease,    ///< a straight interior edge (crease or proposed ruling): an R edge
  Outline,   ///< a straight piece of the sheet's outline: an R or an S edge, as the face needs
};

/// A run of a face's boundary between two corners.
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

/// The edges a pattern's faces use (and the rulings proposed since), with the strokes they belong
/// to: the graph a face's sides and corners are read from.
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
  /// Takes back the edge added last (a chord tried and not kept); its two ends had no edge
  /// between them before.
  void removeLastEdge() {
    assert(!ends.empty() && "an edge to take back");
    const auto [a, b] = ends.back();
    idOfPair.erase(std::minmax(a, b));
    incident[static_cast<std::size_t>(a)].pop_back();
    incident[static_cast<std::size_t>(b)].pop_back();
    ends.pop_back();
    chain.pop_back();
    interior.pop_back();
    patternEdge.pop_back();
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

/// Vertices of a chain of sides (joined), and the positions of its joints in it.
struct ChainPolyline {
  std::vector<int> vertices;
  std::vector<std::size_t> joints;  ///< indices into vertices of the corners inside the chain
  std::vector<double> t;            ///< normalized arc length per vertex
};

/// The sides of a face loop, starting at a corner; empty when the loop has none (one closed curve).
std::vector<Side> sidesOf(const CurvedGraph& g, const std::vector<int>& loop);

/// The cheapest ruling layout of a face with at least one curved side, or nullopt.
std::optional<Layout> bestLayout(const std::vector<Side>& sides);

ChainPolyline chainPolyline(const CurvedGraph& g, const std::vector<Side>& sides, const std::vector<int>& arc,
                            int apexVertex);

/// Whether the segment a–b runs inside the face without touching its boundary elsewhere.
bool chordFits(const CurvedGraph& g, const std::vector<int>& loop, int a, int b, double eps);

/// A proposed ruling from a joint of one chain to the other chain, or nullopt.
std::optional<std::pair<int, int>> proposeRuling(const CurvedGraph& g, const std::vector<int>& loop, const ChainPolyline& from,
                                                 const ChainPolyline& to, double eps);

/// Whether the rulings of a strip between two chains, paired by normalized arc length (both running
/// from the face's first ruling to its second), cross one another: of 65 rulings along the strip,
/// two neighbours cross (each one's ends strictly on both sides of the other).
bool rulingsCross(const CurvedGraph& g, const ChainPolyline& a, const ChainPolyline& b);

/// The vertices of a stroke in order along it (its pattern edges only, not proposed rulings).
std::vector<int> chainPath(const CurvedGraph& g, int chainId);

int startVertexOfPosition(const std::vector<Side>& sides, int half, bool endOfIt);

/// Least-squares cubic with m ≥ 5 control points through a polyline (chord-length parameters),
/// interpolating its end points with the given unit tangent directions there (so two pieces of one
/// crease meet with one tangent).
spline::BSplineCurve fitCrease(const std::vector<Eigen::Vector2d>& pts, int m, const Eigen::Vector2d& startTangent,
                               const Eigen::Vector2d& endTangent);

}  // namespace devsurf::models::composite::curved
