// CompositeModel::validateDesign: what a design must be before a model is built from it, each
// failure naming the field.

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

#include "devsurf/models/HandleValidation.h"
#include "devsurf/models/composite/CompositeModel.h"
#include "devsurf/models/composite/CompositeTopology.h"

namespace devsurf::models::composite {
namespace {

std::string refPath(const std::string& list, std::size_t i) { return list + "[" + std::to_string(i) + "]"; }

}  // namespace

void CompositeModel::validateDesign(const CompositeDesign& design) {
  if (design.vertices.rows() > 0 && !design.vertices.allFinite()) {
    for (Eigen::Index v = 0; v < design.vertices.rows(); ++v)
      if (!design.vertices.row(v).allFinite())
        throw std::invalid_argument(refPath("vertices", static_cast<std::size_t>(v)) + ": coordinates must be finite");
  }
  if (design.developmentSamples < 0 || design.developmentSamples > 64)
    throw std::invalid_argument("development.samples: must be between 1 and 64 (0: no development), got " +
                                std::to_string(design.developmentSamples));
  // An S edge whose control points are all one point has no length: no strip, no crease to fold
  // (the solve would divide by it).
  for (std::size_t e = 0; e < design.edges.size(); ++e) {
    const CompositeEdge& edge = design.edges[e];
    if (edge.type != EdgeType::Spline || edge.curve.points.rows() < 2 || !edge.curve.points.allFinite()) continue;
    const Eigen::MatrixXd& p = edge.curve.points;
    const double span = (p.colwise().maxCoeff() - p.colwise().minCoeff()).norm();
    const double size = design.vertices.rows() > 0 && design.vertices.allFinite()
                            ? (design.vertices.colwise().maxCoeff() - design.vertices.colwise().minCoeff()).norm()
                            : 0.0;
    if (span <= 1e-12 * std::max(size, 1e-300))
      throw std::invalid_argument(refPath("edges", e) + ".points: every control point is the same point; the edge has no length");
  }
  const CompositeTopology topology(design);
  auto checkRef = [&](const PointRef& r, const std::string& path) {
    if (r.vertex >= 0) {
      if (r.vertex >= topology.numVertices())
        throw std::invalid_argument(path + ".vertex: vertex " + std::to_string(r.vertex) + " does not exist (" +
                                    std::to_string(topology.numVertices()) + " vertices)");
      return;
    }
    if (r.edge < 0 || r.edge >= topology.numEdges())
      throw std::invalid_argument(path + ".edge: edge " + std::to_string(r.edge) + " does not exist (" +
                                  std::to_string(topology.numEdges()) + " edges)");
    if (topology.edgeType(r.edge) != EdgeType::Spline)
      throw std::invalid_argument(path + ".edge: edge " + std::to_string(r.edge) +
                                  " is a ruling (R) and has no control points; refer to its vertices");
    const int n = topology.interiorPoints(r.edge) + 2;
    if (r.index < 0 || r.index >= n)
      throw std::invalid_argument(path + ".index: " + std::to_string(r.index) + " is out of range (edge " +
                                  std::to_string(r.edge) + " has " + std::to_string(n) +
                                  " control points; 0 and " + std::to_string(n - 1) + " are its vertices)");
  };
  validateUserConstraints(design.fixed, design.handles, checkRef);
  if (!(design.foldAmount >= 0.0 && design.foldAmount <= 1.0))
    throw std::invalid_argument("fold_amount: must lie in [0, 1]");
  for (std::size_t i = 0; i < design.foldAngles.size(); ++i) {
    const FoldAngleTarget& t = design.foldAngles[i];
    const std::string path = refPath("fold_angles", i);
    if (t.edge < 0 || t.edge >= topology.numEdges())
      throw std::invalid_argument(path + ".edge: edge " + std::to_string(t.edge) + " does not exist");
    if (!topology.edge(t.edge).interior())
      throw std::invalid_argument(path + ".edge: edge " + std::to_string(t.edge) + " is on the boundary; a fold joins two faces");
    if (!(std::abs(t.angleDeg) <= 180.0)) throw std::invalid_argument(path + ".angle: must lie in [-180, 180] degrees");
    if (!hasFoldHinge(topology, t.edge, t.end))
      throw std::invalid_argument(path + ".end: edge " + std::to_string(t.edge) + " has no hinge at end " + std::to_string(t.end) +
                                  (topology.edgeType(t.edge) == EdgeType::Ruling ? " (an R edge is one hinge, end 0)"
                                                                                 : " (a face has no ruling there)"));
    for (std::size_t j = 0; j < i; ++j)
      if (design.foldAngles[j].edge == t.edge && design.foldAngles[j].end == t.end)
        throw std::invalid_argument(path + ": repeats fold_angles[" + std::to_string(j) + "]");
  }

  const DevelopmentDomain& domain = design.developmentDomain;
  if (design.developmentSamples == 0 && (!domain.empty() || !design.developmentSeam.empty()))
    throw std::invalid_argument("development.samples: a domain or a seam needs a development (samples ≥ 1)");
  if (design.developmentVertices.rows() > 0 && !design.developmentVertices.allFinite())
    for (Eigen::Index i = 0; i < design.developmentVertices.rows(); ++i)
      if (!design.developmentVertices.row(i).allFinite())
        throw std::invalid_argument(refPath("development.vertices", static_cast<std::size_t>(i)) +
                                    ": coordinates must be finite");
  for (std::size_t i = 0; i < design.tangentContinuity.size(); ++i) {
    const auto& pair = design.tangentContinuity[i];
    const std::string path = refPath("tangent_continuity", i);
    for (int k = 0; k < 2; ++k) {
      const int e = pair[static_cast<std::size_t>(k)];
      if (e < 0 || e >= topology.numEdges())
        throw std::invalid_argument(path + "[" + std::to_string(k) + "]: edge " + std::to_string(e) + " does not exist");
      if (topology.edgeType(e) != EdgeType::Spline)
        throw std::invalid_argument(path + "[" + std::to_string(k) + "]: edge " + std::to_string(e) +
                                    " is a ruling; tangent continuity joins S edges");
    }
    const auto a = topology.edgeVertices(pair[0]), b = topology.edgeVertices(pair[1]);
    int shared = 0;
    for (int u : a)
      for (int w : b) shared += u == w ? 1 : 0;
    if (pair[0] == pair[1] || shared != 1)
      throw std::invalid_argument(path + ": edges " + std::to_string(pair[0]) + " and " + std::to_string(pair[1]) +
                                  " must be two S edges sharing exactly one vertex");
  }
  std::vector<bool> seamSeen(static_cast<std::size_t>(topology.numEdges()), false);
  for (std::size_t i = 0; i < design.developmentSeam.size(); ++i) {
    const int e = design.developmentSeam[i];
    const std::string path = refPath("development.seam", i);
    if (e < 0 || e >= topology.numEdges())
      throw std::invalid_argument(path + ": edge " + std::to_string(e) + " does not exist (" +
                                  std::to_string(topology.numEdges()) + " edges)");
    if (!topology.edge(e).interior())
      throw std::invalid_argument(path + ": edge " + std::to_string(e) + " is on the boundary; a seam cuts interior edges");
    if (seamSeen[static_cast<std::size_t>(e)])
      throw std::invalid_argument(path + ": edge " + std::to_string(e) + " is listed twice");
    seamSeen[static_cast<std::size_t>(e)] = true;
  }
  for (std::size_t c = 0; c < domain.boundary.size(); ++c) {
    const DomainCurve& curve = domain.boundary[c];
    const std::string path = refPath("development.domain.boundary", c);
    const Eigen::Index need = curve.closed ? 3 : 2;
    if (curve.points.rows() < need)
      throw std::invalid_argument(path + ".points: needs at least " + std::to_string(need) + " points");
    if (!curve.points.allFinite()) throw std::invalid_argument(path + ".points: coordinates must be finite");
    for (Eigen::Index i = 0; i < curve.points.rows(); ++i) {
      const Eigen::Index j = (i + 1) % curve.points.rows();
      if ((j != 0 || curve.closed) && (curve.points.row(i) - curve.points.row(j)).norm() == 0.0)
        throw std::invalid_argument(path + ".points[" + std::to_string(j) + "]: repeats the previous point");
    }
  }
  std::vector<bool> cornerSeen(static_cast<std::size_t>(topology.numVertices()), false);
  for (std::size_t c = 0; c < domain.corners.size(); ++c) {
    const DomainCorner& corner = domain.corners[c];
    const std::string path = refPath("development.domain.corners", c);
    if (corner.vertex < 0 || corner.vertex >= topology.numVertices())
      throw std::invalid_argument(path + ".vertex: vertex " + std::to_string(corner.vertex) + " does not exist (" +
                                  std::to_string(topology.numVertices()) + " vertices)");
    if (cornerSeen[static_cast<std::size_t>(corner.vertex)])
      throw std::invalid_argument(path + ".vertex: vertex " + std::to_string(corner.vertex) + " is pinned twice");
    cornerSeen[static_cast<std::size_t>(corner.vertex)] = true;
    if (!corner.at.allFinite()) throw std::invalid_argument(path + ".at: coordinates must be finite");
  }
}

}  // namespace devsurf::models::composite
