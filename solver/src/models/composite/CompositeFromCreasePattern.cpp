#include "devsurf/models/composite/CompositeFromCreasePattern.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <numeric>
#include <optional>
#include <stdexcept>
#include <string>
#include <utility>

#include "devsurf/io/CreasePatternSlits.h"
#include "devsurf/models/composite/CompositeFoldConflicts.h"
#include "devsurf/spatial/PlanarArrangement.h"

namespace devsurf::models::composite {

namespace {

int findGroup(std::vector<int>& parent, int i) {
  while (parent[i] != i) i = parent[i] = parent[parent[i]];
  return i;
}

/// The boundary of a union of faces as one simple vertex loop, or empty when it is not one (a hole,
/// a pinch, or more than one loop). `loops` are counter-clockwise vertex loops sharing edges in
/// opposite directions.
std::vector<int> unionBoundary(const std::vector<const std::vector<int>*>& loops) {
  std::map<std::pair<int, int>, int> directed;
  for (const auto* loop : loops)
    for (std::size_t k = 0; k < loop->size(); ++k) ++directed[{(*loop)[k], (*loop)[(k + 1) % loop->size()]}];
  std::map<int, int> nextOf;
  for (const auto& [edge, count] : directed) {
    if (directed.count({edge.second, edge.first})) continue;  // inside the union
    if (count != 1 || nextOf.count(edge.first)) return {};   // a vertex the boundary passes twice
    nextOf[edge.first] = edge.second;
  }
  if (nextOf.empty()) return {};
  std::vector<int> boundary{nextOf.begin()->first};
  while (boundary.size() <= nextOf.size()) {
    const auto it = nextOf.find(boundary.back());
    if (it == nextOf.end()) return {};
    if (it->second == boundary.front()) break;
    boundary.push_back(it->second);
  }
  if (boundary.size() != nextOf.size()) return {};  // more than one loop: a hole
  return boundary;
}

/// A note per vertex whose creases cannot all fold (foldConflicts), named by the pattern's vertex
/// and placed by its development coordinates.
void appendFoldConflictNotes(CreasePatternComposite& result, const io::CreasePattern& pattern) {
  std::vector<int> patternVertexOf(static_cast<std::size_t>(result.design.vertices.rows()), -1);
  for (std::size_t v = 0; v < result.designVertexOf.size(); ++v)
    if (result.designVertexOf[v] >= 0) patternVertexOf[static_cast<std::size_t>(result.designVertexOf[v])] = static_cast<int>(v);
  for (const FoldConflict& c : foldConflicts(result.design)) {
    const int v = patternVertexOf[static_cast<std::size_t>(c.vertex)];
    if (v < 0) continue;
    char at[96];
    std::snprintf(at, sizeof at, "at (%.4g, %.4g): ", pattern.vertices2d(v, 0), pattern.vertices2d(v, 1));
    result.notes.push_back({"vertices[" + std::to_string(v) + "]", at + c.reason});
  }
}

}  // namespace

namespace {

/// compositeFromCreasePattern once the sheet is cut along its slits.
CreasePatternComposite compositeFromCutPattern(const io::CreasePattern& pattern, int developmentSamples) {
  pattern.validate();
  if (pattern.faces.empty()) throw std::invalid_argument("crease pattern: no faces");
  if (developmentSamples < 1) throw std::invalid_argument("crease pattern: developmentSamples must be ≥ 1");
  if (hasCurvedCreases(pattern)) {
    CreasePatternComposite curved = compositeFromCurvedCreasePattern(pattern, developmentSamples);
    appendFoldConflictNotes(curved, pattern);
    return curved;
  }
  CreasePatternComposite result;
  const int faceCount = static_cast<int>(pattern.faces.size());

  std::map<std::pair<int, int>, int> edgeOfPair;
  for (std::size_t e = 0; e < pattern.edges.size(); ++e)
    edgeOfPair[std::minmax(pattern.edges[e].v0, pattern.edges[e].v1)] = static_cast<int>(e);
  std::map<std::pair<int, int>, std::vector<int>> facesOfPair;
  for (int f = 0; f < faceCount; ++f) {
    const auto& loop = pattern.faces[f];
    for (std::size_t k = 0; k < loop.size(); ++k) facesOfPair[std::minmax(loop[k], loop[(k + 1) % loop.size()])].push_back(f);
  }
  const std::vector<std::optional<double>> measured = io::measuredFoldAngles(pattern);

  // Merge faces across flat edges, one edge at a time, keeping each union a simple polygon.
  std::vector<int> group(faceCount);
  std::iota(group.begin(), group.end(), 0);
  std::vector<std::vector<int>> members(faceCount);
  for (int f = 0; f < faceCount; ++f) members[f] = {f};
  // Drawn flat edges first, then the proposed ones (bridges, edges marked smooth): around a hole
  // some edges cannot merge, and those are best the proposed ones, which stay smooth, rather than
  // drawn ones, which would be left to fold freely.
  std::vector<std::size_t> mergeOrder(pattern.edges.size());
  std::iota(mergeOrder.begin(), mergeOrder.end(), std::size_t{0});
  std::stable_partition(mergeOrder.begin(), mergeOrder.end(),
                        [&pattern](std::size_t e) { return !pattern.edges[e].proposed; });
  std::vector<bool> keptAsFold(pattern.edges.size(), false);
  for (const std::size_t e : mergeOrder) {
    const io::CreaseEdge& edge = pattern.edges[e];
    if (edge.assignment != io::EdgeAssignment::Flat) continue;
    const auto sides = facesOfPair.find(std::minmax(edge.v0, edge.v1));
    if (sides == facesOfPair.end() || sides->second.size() != 2) continue;
    const std::string element = "edges[" + std::to_string(e) + "]";
    if (measured[e] && std::abs(*measured[e]) >= 1.0) {
      result.notes.push_back({element, "flat (F) but folded by " + std::to_string(*measured[e]) +
                                           "° in the folded state; kept as a fold"});
      keptAsFold[e] = true;
      continue;
    }
    const int a = findGroup(group, sides->second[0]), b = findGroup(group, sides->second[1]);
    if (a == b) continue;
    std::vector<const std::vector<int>*> loops;
    for (int g : {a, b})
      for (int f : members[g]) loops.push_back(&pattern.faces[f]);
    if (unionBoundary(loops).empty()) {
      if (!edge.proposed)
        result.notes.push_back({element, "flat (F), but the faces it would join enclose a hole or touch at a vertex; "
                                         "kept as an edge that folds freely"});
      continue;
    }
    group[b] = a;
    members[a].insert(members[a].end(), members[b].begin(), members[b].end());
    members[b].clear();
  }

  // A folded form whose creases fold against their letters (a file whose faces wind the other
  // way, or whose M and V were exchanged): the folded form is what opens, and the notes say so.
  {
    int against = 0;
    std::string first;
    for (std::size_t e = 0; e < pattern.edges.size(); ++e) {
      const io::EdgeAssignment a = pattern.edges[e].assignment;
      if ((a != io::EdgeAssignment::Mountain && a != io::EdgeAssignment::Valley) || !measured[e] || std::abs(*measured[e]) < 1.0)
        continue;
      if ((a == io::EdgeAssignment::Valley) == (*measured[e] > 0.0)) continue;
      if (++against <= 5)
        first += std::string(first.empty() ? "" : ", ") + "edges_assignment[" + std::to_string(e) + "] " +
                 (a == io::EdgeAssignment::Valley ? "V" : "M") + " folded by " + std::to_string(std::lround(*measured[e])) + "°";
    }
    if (against > 0)
      result.notes.push_back({"edges_assignment", std::to_string(against) + " crease(s) fold against their letter in the "
                                                  "folded form (" + first + (against > 5 ? ", …" : "") +
                                                  "; + is valley): the folded form is kept, so they export as it folds them"});
  }

  // The faces of the design, as vertex loops of the pattern.
  std::vector<std::vector<int>> loops;
  for (int f = 0; f < faceCount; ++f) {
    if (findGroup(group, f) != f || members[f].empty()) continue;
    if (members[f].size() == 1) {
      loops.push_back(pattern.faces[f]);
      continue;
    }
    std::vector<const std::vector<int>*> parts;
    for (int m : members[f]) parts.push_back(&pattern.faces[m]);
    loops.push_back(unionBoundary(parts));
  }

  // Vertices the faces use, in the pattern's order.
  const int n = pattern.numVertices();
  result.designVertexOf.assign(n, -1);
  for (const auto& loop : loops)
    for (int v : loop) result.designVertexOf[v] = 0;
  int used = 0;
  for (int v = 0; v < n; ++v)
    if (result.designVertexOf[v] == 0) result.designVertexOf[v] = used++;
  for (int v = 0; v < n; ++v)
    if (result.designVertexOf[v] < 0) result.notes.push_back({"vertices[" + std::to_string(v) + "]", "on no face; left out"});
  CompositeDesign& d = result.design;
  d.vertices.resize(used, 3);
  for (int v = 0; v < n; ++v) {
    const int to = result.designVertexOf[v];
    if (to < 0) continue;
    if (pattern.hasFoldedState())
      d.vertices.row(to) = pattern.vertices3d.row(v);
    else
      d.vertices.row(to) << pattern.vertices2d(v, 0), pattern.vertices2d(v, 1), 0.0;
  }

  // Edges: one R edge per side of a face, numbered by the pattern's edges first.
  result.designEdgeOf.assign(pattern.edges.size(), -1);
  std::map<std::pair<int, int>, int> designEdgeOfPair;
  auto designEdge = [&d, &result, &designEdgeOfPair, &edgeOfPair](int a, int b) {
    const auto key = std::minmax(a, b);
    if (const auto it = designEdgeOfPair.find(key); it != designEdgeOfPair.end()) return it->second;
    CompositeEdge edge;
    edge.v0 = result.designVertexOf[a];
    edge.v1 = result.designVertexOf[b];
    edge.type = EdgeType::Ruling;
    const int id = static_cast<int>(d.edges.size());
    d.edges.push_back(edge);
    designEdgeOfPair[key] = id;
    if (const auto source = edgeOfPair.find(key); source != edgeOfPair.end()) result.designEdgeOf[source->second] = id;
    return id;
  };
  for (std::size_t e = 0; e < pattern.edges.size(); ++e) {
    const auto key = std::minmax(pattern.edges[e].v0, pattern.edges[e].v1);
    bool onLoop = false;
    for (const auto& loop : loops)
      for (std::size_t k = 0; k < loop.size() && !onLoop; ++k)
        onLoop = std::minmax(loop[k], loop[(k + 1) % loop.size()]) == key;
    if (onLoop) designEdge(key.first, key.second);
  }
  // A bridge the import proposed to an island stays smooth: the faces on its two sides are one
  // piece of the sheet.
  // (Not one the folded state folds: that one was kept as a fold, and a smooth label would force
  // its two faces into one plane.)
  for (std::size_t e = 0; e < pattern.edges.size(); ++e)
    if (pattern.edges[e].proposed && pattern.edges[e].assignment == io::EdgeAssignment::Flat && !keptAsFold[e] &&
        result.designEdgeOf[e] >= 0)
      d.edges[static_cast<std::size_t>(result.designEdgeOf[e])].crease = CreaseKind::Smooth;
  double largestArea = -1.0;
  int largestFace = 0;
  for (const auto& loop : loops) {
    std::vector<int> face;
    for (std::size_t k = 0; k < loop.size(); ++k) face.push_back(designEdge(loop[k], loop[(k + 1) % loop.size()]));
    const double area = spatial::loopSignedArea2(pattern.vertices2d, loop);
    if (area > largestArea) {
      largestArea = area;
      largestFace = static_cast<int>(d.faces.size());
    }
    d.faces.push_back(std::move(face));
  }
  for (int v : loops[largestFace]) d.fixed.push_back(PointRef::ofVertex(result.designVertexOf[v]));

  // Fold-angle targets: the file's angles; on a flat sheet, mountain and valley creases without
  // one aim at a full fold (∓180°, as Origami Simulator reads them). A folded form is the design
  // itself (fold amount 1); a flat sheet starts at 0 and the slider folds it.
  bool guessed = false;
  for (std::size_t e = 0; e < pattern.edges.size(); ++e) {
    const io::CreaseEdge& edge = pattern.edges[e];
    const int to = result.designEdgeOf[e];
    if (to < 0) continue;
    std::optional<double> angle = edge.foldAngle;
    if (!angle && !pattern.hasFoldedState() &&
        (edge.assignment == io::EdgeAssignment::Mountain || edge.assignment == io::EdgeAssignment::Valley)) {
      angle = edge.assignment == io::EdgeAssignment::Mountain ? -180.0 : 180.0;
      guessed = true;
    }
    if (!angle || *angle == 0.0) continue;
    d.foldAngles.push_back({to, 0, *angle});
  }
  if (guessed)
    result.notes.push_back({"edges_foldAngle", "not given for every crease: mountain and valley creases without one aim "
                                               "at a full fold (∓180°)"});
  d.foldAmount = pattern.hasFoldedState() || d.foldAngles.empty() ? 1.0 : 0.0;
  d.developmentSamples = developmentSamples;
  // The development is the sheet itself: every vertex pinned where the pattern has it, so folding
  // bends the sheet and never stretches it (a free development would co-evolve with the surface).
  for (int v = 0; v < n; ++v)
    if (result.designVertexOf[v] >= 0) d.developmentDomain.corners.push_back({result.designVertexOf[v], pattern.vertices2d.row(v).transpose()});
  appendFoldConflictNotes(result, pattern);
  return result;
}

}  // namespace

CreasePatternComposite compositeFromCreasePattern(const io::CreasePattern& pattern, int developmentSamples) {
  pattern.validate();
  const io::SlitCut slit = io::cutAlongSlits(pattern);
  CreasePatternComposite result = compositeFromCutPattern(slit.pattern, developmentSamples);
  result.notes.insert(result.notes.begin(), slit.notes.begin(), slit.notes.end());
  // Per vertex and edge of the pattern as given: a doubled point is its first copy, a cut edge
  // its first side.
  result.designVertexOf.resize(static_cast<std::size_t>(pattern.numVertices()));
  result.designEdgeOf.resize(pattern.edges.size());
  return result;
}

}  // namespace devsurf::models::composite
