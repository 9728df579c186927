#include "devsurf/io/CreasePatternSlits.h"

#include <algorithm>
#include <map>
#include <numeric>
#include <string>
#include <utility>

namespace devsurf::io {

namespace {

int slitRoot(std::vector<int>& parent, int i) {
  while (parent[static_cast<std::size_t>(i)] != i) i = parent[static_cast<std::size_t>(i)] = parent[static_cast<std::size_t>(parent[static_cast<std::size_t>(i)])];
  return i;
}

}  // namespace

SlitCut cutAlongSlits(const CreasePattern& pattern) {
  SlitCut out;
  out.pattern = pattern;
  const int n = pattern.numVertices();
  out.sourceVertex.resize(static_cast<std::size_t>(n));
  std::iota(out.sourceVertex.begin(), out.sourceVertex.end(), 0);
  std::map<std::pair<int, int>, int> cutEdgeOf;  // vertex pair → cut edge
  for (std::size_t e = 0; e < pattern.edges.size(); ++e)
    if (pattern.edges[e].assignment == EdgeAssignment::Cut)
      cutEdgeOf[std::minmax(pattern.edges[e].v0, pattern.edges[e].v1)] = static_cast<int>(e);
  if (cutEdgeOf.empty()) return out;

  // Corners: (face, position). Per vertex on a cut, its corners grouped into sectors.
  struct Corner {
    int face, k;
  };
  std::vector<std::vector<Corner>> cornersAt(static_cast<std::size_t>(n));
  for (std::size_t f = 0; f < pattern.faces.size(); ++f)
    for (std::size_t k = 0; k < pattern.faces[f].size(); ++k)
      cornersAt[static_cast<std::size_t>(pattern.faces[f][k])].push_back({static_cast<int>(f), static_cast<int>(k)});
  std::vector<bool> onCut(static_cast<std::size_t>(n), false);
  for (const auto& [pair, e] : cutEdgeOf) onCut[static_cast<std::size_t>(pair.first)] = onCut[static_cast<std::size_t>(pair.second)] = true;

  std::vector<std::vector<int>>& faces = out.pattern.faces;
  int next = n;
  std::vector<std::vector<double>> extra2d, extra3d;
  for (int v = 0; v < n; ++v) {
    const std::vector<Corner>& corners = cornersAt[static_cast<std::size_t>(v)];
    if (!onCut[static_cast<std::size_t>(v)] || corners.size() < 2) continue;
    // Corners sharing an edge {v, u} that is not a cut are in one sector.
    std::vector<int> parent(corners.size());
    std::iota(parent.begin(), parent.end(), 0);
    std::map<int, int> firstCornerWith;  // neighbour u → a corner having edge {v, u}
    for (std::size_t c = 0; c < corners.size(); ++c) {
      const std::vector<int>& loop = pattern.faces[static_cast<std::size_t>(corners[c].face)];
      const int m = static_cast<int>(loop.size());
      for (int u : {loop[static_cast<std::size_t>((corners[c].k + m - 1) % m)], loop[static_cast<std::size_t>((corners[c].k + 1) % m)]}) {
        if (cutEdgeOf.count(std::minmax(v, u))) continue;
        const auto [it, fresh] = firstCornerWith.emplace(u, static_cast<int>(c));
        if (!fresh) parent[static_cast<std::size_t>(slitRoot(parent, static_cast<int>(c)))] = slitRoot(parent, it->second);
      }
    }
    std::map<int, int> copyOfSector;
    for (std::size_t c = 0; c < corners.size(); ++c) {
      const int sector = slitRoot(parent, static_cast<int>(c));
      auto [it, fresh] = copyOfSector.emplace(sector, copyOfSector.empty() ? v : next);
      if (fresh && it->second == next) {
        ++next;
        out.sourceVertex.push_back(v);
      }
      faces[static_cast<std::size_t>(corners[c].face)][static_cast<std::size_t>(corners[c].k)] = it->second;
    }
  }
  // The copies' positions.
  const int total = next;
  out.pattern.vertices2d.conservativeResize(total, 2);
  if (pattern.hasFoldedState()) out.pattern.vertices3d.conservativeResize(total, 3);
  for (int w = n; w < total; ++w) {
    out.pattern.vertices2d.row(w) = pattern.vertices2d.row(out.sourceVertex[static_cast<std::size_t>(w)]);
    if (pattern.hasFoldedState()) out.pattern.vertices3d.row(w) = pattern.vertices3d.row(out.sourceVertex[static_cast<std::size_t>(w)]);
  }

  // Edges: every edge takes the vertices its faces use now; a cut edge one boundary edge per side.
  std::map<std::pair<int, int>, std::vector<std::pair<int, int>>> sidesOf;  // old pair → new (a, b) per face
  for (std::size_t f = 0; f < faces.size(); ++f) {
    const std::vector<int>& was = pattern.faces[f];
    const std::vector<int>& is = faces[f];
    for (std::size_t k = 0; k < was.size(); ++k) {
      const std::size_t j = (k + 1) % was.size();
      const auto key = std::minmax(was[k], was[j]);
      // In the old edge's orientation (key.first → key.second).
      sidesOf[key].push_back(was[k] == key.first ? std::pair{is[k], is[j]} : std::pair{is[j], is[k]});
    }
  }
  std::vector<CreaseEdge>& edges = out.pattern.edges;
  const std::size_t numEdges = edges.size();
  for (std::size_t e = 0; e < numEdges; ++e) {
    CreaseEdge& edge = edges[e];
    const auto key = std::minmax(edge.v0, edge.v1);
    const auto sides = sidesOf.find(key);
    const std::string element = "edges[" + std::to_string(e) + "]";
    if (sides == sidesOf.end()) {
      if (edge.assignment == EdgeAssignment::Cut) out.notes.push_back({element, "a cut (C) on no face; left as it is"});
      continue;
    }
    const bool forward = edge.v0 == key.first;
    const auto oriented = [forward](std::pair<int, int> s) { return forward ? s : std::pair{s.second, s.first}; };
    const std::pair<int, int> first = oriented(sides->second.front());
    edge.v0 = first.first;
    edge.v1 = first.second;
    if (edge.assignment != EdgeAssignment::Cut) continue;
    if (sides->second.size() == 2 && std::minmax(sides->second[0].first, sides->second[0].second) ==
                                         std::minmax(sides->second[1].first, sides->second[1].second)) {
      out.notes.push_back({element, "a cut (C) of one edge with both ends inside the sheet: its two sides would join the "
                                    "same two points, so it is not cut: its faces stay joined and fold freely there (draw the slit with a point in its middle)"});
      continue;
    }
    edge.assignment = EdgeAssignment::Boundary;
    edge.foldAngle.reset();
    if (sides->second.size() == 2) {
      CreaseEdge other = edge;
      const std::pair<int, int> second = oriented(sides->second.back());
      other.v0 = second.first;
      other.v1 = second.second;
      edges.push_back(other);
    }
  }
  // A design is one piece: cuts that part the sheet (a cut from edge to edge) are not made.
  {
    std::vector<int> piece(faces.size());
    std::iota(piece.begin(), piece.end(), 0);
    std::map<std::pair<int, int>, int> faceWithSide;
    for (std::size_t f = 0; f < faces.size(); ++f)
      for (std::size_t k = 0; k < faces[f].size(); ++k) {
        const auto key = std::minmax(faces[f][k], faces[f][(k + 1) % faces[f].size()]);
        const auto [it, fresh] = faceWithSide.emplace(key, static_cast<int>(f));
        if (!fresh) piece[static_cast<std::size_t>(slitRoot(piece, static_cast<int>(f)))] = slitRoot(piece, it->second);
      }
    int pieces = 0;
    for (std::size_t f = 0; f < faces.size(); ++f) pieces += slitRoot(piece, static_cast<int>(f)) == static_cast<int>(f);
    if (pieces > 1) {
      SlitCut joined;
      joined.pattern = pattern;
      joined.sourceVertex.resize(static_cast<std::size_t>(n));
      std::iota(joined.sourceVertex.begin(), joined.sourceVertex.end(), 0);
      joined.notes = out.notes;
      joined.notes.push_back({"edges_assignment", "the cut (C) edges would cut the sheet into " + std::to_string(pieces) +
                                                      " pieces, and a design is one piece: they are kept joined and fold freely "
                                                      "(import each piece on its own, or end a slit inside the sheet)"});
      return joined;
    }
  }
  int doubled = total - n;
  if (doubled > 0)
    out.notes.push_back({"edges_assignment", "the sheet is cut along its cut (C) edges: " + std::to_string(doubled) +
                                                 " point" + (doubled == 1 ? "" : "s") + " along them doubled, one per side"});
  out.pattern.validate();
  return out;
}

}  // namespace devsurf::io
