// The sampled mesh of a composite and its flat pieces cut along seams (issue 15: a cover's cutting
// pattern).
#include "devsurf/models/composite/CompositePieces.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <numeric>
#include <stdexcept>
#include <string>

#include "devsurf/spatial/IsometricUnfolding.h"

namespace devsurf::models::composite {

int SampledComposite::sampleId(const CompositeTopology& topology, int e, int i) const {
  const int U = edgeCount[static_cast<std::size_t>(e)];
  const auto ends = topology.edgeVertices(e);
  if (i == 0) return ends[0];
  if (i == U - 1) return ends[1];
  return edgeBase[static_cast<std::size_t>(e)] + i - 1;
}

SampledComposite sampleComposite(const CompositeDesign& design, const CompositeTopology& topology,
                                 int samplesPerSpan) {
  if (samplesPerSpan < 1) throw std::invalid_argument("samplesPerSpan: need at least 1 sample per span");
  SampledComposite s;
  for (int v = 0; v < topology.numVertices(); ++v) s.points.push_back(design.vertices.row(v).transpose());
  s.edgeBase.assign(static_cast<std::size_t>(topology.numEdges()), -1);
  s.edgeCount.assign(static_cast<std::size_t>(topology.numEdges()), 0);
  for (int e = 0; e < topology.numEdges(); ++e) {
    if (topology.edgeType(e) != EdgeType::Spline) continue;
    const spline::BSplineCurve& c = design.edges[static_cast<std::size_t>(e)].curve;
    const int U = c.knots.numSpans() * samplesPerSpan + 1;
    s.edgeCount[static_cast<std::size_t>(e)] = U;
    s.edgeBase[static_cast<std::size_t>(e)] = static_cast<int>(s.points.size());
    const Eigen::MatrixXd samples = c.evaluate(c.knots.uniformSamples(U), 0);
    for (int i = 1; i + 1 < U; ++i) s.points.push_back(samples.row(i).transpose());
  }
  auto sampleOf = [&s, &topology](const OrientedEdge& oe, int i) {
    const int U = s.edgeCount[static_cast<std::size_t>(oe.edge)];
    return s.sampleId(topology, oe.edge, oe.reversed ? U - 1 - i : i);
  };
  s.facePolygons.resize(static_cast<std::size_t>(topology.numFaces()));
  for (int f = 0; f < topology.numFaces(); ++f) {
    const FaceInfo& info = topology.face(f);
    auto& polygons = s.facePolygons[static_cast<std::size_t>(f)];
    if (info.type == FaceType::Planar) {
      polygons.push_back(info.corners);
      continue;
    }
    const int U = s.edgeCount[static_cast<std::size_t>(info.a.edge)];
    for (int i = 0; i + 1 < U; ++i) {
      const int a0 = sampleOf(info.a, i), a1 = sampleOf(info.a, i + 1);
      const int b0 = info.type == FaceType::Cone ? info.apex : sampleOf(info.b, i);
      const int b1 = info.type == FaceType::Cone ? info.apex : sampleOf(info.b, i + 1);
      std::vector<int> poly;
      for (const int id : {a0, a1, b1, b0})
        if (poly.empty() || poly.back() != id) poly.push_back(id);
      while (poly.size() > 1 && poly.front() == poly.back()) poly.pop_back();
      polygons.push_back(std::move(poly));
    }
  }
  return s;
}

bool isSeam(const CompositeDesign& design, const CompositeTopology& topology, int e) {
  return design.developmentSamples == 0 && topology.edgeType(e) == EdgeType::Spline &&
         design.edges[static_cast<std::size_t>(e)].crease == CreaseKind::None && topology.edge(e).interior();
}

bool hasSeams(const CompositeDesign& design, const CompositeTopology& topology) {
  for (int e = 0; e < topology.numEdges(); ++e)
    if (isSeam(design, topology, e)) return true;
  return false;
}

FlatPieces unfoldPieces(const CompositeDesign& design, const CompositeTopology& topology, int samplesPerSpan) {
  const SampledComposite s = sampleComposite(design, topology, samplesPerSpan);
  const int numFaces = topology.numFaces();

  // Pieces: faces joined across every shared edge that is not a seam.
  std::vector<int> parent(static_cast<std::size_t>(numFaces));
  std::iota(parent.begin(), parent.end(), 0);
  auto find = [&parent](int f) {
    while (parent[static_cast<std::size_t>(f)] != f)
      f = parent[static_cast<std::size_t>(f)] = parent[static_cast<std::size_t>(parent[static_cast<std::size_t>(f)])];
    return f;
  };
  std::vector<bool> seamPoint(s.points.size(), false);
  for (int e = 0; e < topology.numEdges(); ++e) {
    const EdgeInfo& info = topology.edge(e);
    if (!info.interior()) continue;
    if (isSeam(design, topology, e)) {
      for (int i = 0; i < s.edgeCount[static_cast<std::size_t>(e)]; ++i)
        seamPoint[static_cast<std::size_t>(s.sampleId(topology, e, i))] = true;
      continue;
    }
    parent[static_cast<std::size_t>(find(info.faces[0]))] = find(info.faces[1]);
  }
  std::map<int, int> pieceNumber;  // pieces numbered by their first face
  std::vector<std::vector<int>> polygons;
  std::vector<int> pieceOfPolygon, faceOfInput;
  for (int f = 0; f < numFaces; ++f)
    for (const std::vector<int>& poly : s.facePolygons[static_cast<std::size_t>(f)]) {
      if (poly.size() < 3) continue;
      polygons.push_back(poly);
      pieceOfPolygon.push_back(pieceNumber.emplace(find(f), static_cast<int>(pieceNumber.size())).first->second);
      faceOfInput.push_back(f);
    }
  const spatial::FlatLayout layout = spatial::unfoldPieces(s.points, polygons, pieceOfPolygon);

  FlatPieces out;
  out.pieces = layout.pieces;
  out.vertices = layout.vertices;
  out.pieceOfVertex = layout.pieceOfVertex;
  out.pointOfVertex = layout.pointOfVertex;
  out.lengthErrorMax = layout.lengthErrorMax;
  out.spaceVertices.resize(static_cast<Eigen::Index>(out.pointOfVertex.size()), 3);
  for (std::size_t k = 0; k < out.pointOfVertex.size(); ++k)
    out.spaceVertices.row(static_cast<Eigen::Index>(k)) = s.points[static_cast<std::size_t>(out.pointOfVertex[k])].transpose();
  for (std::size_t k = 0; k < layout.polygons.size(); ++k) {
    const std::vector<int>& ids = layout.polygons[k];
    if (ids.empty()) continue;
    if (ids.size() <= 4) {
      out.faces.push_back({{ids[0], ids[1], ids[2], ids.size() == 4 ? ids[3] : -1}});
      out.faceOfPolygon.push_back(faceOfInput[k]);
    } else {  // a planar N-gon: a fan
      for (std::size_t c = 1; c + 1 < ids.size(); ++c) {
        out.faces.push_back({{ids[0], ids[c], ids[c + 1], -1}});
        out.faceOfPolygon.push_back(faceOfInput[k]);
      }
    }
  }
  // Glue pairs: the copies of a seam point in the pieces it joins.
  std::map<int, std::vector<int>> copiesOfPoint;
  for (std::size_t k = 0; k < out.pointOfVertex.size(); ++k)
    if (seamPoint[static_cast<std::size_t>(out.pointOfVertex[k])]) copiesOfPoint[out.pointOfVertex[k]].push_back(static_cast<int>(k));
  for (const auto& [point, copies] : copiesOfPoint)
    for (std::size_t k = 1; k < copies.size(); ++k) out.gluePairs.push_back({{copies[0], copies[k]}});
  return out;
}

}  // namespace devsurf::models::composite
