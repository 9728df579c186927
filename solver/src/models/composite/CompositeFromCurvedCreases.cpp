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

#include "devsurf/io/CreaseStrokes.h"
#include "devsurf/models/composite/CompositeFromCreasePattern.h"
#include "devsurf/models/composite/CompositeHinges.h"
#include "devsurf/models/composite/CompositeTopology.h"
#include "devsurf/models/composite/CurvedCreaseLayout.h"
#include "devsurf/spatial/PlanarArrangement.h"
#include "devsurf/spline/Basis.h"

namespace devsurf::models::composite {

namespace {

/// Control points of every S edge at least, and development samples per span at least: a coarser
/// curved fold cannot meet its fold condition and the sheet's isometry together (4 and 2 leave a
/// 0.1 % strain that a release's projections resolve by unfolding a 90° fold to 45°; 6 and 4 keep
/// 80° of it).
constexpr int kMinControlPoints = 6;
constexpr int kMinDevelopmentSamples = 4;

/// The two loops a chord between the loop's vertices a and b cuts it into: a … b and b … a.
std::pair<std::vector<int>, std::vector<int>> splitLoop(const std::vector<int>& loop, int a, int b) {
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
  return {std::move(one), std::move(two)};
}

}  // namespace

using curved::ChainPolyline;
using curved::CurvedGraph;
using curved::kChordChain;
using curved::Layout;
using curved::Side;
using curved::SideKind;
using curved::bestLayout;
using curved::chainPath;
using curved::chainPolyline;
using curved::chordFits;
using curved::fitCrease;
using curved::proposeRuling;
using curved::rulingsCross;
using curved::sidesOf;
using curved::startVertexOfPosition;

namespace {
/// The farthest of `pts` from their principal line (the measure the import's straightness test
/// takes, io::kStraightStrokeFraction, rather than a mean that lets a bend 3× larger pass).
double offLine(const Eigen::MatrixX2d& pts) {
  const Eigen::RowVector2d centre = pts.colwise().mean();
  const Eigen::MatrixX2d centred = pts.rowwise() - centre;
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> pca(centred.transpose() * centred);
  return (centred * pca.eigenvectors().col(0)).cwiseAbs().maxCoeff();
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
    if (offLine(pts) > io::kStraightStrokeFraction * diagonal) return true;
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

  // A straight edge the import proposed (a bridge to an island) or one a FOLD file marks smooth:
  // a ruling this import proposes, not a drawn crease. A marked edge on a curve stays a curve.
  const auto isBridge = [](const io::CreaseEdge& edge) { return edge.proposed && edge.curve < 0; };

  // The graph of the edges the faces use; chains that are curved.
  CurvedGraph g(pattern);
  std::map<std::pair<int, int>, int> faceCount;
  for (const auto& f : pattern.faces)
    for (std::size_t k = 0; k < f.size(); ++k) ++faceCount[std::minmax(f[k], f[(k + 1) % f.size()])];
  std::map<int, std::vector<int>> verticesOfChain;
  for (std::size_t e = 0; e < pattern.edges.size(); ++e) {
    const io::CreaseEdge& edge = pattern.edges[e];
    const auto key = std::minmax(edge.v0, edge.v1);
    if (isBridge(edge) || !faceCount.count(key) || g.edgeBetween(edge.v0, edge.v1) >= 0) continue;
    g.addEdge(edge.v0, edge.v1, edge.curve, faceCount[key] == 2, static_cast<int>(e));
    if (edge.curve >= 0) {
      verticesOfChain[edge.curve].push_back(edge.v0);
      verticesOfChain[edge.curve].push_back(edge.v1);
    }
  }
  // Edges the faces use that the pattern does not list are straight (as are the import's bridges,
  // added below).
  std::set<std::pair<int, int>> bridges;
  for (const io::CreaseEdge& edge : pattern.edges)
    if (isBridge(edge)) bridges.insert(std::minmax(edge.v0, edge.v1));
  for (const auto& [key, count] : faceCount)
    if (g.edgeBetween(key.first, key.second) < 0 && !bridges.count(key)) g.addEdge(key.first, key.second, -1, count == 2, -1);
  for (const auto& [id, vs] : verticesOfChain) {
    Eigen::MatrixX2d pts(static_cast<Eigen::Index>(vs.size()), 2);
    for (std::size_t i = 0; i < vs.size(); ++i) pts.row(static_cast<Eigen::Index>(i)) = pattern.vertices2d.row(vs[i]);
    if (offLine(pts) > io::kStraightStrokeFraction * diagonal) g.curvedChains.insert(id);
  }
  for (std::size_t e = 0; e < pattern.edges.size(); ++e)
    if (pattern.edges[e].assignment == io::EdgeAssignment::Cut)
      result.notes.push_back({"edges[" + std::to_string(e) + "]",
                              "a cut (C): the composite has no slits, so its faces stay joined there"});

  std::vector<bool> drawnCorner(static_cast<std::size_t>(n), false);
  for (int v = 0; v < n; ++v) drawnCorner[static_cast<std::size_t>(v)] = !g.incident[static_cast<std::size_t>(v)].empty() && g.isCorner(v);
  // The import's bridges to islands are rulings it proposes: smooth, their ends free to slide along
  // their strokes (added after the corners were read, so their ends are not corners of the drawing).
  for (const auto& key : bridges)
    if (faceCount.count(key) && g.edgeBetween(key.first, key.second) < 0)
      g.addEdge(key.first, key.second, kChordChain, faceCount[key] == 2, -1);

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
    auto [one, two] = splitLoop(loops[f], a, b);
    loops[f] = std::move(one);
    loops.push_back(std::move(two));
    originOf.push_back(originOf[f]);
  };
  // A face with no ruling layout may still split into faces that have one: a straight ruling
  // between two of its corners (a hole beside a straight crease leaves S R R R — its arc, two
  // bridges and the crease — which a ruling from one bridge's foot on the hole to the other's on
  // the crease cuts into a cone S R R and a planar triangle). The shortest such chord, or nullopt.
  const auto chordIntoLayouts = [&g, &loops, eps](std::size_t f,
                                                  const std::vector<Side>& sides) -> std::optional<std::pair<int, int>> {
    std::vector<std::pair<double, std::pair<int, int>>> chords;
    for (std::size_t i = 0; i < sides.size(); ++i)
      for (std::size_t j = i + 1; j < sides.size(); ++j) {
        const int a = sides[i].vertices.front(), b = sides[j].vertices.front();
        if (g.edgeBetween(a, b) >= 0) continue;
        chords.push_back({(g.at(a) - g.at(b)).norm(), {a, b}});
      }
    std::sort(chords.begin(), chords.end());
    const std::vector<int>& loop = loops[f];
    for (const auto& candidate : chords) {
      const double length = candidate.first;
      const int a = candidate.second.first, b = candidate.second.second;
      // Each end once in the loop (else the split is ambiguous), and no other corner of the face on
      // the chord (chordFits does not see a chord running along a straight crease through one: it
      // would cut off a triangle of no area).
      if (std::count(loop.begin(), loop.end(), a) != 1 || std::count(loop.begin(), loop.end(), b) != 1) continue;
      if (!chordFits(g, loop, a, b, eps)) continue;
      const Eigen::Vector2d pa = g.at(a), ab = g.at(b) - pa;
      const bool throughAVertex = std::any_of(loop.begin(), loop.end(), [&g, &pa, &ab, a, b, length](int v) {
        if (v == a || v == b) return false;
        const double t = std::clamp((g.at(v) - pa).dot(ab) / ab.squaredNorm(), 0.0, 1.0);
        return (pa + t * ab - g.at(v)).norm() <= 1e-6 * length;
      });
      if (throughAVertex) continue;
      const auto [one, two] = splitLoop(loop, a, b);
      g.addEdge(a, b, kChordChain, true, -1);  // tried on the graph itself, and taken back
      const auto hasLayout = [&g, length](const std::vector<int>& half) {
        if (std::abs(spatial::loopSignedArea2(g.pattern.vertices2d, half)) <= 1e-9 * length * length) return false;
        const std::vector<Side> parts = sidesOf(g, half);
        if (parts.size() < 3) return false;
        const bool curved = std::any_of(parts.begin(), parts.end(), [](const Side& s) { return s.kind == SideKind::Curve; });
        return !curved || bestLayout(parts).has_value();  // a planar face, or a strip or cone
      };
      const bool fits = hasLayout(one) && hasLayout(two);
      g.removeLastEdge();
      if (fits) return candidate.second;
    }
    return std::nullopt;
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
        const bool allCurved = std::all_of(sides.begin(), sides.end(), [](const Side& s) { return s.kind == SideKind::Curve; });
        if (!layout && !allCurved) {
          if (const auto chord = chordIntoLayouts(f, sides)) {
            splitFace(f, chord->first, chord->second);
            changed = true;
            continue;
          }
        }
        if (!layout && allCurved)
          throw std::invalid_argument(faceName(f) + ": bounded by curves only (a closed curved crease, or a round "
                                                    "sheet's outline) with no straight crease in it, and every face needs "
                                                    "straight ends between its curved sides (S R S R, S R S or S R R): draw "
                                                    "three or more straight creases from a point inside out to the curve "
                                                    "(cones around that point), or, for a closed crease inside the sheet, "
                                                    "outline it (black in an SVG, B edges in a FOLD file) to cut it out as a hole");
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
  // A strip pairs its two curves by arc length (the splines are fitted with chord-length
  // parameters): where the curves are too unlike (a short side of a hole facing a long crease),
  // neighbouring rulings cross and the strip would lie on itself in its development. Such a face
  // gets one more ruling across its middle, until none crosses.
  for (bool changed = true; changed;) {
    changed = false;
    for (std::size_t f = 0; f < loops.size() && !changed; ++f) {
      const std::vector<Side> sides = sidesOf(g, loops[f]);
      const std::optional<Layout> layout = bestLayout(sides);
      if (!layout || layout->corners > 0) continue;
      auto [a, b] = chainsOf(sides, *layout);
      if (!rulingsCross(g, a, b)) continue;
      // A ruling from the middle of one side (by arc length) to the other, either way round.
      const auto fromMiddle = [&g, &loops, f, eps](ChainPolyline from, ChainPolyline to) -> std::optional<std::pair<int, int>> {
        if (from.vertices.size() < 3) return std::nullopt;
        std::size_t middle = static_cast<std::size_t>(std::lower_bound(from.t.begin(), from.t.end(), 0.5) - from.t.begin());
        middle = std::clamp<std::size_t>(middle, 1, from.vertices.size() - 2);
        from.joints = {middle};
        to.joints.clear();
        return proposeRuling(g, loops[f], from, to, eps);
      };
      std::optional<std::pair<int, int>> chord = fromMiddle(a, b);
      if (!chord) chord = fromMiddle(b, a);
      if (!chord)
        throw std::invalid_argument(faceName(f) + ": the rulings between its curved sides would cross (the two sides are "
                                                  "too unlike) and no straight ruling fits across its middle; draw a "
                                                  "straight crease across it");
      splitFace(f, chord->first, chord->second);
      resolveJoints();
      changed = true;
    }
  }
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
  bool guessed = false, curvedFullFolds = false;
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
    const bool curved = d.edges[e].type == EdgeType::Spline;
    // A full fold (±180°: Origami Simulator's opacity 1, a FOLD crease without an angle, a drawn
    // crease without one) lays the two sides of a crease onto each other, which only a straight
    // crease can: a curved one aims at ±kCurvedFullFoldDeg instead (a tryout's SVG of curved
    // creases ended every fold short of 180° by tens of degrees, its quality missed; at 90° the
    // same creases fold to their targets).
    if (curved && std::abs(*angle) >= 180.0) {
      angle = std::copysign(kCurvedFullFoldDeg, *angle);
      curvedFullFolds = true;
    }
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
  if (curvedFullFolds)
    result.notes.push_back({"fold angles", "curved creases cannot fold flat: those at a full fold (±180°) aim at ±" +
                                               std::to_string(static_cast<int>(kCurvedFullFoldDeg)) +
                                               "° (set another angle on the crease board)"});
  d.foldAmount = d.foldAngles.empty() ? 1.0 : 0.0;
  return result;
}

}  // namespace devsurf::models::composite
