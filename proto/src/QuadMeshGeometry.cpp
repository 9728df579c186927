#include <algorithm>
#include <cmath>

#include <Eigen/Geometry>

#include "devsurf/models/quad_mesh/FaceMeasures.h"
#include "devsurf/models/quad_mesh/SplineSurface.h"
#include "devsurf/proto/Geometry.h"

namespace devsurf::proto {

namespace qm = models::quad_mesh;

nlohmann::json quadMeshGeometryJson(const qm::QuadMeshModel& model, const qm::QuadMeshQuality& quality) {
  const qm::QuadMeshTopology& topology = model.topology();
  const Eigen::MatrixX3d mesh = model.meshVertices(), unfolding = model.unfoldingVertices();
  const auto& faces = topology.faces();
  const auto& edges = topology.edges();
  const int F = static_cast<int>(faces.size()), E = static_cast<int>(edges.size());
  Eigen::MatrixXi faceArray(F, 4), edgeArray(E, 2), edgeBoundary(E, 1);
  for (int f = 0; f < F; ++f)
    for (int k = 0; k < 4; ++k) faceArray(f, k) = faces[f][k];
  for (int e = 0; e < E; ++e) {
    edgeArray(e, 0) = edges[e][0];
    edgeArray(e, 1) = edges[e][1];
    edgeBoundary(e, 0) = topology.edgeOnBoundary()[e] ? 1 : 0;
  }
  Eigen::MatrixXd faceAreaError(F, 1);
  for (int f = 0; f < F; ++f) {
    const double a = qm::faceArea(mesh, faces[f]), b = qm::faceArea(unfolding, faces[f]);
    faceAreaError(f, 0) = a > 0 ? (b - a) / a : 0.0;
  }
  const qm::QuadMeshDesign design = model.design();
  std::vector<std::array<int, 2>> glueMesh, glueUnfolding;
  for (const qm::GluePair& g : design.glue) (g.on == qm::MeshSide::Mesh ? glueMesh : glueUnfolding).push_back({g.a, g.b});
  auto pairArray = [](const std::vector<std::array<int, 2>>& pairs) {
    Eigen::MatrixXi m(static_cast<Eigen::Index>(pairs.size()), 2);
    for (std::size_t i = 0; i < pairs.size(); ++i) m.row(static_cast<Eigen::Index>(i)) << pairs[i][0], pairs[i][1];
    return m;
  };
  nlohmann::json j = {{"kind", "quad_mesh"},
                      {"mesh", float32Array(mesh)},
                      {"unfolding", float32Array(unfolding)},
                      {"faces", int32Array(faceArray)},
                      {"edges", int32Array(edgeArray)},
                      {"edge_boundary", int32Array(edgeBoundary)},
                      {"edge_length_error", float32Array(quality.edgeLengthError)},
                      {"face_area_error", float32Array(faceAreaError)},
                      {"glue", int32Array(pairArray(glueMesh))},
                      {"glue_unfolding", int32Array(pairArray(glueUnfolding))},
                      {"variable", qm::variableMeshesName(design.variable)},
                      {"planar", design.unfoldingPlanar},
                      {"conformal", design.conformal},
                      {"curvature", nullptr}};
  if (design.gaussImage) {
    const qm::QuadMeshCurvature c = model.curvature();
    Eigen::MatrixXd rulings = Eigen::MatrixXd::Zero(F, 6);
    for (int f = 0; f < F; ++f) {
      const int n = qm::faceSize(faces[f]);
      Eigen::Vector3d centre = Eigen::Vector3d::Zero();
      for (int k = 0; k < n; ++k) centre += mesh.row(faces[f][k]).transpose();
      centre /= n;
      double size = 0.0;
      for (int k = 0; k < n; ++k) size = std::max(size, (mesh.row(faces[f][k]).transpose() - centre).norm());
      const double k1 = std::max(std::abs(c.kappa1[f]), std::abs(c.kappa2[f]));
      const bool developable = std::abs(c.gauss[f]) <= 0.05 * k1 * k1 || k1 == 0.0;
      const Eigen::Vector3d half = developable ? Eigen::Vector3d(0.5 * size * c.ruling.row(f).transpose())
                                               : Eigen::Vector3d::Zero();
      rulings.row(f) << (centre - half).transpose(), (centre + half).transpose();
    }
    j["curvature"] = {{"gauss", float32Array(c.gauss)},   {"mean", float32Array(c.mean)},
                      {"kappa1", float32Array(c.kappa1)}, {"kappa2", float32Array(c.kappa2)},
                      {"rulings", float32Array(rulings)}};
  }
  if (design.control) j["spline"] = splineGeometryJson(*design.control, model.controlPoints());
  return j;
}

nlohmann::json splineGeometryJson(const qm::ControlNet& net, const Eigen::MatrixX3d& points) {
  qm::SplineAnalysisOptions options;
  options.samplesPerSpan = 6;
  const qm::SplineSurfaceAnalysis a = qm::analyzeSplineSurface(net, points, options);
  // The control mesh's edges: every grid edge of every patch, once.
  std::vector<std::array<int, 2>> edges;
  for (const qm::ControlPatch& p : qm::controlPatches(net))
    for (int r = 0; r < p.rows; ++r)
      for (int c = 0; c < p.columns; ++c) {
        const int i = p.indices[static_cast<std::size_t>(r * p.columns + c)];
        if (c + 1 < p.columns) edges.push_back({i, p.indices[static_cast<std::size_t>(r * p.columns + c + 1)]});
        if (r + 1 < p.rows) edges.push_back({i, p.indices[static_cast<std::size_t>((r + 1) * p.columns + c)]});
      }
  for (auto& e : edges)
    if (e[0] > e[1]) std::swap(e[0], e[1]);
  std::sort(edges.begin(), edges.end());
  edges.erase(std::unique(edges.begin(), edges.end()), edges.end());
  Eigen::MatrixXi edgeArray(static_cast<Eigen::Index>(edges.size()), 2);
  for (std::size_t e = 0; e < edges.size(); ++e) edgeArray.row(static_cast<Eigen::Index>(e)) << edges[e][0], edges[e][1];
  const double d2 = a.diameter * a.diameter;
  nlohmann::json patches = nlohmann::json::array(), rulings = nlohmann::json::array();
  for (std::size_t p = 0; p < a.samples.size(); ++p)
    patches.push_back({{"rows", a.sampleGridSize[p][0]},
                       {"columns", a.sampleGridSize[p][1]},
                       {"points", float32Array(a.samples[p])},
                       {"gauss_scaled", float32Array(a.gauss[p] * d2)}});
  for (const Eigen::MatrixX3d& r : a.rulings) rulings.push_back(float32Array(r));
  return {{"control", float32Array(points)},
          {"control_edges", int32Array(edgeArray)},
          {"rounds", net.rounds},
          {"patches", std::move(patches)},
          {"rulings", std::move(rulings)},
          {"gauss_max_scaled", a.gaussMaxScaled},
          {"gauss_mean_scaled", a.gaussMeanScaled},
          {"shared_sides", a.sharedSides},
          {"normal_jump_max_deg", a.normalJumpMaxDegrees}};
}

}  // namespace devsurf::proto
