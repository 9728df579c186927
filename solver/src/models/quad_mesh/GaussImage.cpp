#include "devsurf/models/quad_mesh/GaussImage.h"
#include "devsurf/models/quad_mesh/FaceMeasures.h"

#include <memory>
#include <stdexcept>
#include <string>

#include <Eigen/Geometry>

#include "devsurf/engine/Normalization.h"
#include "devsurf/engine/Problem.h"
#include "devsurf/terms/GaussImageNormalTerm.h"
#include "devsurf/terms/NormalDirectionAnchorTerm.h"
#include "devsurf/terms/PolylineFairnessTerm.h"
#include "devsurf/terms/ShapeOperatorSymmetryTerm.h"

namespace devsurf::models::quad_mesh {
namespace {

}  // namespace

Eigen::MatrixX3d solveGaussImage(const Eigen::MatrixX3d& mesh,
                                 const std::vector<std::array<int, 4>>& faces,
                                 const std::vector<std::array<int, 3>>& polylineTriples,
                                 const GaussImageOptions& options, engine::SolveSummary* summary) {
  const int numVertices = static_cast<int>(mesh.rows());
  if (!mesh.allFinite()) throw std::invalid_argument("solveGaussImage: mesh is not finite");
  std::vector<char> used(numVertices, 0);
  for (int f = 0; f < static_cast<int>(faces.size()); ++f) {
    const int n = faces[f][3] < 0 ? 3 : 4;
    for (int c = 0; c < n; ++c) {
      if (faces[f][c] < 0 || faces[f][c] >= numVertices)
        throw std::invalid_argument("solveGaussImage: face " + std::to_string(f) +
                                    " has a vertex index out of range");
      used[faces[f][c]] = 1;
    }
  }
  for (int v = 0; v < numVertices; ++v)
    if (!used[v])
      throw std::invalid_argument("solveGaussImage: vertex " + std::to_string(v) +
                                  " is in no face");
  for (int t = 0; t < static_cast<int>(polylineTriples.size()); ++t) {
    const auto& [i, j, k] = polylineTriples[t];
    if (i < 0 || j < 0 || k < 0 || i >= numVertices || j >= numVertices || k >= numVertices ||
        i == j || j == k || i == k)
      throw std::invalid_argument("solveGaussImage: polyline triple " + std::to_string(t) +
                                  " is invalid");
  }

  // M at unit size (weights mean the same for every scene); normals do not change with scale.
  Eigen::MatrixX3d unitMesh = mesh;
  engine::Normalization::fromPoints(mesh).normalizeRows(unitMesh);

  engine::Problem problem;
  const int meshBlock = problem.addBlock("mesh", 3 * numVertices);
  const int normalBlock = problem.addBlock("normals", 3 * numVertices);
  problem.layout().setBlockFixed(meshBlock);
  const Eigen::MatrixX3d initial = unitVertexNormals(unitMesh, faces);
  std::vector<int> meshOffsets(numVertices), normalOffsets(numVertices);
  const int meshBase = problem.layout().block(meshBlock).offset;
  const int normalBase = problem.layout().block(normalBlock).offset;
  for (int v = 0; v < numVertices; ++v) {
    meshOffsets[v] = meshBase + 3 * v;
    normalOffsets[v] = normalBase + 3 * v;
    problem.x().segment<3>(meshOffsets[v]) = unitMesh.row(v).transpose();
    problem.x().segment<3>(normalOffsets[v]) = initial.row(v).transpose();
  }

  problem.addTerm(std::make_unique<terms::GaussImageNormalTerm>("gauss image normals", faces,
                                                                meshOffsets, normalOffsets),
                  options.normalWeight, engine::Strength::Hard);
  problem.addTerm(std::make_unique<terms::ShapeOperatorSymmetryTerm>(
                      "shape operator symmetry", faces, meshOffsets, normalOffsets),
                  options.symmetryWeight, engine::Strength::Hard);
  if (!polylineTriples.empty() && options.fairnessWeight > 0.0)
    problem.addTerm(
        std::make_unique<terms::PolylineFairnessTerm>("normal fairness", polylineTriples, normalOffsets),
        options.fairnessWeight, engine::Strength::Soft);

  if (options.anchorWeight > 0.0)
    problem.addTerm(std::make_unique<terms::NormalDirectionAnchorTerm>("normal direction", initial,
                                                                normalOffsets),
                    options.anchorWeight, engine::Strength::Soft);

  engine::GuidedProjectionSolver solver(problem);
  engine::SolverOptions solverOptions;
  solverOptions.maxIterations = options.iterations;
  solverOptions.regularization = options.regularization;
  // Linear least squares: every full step lowers the energy; no hard band to keep.
  solverOptions.stepControl.enabled = false;
  const engine::SolveSummary result = solver.solve(solverOptions);
  if (summary) *summary = result;

  Eigen::MatrixX3d normals(numVertices, 3);
  for (int v = 0; v < numVertices; ++v)
    normals.row(v) = problem.x().segment<3>(normalOffsets[v]).transpose();
  return normals;
}

}  // namespace devsurf::models::quad_mesh
