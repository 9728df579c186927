// The sampled mesh of a composite and its flat pieces cut along seams (issue 15: a cover's cutting
// pattern).
#include "devsurf/models/composite/CompositePieces.h"

#include <algorithm>
#include <cmath>
#include <deque>
#include <map>
#include <numeric>
#include <stdexcept>
#include <string>

#include <Eigen/Eigenvalues>

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

namespace {

/// The third corner of a triangle unfolded onto the side of edge (p, q) away from `away`, at
/// distances dp from p and dq from q.
Eigen::Vector2d unfoldCorner(const Eigen::Vector2d& p, const Eigen::Vector2d& q, double dp, double dq,
                             double side) {
  const Eigen::Vector2d pq = q - p;
  const double d = pq.norm();
  if (!(d > 0.0)) throw std::invalid_argument("unfoldPieces: a sampled edge has zero length");
  const double along = (dp * dp - dq * dq + d * d) / (2.0 * d);
  const double across = std::sqrt(std::max(0.0, dp * dp - along * along));
  const Eigen::Vector2d u = pq / d, n(-u.y(), u.x());
  return p + along * u + side * across * n;
}

double cross2(const Eigen::Vector2d& a, const Eigen::Vector2d& b) { return a.x() * b.y() - a.y() * b.x(); }

}  // namespace

FlatPieces unfoldPieces(const CompositeDesign& design, const CompositeTopology& topology, int samplesPerSpan) {
  const SampledComposite s = sampleComposite(design, topology, samplesPerSpan);
  const int numFaces = topology.numFaces();

  // Pieces: faces joined across every shared edge that is not a seam.
  std::vector<int> parent(static_cast<std::size_t>(numFaces));
  std::iota(parent.begin(), parent.end(), 0);
  auto find = [&parent](int f) {
    while (parent[static_cast<std::size_t>(f)] != f) f = parent[static_cast<std::size_t>(f)] = parent[static_cast<std::size_t>(parent[static_cast<std::size_t>(f)])];
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
  std::map<int, int> pieceIndex;
  std::vector<int> pieceOfFace(static_cast<std::size_t>(numFaces));
  for (int f = 0; f < numFaces; ++f) {
    const int root = find(f);
    if (!pieceIndex.count(root)) pieceIndex.emplace(root, static_cast<int>(pieceIndex.size()));
    pieceOfFace[static_cast<std::size_t>(f)] = pieceIndex[root];
  }

  FlatPieces out;
  out.pieces = static_cast<int>(pieceIndex.size());
  std::vector<Eigen::Vector2d> flat;
  std::vector<std::pair<int, int>> copyKey;  // (piece, point) of every flat vertex
  std::map<std::pair<int, int>, int> copyOf;
  std::vector<double> offsets;
  double cursorY = 0.0;
  for (int piece = 0; piece < out.pieces; ++piece) {
    // The piece's triangles (quads split along a0–b1 for unfolding; the faces keep the quads).
    struct Triangle {
      std::array<int, 3> ids;
    };
    std::vector<Triangle> triangles;
    std::vector<std::pair<int, std::vector<int>>> polygons;  // (face, ids)
    for (int f = 0; f < numFaces; ++f) {
      if (pieceOfFace[static_cast<std::size_t>(f)] != piece) continue;
      for (const std::vector<int>& poly : s.facePolygons[static_cast<std::size_t>(f)]) {
        if (poly.size() < 3) continue;
        polygons.emplace_back(f, poly);
        for (std::size_t k = 1; k + 1 < poly.size(); ++k) triangles.push_back({{poly[0], poly[k], poly[k + 1]}});
      }
    }
    if (triangles.empty()) continue;
    // Unfold breadth-first across shared triangle edges.
    std::map<int, Eigen::Vector2d> at;
    std::map<std::pair<int, int>, std::vector<int>> edgeTriangles;
    for (std::size_t t = 0; t < triangles.size(); ++t)
      for (int k = 0; k < 3; ++k) {
        const int i = triangles[t].ids[static_cast<std::size_t>(k)], j = triangles[t].ids[static_cast<std::size_t>((k + 1) % 3)];
        edgeTriangles[std::minmax(i, j)].push_back(static_cast<int>(t));
      }
    auto length = [&s](int i, int j) { return (s.points[static_cast<std::size_t>(i)] - s.points[static_cast<std::size_t>(j)]).norm(); };
    {
      const auto& first = triangles.front().ids;
      at[first[0]] = Eigen::Vector2d::Zero();
      at[first[1]] = Eigen::Vector2d(length(first[0], first[1]), 0.0);
      at[first[2]] = unfoldCorner(at[first[0]], at[first[1]], length(first[0], first[2]), length(first[1], first[2]), 1.0);
    }
    std::vector<bool> placed(triangles.size(), false);
    placed[0] = true;
    std::deque<int> queue{0};
    while (!queue.empty()) {
      const int t = queue.front();
      queue.pop_front();
      const auto& ids = triangles[static_cast<std::size_t>(t)].ids;
      for (int k = 0; k < 3; ++k) {
        const int i = ids[static_cast<std::size_t>(k)], j = ids[static_cast<std::size_t>((k + 1) % 3)];
        const int opposite = ids[static_cast<std::size_t>((k + 2) % 3)];
        for (const int n : edgeTriangles[std::minmax(i, j)]) {
          if (placed[static_cast<std::size_t>(n)]) continue;
          placed[static_cast<std::size_t>(n)] = true;
          queue.push_back(n);
          const auto& other = triangles[static_cast<std::size_t>(n)].ids;
          const int third = other[0] != i && other[0] != j ? other[0] : (other[1] != i && other[1] != j ? other[1] : other[2]);
          if (at.count(third)) continue;  // reached before (a closed loop of triangles)
          // Across edge (i, j) from `opposite`.
          const double side = cross2(at[j] - at[i], at[opposite] - at[i]) > 0.0 ? -1.0 : 1.0;
          at[third] = unfoldCorner(at[i], at[j], length(i, third), length(j, third), side);
        }
      }
    }
    if (at.size() < 2) continue;
    // Longest direction along x, then stacked above the previous piece.
    Eigen::Vector2d mean = Eigen::Vector2d::Zero();
    for (const auto& [id, p] : at) mean += p;
    mean /= static_cast<double>(at.size());
    Eigen::Matrix2d cov = Eigen::Matrix2d::Zero();
    for (const auto& [id, p] : at) cov += (p - mean) * (p - mean).transpose();
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> eig(cov);
    Eigen::Vector2d axis = eig.eigenvectors().col(1);
    const Eigen::Matrix2d rotation = (Eigen::Matrix2d() << axis.x(), axis.y(), -axis.y(), axis.x()).finished();
    double minY = 1e300, maxY = -1e300, minX = 1e300;
    for (auto& [id, p] : at) {
      p = rotation * (p - mean);  // a rotation: orientation kept
      minY = std::min(minY, p.y());
      maxY = std::max(maxY, p.y());
      minX = std::min(minX, p.x());
    }
    const double gap = 0.15 * std::max(maxY - minY, 1e-12);
    for (auto& [id, p] : at) {
      p = Eigen::Vector2d(p.x() - minX, p.y() - minY + cursorY);
      copyOf[{piece, id}] = static_cast<int>(flat.size());
      flat.push_back(p);
      copyKey.emplace_back(piece, id);
    }
    cursorY += maxY - minY + gap;
    for (const auto& [face, poly] : polygons) {
      std::vector<int> ids;
      for (const int id : poly) ids.push_back(copyOf.at({piece, id}));
      if (ids.size() <= 4) {
        io::PolygonFace pf{{ids[0], ids[1], ids[2], ids.size() == 4 ? ids[3] : -1}};
        out.faces.push_back(pf);
        out.faceOfPolygon.push_back(face);
      } else {  // a planar N-gon: a fan
        for (std::size_t k = 1; k + 1 < ids.size(); ++k) {
          out.faces.push_back({{ids[0], ids[k], ids[k + 1], -1}});
          out.faceOfPolygon.push_back(face);
        }
      }
    }
  }
  out.vertices.resize(static_cast<Eigen::Index>(flat.size()), 2);
  out.pieceOfVertex.resize(flat.size());
  out.pointOfVertex.resize(flat.size());
  for (std::size_t k = 0; k < flat.size(); ++k) {
    out.vertices.row(static_cast<Eigen::Index>(k)) = flat[k].transpose();
    out.pieceOfVertex[k] = copyKey[k].first;
    out.pointOfVertex[k] = copyKey[k].second;
  }
  // Glue pairs: the copies of a seam point in the two pieces it joins.
  std::map<int, std::vector<int>> copiesOfPoint;
  for (std::size_t k = 0; k < copyKey.size(); ++k)
    if (seamPoint[static_cast<std::size_t>(copyKey[k].second)]) copiesOfPoint[copyKey[k].second].push_back(static_cast<int>(k));
  for (const auto& [point, copies] : copiesOfPoint)
    for (std::size_t k = 1; k < copies.size(); ++k) out.gluePairs.push_back({{copies[0], copies[k]}});
  // Edge lengths against 3D.
  for (const io::PolygonFace& face : out.faces) {
    const int n = io::cornerCount(face);
    for (int k = 0; k < n; ++k) {
      const int i = face[static_cast<std::size_t>(k)], j = face[static_cast<std::size_t>((k + 1) % n)];
      const double l3 = (s.points[static_cast<std::size_t>(copyKey[static_cast<std::size_t>(i)].second)] -
                         s.points[static_cast<std::size_t>(copyKey[static_cast<std::size_t>(j)].second)]).norm();
      const double l2 = (out.vertices.row(i) - out.vertices.row(j)).norm();
      if (l3 > 0.0) out.lengthErrorMax = std::max(out.lengthErrorMax, std::abs(l2 - l3) / l3);
    }
  }
  return out;
}

}  // namespace devsurf::models::composite
