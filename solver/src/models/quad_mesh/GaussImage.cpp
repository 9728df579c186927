#include "devsurf/models/quad_mesh/GaussImage.h"

#include <memory>
#include <stdexcept>
#include <string>

#include <Eigen/Geometry>

#include "devsurf/engine/Normalization.h"
#include "devsurf/engine/Problem.h"
#include "devsurf/terms/GaussImageNormalTerm.h"
#include "devsurf/terms/ShapeOperatorSymmetryTerm.h"

namespace devsurf::models::quad_mesh {
namespace {

/// E_fair on the normals: per triple (i, j, k) three rows n_i − 2n_j + n_k (linear).
/// \note Stand-in for terms::PolylineFairnessTerm(triples, pointOffsets) (branch issue13-terms),
///       which has the same rows; swap it in at merge.
class NormalFairnessTerm final : public engine::Term {
 public:
  NormalFairnessTerm(std::string name, std::vector<std::array<int, 3>> triples,
                     std::vector<int> pointOffsets)
      : Term(std::move(name)), triples_(std::move(triples)), offsets_(std::move(pointOffsets)) {}

  int numResiduals() const override { return 3 * static_cast<int>(triples_.size()); }

  void jacobianStructure(std::vector<engine::JacobianEntry>& entries) const override {
    for (int t = 0; t < static_cast<int>(triples_.size()); ++t)
      for (int k = 0; k < 3; ++k)
        for (const int vertex : triples_[t]) entries.push_back({3 * t + k, offsets_[vertex] + k});
  }

  void evaluate(const Eigen::VectorXd& x, double* residuals, double* jacobian) const override {
    for (int t = 0; t < static_cast<int>(triples_.size()); ++t) {
      const auto& [i, j, k] = triples_[t];
      const Eigen::Vector3d r =
          x.segment<3>(offsets_[i]) - 2.0 * x.segment<3>(offsets_[j]) + x.segment<3>(offsets_[k]);
      for (int c = 0; c < 3; ++c) {
        residuals[3 * t + c] = r[c];
        if (jacobian) {
          jacobian[9 * t + 3 * c + 0] = 1.0;
          jacobian[9 * t + 3 * c + 1] = -2.0;
          jacobian[9 * t + 3 * c + 2] = 1.0;
        }
      }
    }
  }

 private:
  std::vector<std::array<int, 3>> triples_;
  std::vector<int> offsets_;
};

/// Keeps each normal near the direction it started in: per vertex three rows (I − u uᵀ) n_i with
/// u the unit start normal (rank 2: the length along u is free). Linear.
class NormalDirectionAnchorTerm final : public engine::Term {
 public:
  NormalDirectionAnchorTerm(std::string name, Eigen::MatrixX3d directions,
                            std::vector<int> pointOffsets)
      : Term(std::move(name)),
        directions_(std::move(directions)),
        offsets_(std::move(pointOffsets)) {}

  int numResiduals() const override { return 3 * static_cast<int>(offsets_.size()); }

  void jacobianStructure(std::vector<engine::JacobianEntry>& entries) const override {
    for (int i = 0; i < static_cast<int>(offsets_.size()); ++i)
      for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 3; ++c) entries.push_back({3 * i + r, offsets_[i] + c});
  }

  void evaluate(const Eigen::VectorXd& x, double* residuals, double* jacobian) const override {
    for (int i = 0; i < static_cast<int>(offsets_.size()); ++i) {
      const Eigen::Vector3d u = directions_.row(i).transpose();
      const Eigen::Matrix3d P = Eigen::Matrix3d::Identity() - u * u.transpose();
      const Eigen::Vector3d r = P * x.segment<3>(offsets_[i]);
      for (int row = 0; row < 3; ++row) {
        residuals[3 * i + row] = r[row];
        if (jacobian)
          for (int c = 0; c < 3; ++c) jacobian[9 * i + 3 * row + c] = P(row, c);
      }
    }
  }

 private:
  Eigen::MatrixX3d directions_;
  std::vector<int> offsets_;
};

/// Unit area-weighted vertex normals (zero for a vertex whose faces cancel).
Eigen::MatrixX3d areaWeightedNormals(const Eigen::MatrixX3d& mesh,
                                     const std::vector<std::array<int, 4>>& faces) {
  Eigen::MatrixX3d normals = Eigen::MatrixX3d::Zero(mesh.rows(), 3);
  for (const auto& face : faces) {
    const int n = face[3] < 0 ? 3 : 4;
    const auto v = [&mesh, &face](int c) -> Eigen::Vector3d { return mesh.row(face[c]); };
    const Eigen::Vector3d vectorArea = n == 4 ? 0.5 * (v(2) - v(0)).cross(v(3) - v(1))
                                              : 0.5 * (v(1) - v(0)).cross(v(2) - v(0));
    for (int c = 0; c < n; ++c) normals.row(face[c]) += vectorArea.transpose();
  }
  for (Eigen::Index i = 0; i < normals.rows(); ++i) {
    const double length = normals.row(i).norm();
    if (length > 0.0) normals.row(i) /= length;
  }
  return normals;
}

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
  const Eigen::MatrixX3d initial = areaWeightedNormals(unitMesh, faces);
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
        std::make_unique<NormalFairnessTerm>("normal fairness", polylineTriples, normalOffsets),
        options.fairnessWeight, engine::Strength::Soft);

  if (options.anchorWeight > 0.0)
    problem.addTerm(std::make_unique<NormalDirectionAnchorTerm>("normal direction", initial,
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
