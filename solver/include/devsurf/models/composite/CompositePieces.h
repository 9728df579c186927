#pragma once

#include <array>
#include <vector>

#include <Eigen/Core>

#include "devsurf/io/PolygonMesh.h"
#include "devsurf/models/composite/CompositeDesign.h"
#include "devsurf/models/composite/CompositeTopology.h"

namespace devsurf::models::composite {

/// The welded auxiliary mesh of a composite (000_… §3.1): its vertices, then every S edge's
/// interior samples (U = spans·samplesPerSpan + 1 parameters equally spaced, ends = the edge's
/// vertices), and per face its polygons — a planar face its corner polygon, a strip or cone one
/// quad (a(u_i), a(u_i+1), b(u_i+1), b(u_i)) per pair of consecutive rulings, a triangle where b
/// is the apex. Samples along a shared edge are shared by both faces. Used by
/// CompositeModel::quality and by the flat pieces below.
struct SampledComposite {
  std::vector<Eigen::Vector3d> points;
  /// Per face: its polygons as ids into points (consecutive repeats dropped; may hold fewer than
  /// three ids where a quad degenerates).
  std::vector<std::vector<std::vector<int>>> facePolygons;
  std::vector<int> edgeBase;   ///< per edge: id of its first interior sample (−1 for R edges)
  std::vector<int> edgeCount;  ///< per edge: samples including both ends (0 for R edges)
  /// Id of sample i (0 … edgeCount[e] − 1, from v0 to v1) of S edge e.
  int sampleId(const CompositeTopology& topology, int e, int i) const;
};

/// @param samplesPerSpan ≥ 1
SampledComposite sampleComposite(const CompositeDesign& design, const CompositeTopology& topology,
                                 int samplesPerSpan);

/// Flat pieces of a composite cut apart along its seams — interior S edges without a crease
/// condition in a composite without a development (CompositeFromStrips' covers) — each unfolded
/// from its own 3D edge lengths (triangle by triangle across shared edges, the first triangle
/// counter-clockwise), laid out one above the other with their longest direction along x, in
/// design units. A composite without seams is one piece.
struct FlatPieces {
  Eigen::MatrixX2d vertices;                ///< every piece's own copies of its points
  Eigen::MatrixX3d spaceVertices;           ///< where each of them is on the surface (its point)
  std::vector<io::PolygonFace> faces;       ///< quads and triangles, counter-clockwise
  std::vector<int> faceOfPolygon;           ///< composite face of each entry of faces
  std::vector<int> pieceOfVertex;           ///< piece of each vertex
  std::vector<int> pointOfVertex;           ///< its point in sampleComposite's points
  std::vector<std::array<int, 2>> gluePairs;  ///< the two copies of every point of a seam
  int pieces = 0;
  /// Largest |ℓ′ − ℓ| / ℓ over the edges of the flat pieces against the same edges in 3D (0 for a
  /// developable composite, up to the sampling's round-off).
  double lengthErrorMax = 0.0;
};

/// @param samplesPerSpan ≥ 1
/// @throws std::invalid_argument when a piece cannot be unfolded (a degenerate triangle).
FlatPieces unfoldPieces(const CompositeDesign& design, const CompositeTopology& topology, int samplesPerSpan = 10);

/// Whether edge e is a seam: an interior S edge without a crease condition in a composite
/// without a development (the pieces are cut apart along it).
bool isSeam(const CompositeDesign& design, const CompositeTopology& topology, int e);

/// Whether some edge is a seam (the composite is pieces to cut apart).
bool hasSeams(const CompositeDesign& design, const CompositeTopology& topology);

}  // namespace devsurf::models::composite
