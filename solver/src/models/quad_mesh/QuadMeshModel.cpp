#include "devsurf/models/quad_mesh/QuadMeshModel.h"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <iterator>
#include <stdexcept>
#include <string>

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>

#include "devsurf/metrics/CheckerboardCurvature.h"
#include "devsurf/models/quad_mesh/FaceMeasures.h"
#include "devsurf/spatial/TriangleMeshProximity.h"
#include "devsurf/models/quad_mesh/SplineSurface.h"
#include "devsurf/terms/CheckerboardConformalityTerm.h"
#include "devsurf/terms/CheckerboardIsometryTerm.h"
#include "devsurf/terms/ConformalFactorTerm.h"
#include "devsurf/terms/HandleTargetTerm.h"
#include "devsurf/terms/LinearPointMapTerm.h"
#include "devsurf/terms/MappingRegularityTerm.h"
#include "devsurf/terms/PolylineFairnessTerm.h"
#include "devsurf/terms/ReferenceFootPoints.h"
#include "devsurf/terms/ReferencePlaneDistanceTerm.h"
#include "devsurf/terms/ReferencePointDistanceTerm.h"
#include "devsurf/terms/TriangleOrientationTerm.h"
#include "devsurf/terms/VertexCoincidenceTerm.h"

namespace devsurf::models::quad_mesh {

namespace {

[[noreturn]] void failQuadMesh(const std::string& message) { throw std::invalid_argument(message); }

std::string indexed(const char* name, std::size_t i) { return std::string(name) + "[" + std::to_string(i) + "]"; }

bool finiteRows(const Eigen::MatrixX3d& m) { return m.allFinite(); }

void checkVertex(const VertexRef& v, int vertexCount, const std::string& path, int controlCount = -1) {
  if (v.on == MeshSide::Control) {
    if (controlCount < 0) failQuadMesh(path + ".on: \"control\" addresses control points; this design has no control net");
    if (v.vertex < 0 || v.vertex >= controlCount)
      failQuadMesh(path + ".vertex: " + std::to_string(v.vertex) + " is not a control point (the net has " +
           std::to_string(controlCount) + ")");
    return;
  }
  if (v.vertex < 0 || v.vertex >= vertexCount)
    failQuadMesh(path + ".vertex: " + std::to_string(v.vertex) + " is not a vertex (the mesh has " +
         std::to_string(vertexCount) + ")");
}

void checkWeight(double w, const std::string& path) {
  if (!std::isfinite(w) || w < 0) failQuadMesh(path + ": must be a finite number ≥ 0");
}

/// M projected onto its least-squares plane, oriented so that the faces keep their turning sense
/// (z = 0): the start of an unfolding the scene did not give.
Eigen::MatrixX3d projectedOntoPlane(const Eigen::MatrixX3d& mesh, const std::vector<Face>& faces) {
  const Eigen::RowVector3d centre = mesh.colwise().mean();
  const Eigen::MatrixX3d centred = mesh.rowwise() - centre;
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(centred.transpose() * centred);
  const Eigen::Vector3d e1 = eig.eigenvectors().col(2), e2 = eig.eigenvectors().col(1);
  Eigen::MatrixX3d flat = Eigen::MatrixX3d::Zero(mesh.rows(), 3);
  flat.col(0) = centred * e1;
  flat.col(1) = centred * e2;
  double signedArea = 0.0;
  for (const Face& f : faces) signedArea += signedPlanarArea(flat, f);
  if (signedArea < 0) flat.col(1) = -flat.col(1);
  return flat;
}

double diameter(const Eigen::MatrixX3d& v) {
  if (v.rows() == 0) return 0.0;
  return (v.colwise().maxCoeff() - v.colwise().minCoeff()).norm();
}

}  // namespace

const char* meshSideName(MeshSide side) {
  switch (side) {
    case MeshSide::Mesh: return "mesh";
    case MeshSide::Unfolding: return "unfolding";
    default: return "control";
  }
}

const char* variableMeshesName(VariableMeshes v) {
  switch (v) {
    case VariableMeshes::Mesh: return "mesh";
    case VariableMeshes::Unfolding: return "unfolding";
    case VariableMeshes::Both: return "both";
  }
  return "mesh";
}

void QuadMeshModel::validateDesign(const QuadMeshDesign& d) {
  const int V = static_cast<int>(d.mesh.rows());
  if (V < 3) failQuadMesh("mesh: at least 3 vertices are needed");
  if (!finiteRows(d.mesh)) failQuadMesh("mesh: every coordinate must be a finite number");
  if (!((d.mesh.colwise().maxCoeff() - d.mesh.colwise().minCoeff()).norm() > 0.0))
    failQuadMesh("mesh.vertices: they all lie at one point");
  if (d.unfolding.rows() == 0) {
    if (d.variable == VariableMeshes::Mesh)
      failQuadMesh("unfolding: required when only the mesh is variable (the unfolding is what it is bent from)");
  } else {
    if (d.unfolding.rows() != V)
      failQuadMesh("unfolding: " + std::to_string(d.unfolding.rows()) + " vertices, the mesh has " + std::to_string(V));
    if (!finiteRows(d.unfolding)) failQuadMesh("unfolding: every coordinate must be a finite number");
    // An unfolding shrunk to a point (or a mesh) has no shape to bend from or to: every length
    // and area of it is 0, and no solve gets away from there.
    const double meshExtent = (d.mesh.colwise().maxCoeff() - d.mesh.colwise().minCoeff()).norm();
    const double unfoldingExtent = (d.unfolding.colwise().maxCoeff() - d.unfolding.colwise().minCoeff()).norm();
    if (!(unfoldingExtent > 1e-9 * meshExtent) || !(unfoldingExtent > 0.0))
      failQuadMesh("unfolding.vertices: they all lie at one point (an unfolding needs the size of the sheet)");
  }
  if (d.control) {
    const long long refined = splineRefinement(*d.control).subdivision.rows();  // throws naming the field
    if (refined != V) failQuadMesh("mesh: the control net's refinement has " + std::to_string(refined) + " vertices, the mesh " + std::to_string(V));
  }
  if (!d.conformalFactors.empty()) {
    if (d.conformalFactors.size() != d.faces.size())
      failQuadMesh("conformal_factors: one per face (" + std::to_string(d.faces.size()) + ") expected");
    for (std::size_t f = 0; f < d.conformalFactors.size(); ++f)
      if (!std::isfinite(d.conformalFactors[f])) failQuadMesh(indexed("conformal_factors", f) + ": must be finite");
  }
  const int controlCount = d.control ? static_cast<int>(d.control->points.rows()) : -1;
  for (std::size_t i = 0; i < d.fixed.size(); ++i) checkVertex(d.fixed[i], V, indexed("fixed", i), controlCount);
  for (std::size_t i = 0; i < d.handles.size(); ++i) {
    const std::string path = indexed("handles", i);
    checkVertex(d.handles[i].vertex, V, path, controlCount);
    if (!d.handles[i].target.allFinite()) failQuadMesh(path + ".target: every coordinate must be a finite number");
    checkWeight(d.handles[i].weight, path + ".weight");
  }
  for (std::size_t i = 0; i < d.glue.size(); ++i) {
    const std::string path = indexed("glue", i);
    const GluePair& g = d.glue[i];
    if (g.a < 0 || g.a >= V || g.b < 0 || g.b >= V)
      failQuadMesh(path + ": vertex pair (" + std::to_string(g.a) + ", " + std::to_string(g.b) + ") is not in [0, " +
           std::to_string(V) + ")");
    if (g.a == g.b) failQuadMesh(path + ": a vertex cannot be glued to itself (" + std::to_string(g.a) + ")");
    if (g.on == MeshSide::Control) failQuadMesh(path + ".on: glue joins vertices of M or M′, not control points");
  }
  const QuadMeshWeights& w = d.weights;
  checkWeight(w.isometry, "weights.isometry");
  checkWeight(w.conformality, "weights.conformality");
  checkWeight(w.conformalFactor, "weights.conformal_factor");
  checkWeight(w.position, "weights.position");
  checkWeight(w.fairnessMesh, "weights.fairness_mesh");
  checkWeight(w.fairnessUnfolding, "weights.fairness_unfolding");
  checkWeight(w.proximityPoint, "weights.proximity_point");
  checkWeight(w.proximityPlane, "weights.proximity_plane");
  checkWeight(w.mapping, "weights.mapping");
  checkWeight(w.normals, "weights.normals");
  checkWeight(w.symmetry, "weights.symmetry");
  if ((w.proximityPoint > 0 || w.proximityPlane > 0) && !d.reference)
    failQuadMesh("reference: the proximity weights need a reference surface");
  if (d.reference) {
    const ReferenceSurface& r = *d.reference;
    if (r.vertices.rows() < 3 || r.triangles.rows() < 1)
      failQuadMesh("reference: at least 3 vertices and one triangle are needed");
    if (!r.vertices.allFinite()) failQuadMesh("reference.vertices: every coordinate must be a finite number");
    for (Eigen::Index t = 0; t < r.triangles.rows(); ++t)
      for (int k = 0; k < 3; ++k)
        if (r.triangles(t, k) < 0 || r.triangles(t, k) >= r.vertices.rows())
          failQuadMesh("reference.triangles[" + std::to_string(t) + "]: vertex " + std::to_string(r.triangles(t, k)) +
               " is not in [0, " + std::to_string(r.vertices.rows()) + ")");
  }
  const IsometrySchedule& s = d.schedule;
  if (!(s.energyMin >= 0) || !std::isfinite(s.energyMin)) failQuadMesh("schedule.energy_min: must be a finite number ≥ 0");
  if (!(s.isometryMin >= 0) || !std::isfinite(s.isometryMin))
    failQuadMesh("schedule.isometry_min: must be a finite number ≥ 0");
  if (s.roundIterations < 1) failQuadMesh("schedule.round_iterations: must be ≥ 1");
  if (s.rounds < 1) failQuadMesh("schedule.rounds: must be ≥ 1");
  if (!(s.fairnessDivisor >= 1) || !std::isfinite(s.fairnessDivisor))
    failQuadMesh("schedule.fairness_divisor: must be a finite number ≥ 1");
}

namespace {
QuadMeshDesign validatedQuadMesh(QuadMeshDesign design) {
  QuadMeshModel::validateDesign(design);
  return design;
}
}  // namespace

QuadMeshModel::QuadMeshModel(QuadMeshDesign design, QuadMeshOptions options)
    : design_(validatedQuadMesh(std::move(design))),
      options_(std::move(options)),
      topology_(static_cast<int>(design_.mesh.rows()), design_.faces) {
  if (design_.unfolding.rows() == 0) {
    design_.unfolding = projectedOntoPlane(design_.mesh, design_.faces);
  }
  if (design_.unfoldingPlanar) design_.unfolding.col(2).setZero();
  if (options_.normalize) {
    meshNormalization_ = engine::Normalization::fromPoints(design_.mesh);
    unfoldingNormalization_ = engine::Normalization::fromPoints(design_.unfolding);
    unfoldingNormalization_.scale = meshNormalization_.scale;
    if (design_.unfoldingPlanar) unfoldingNormalization_.centre.z() = 0.0;
  }
  buildProblem();
}

QuadMeshModel::~QuadMeshModel() = default;

const engine::Normalization& QuadMeshModel::normalizationOf(MeshSide side) const {
  return side == MeshSide::Unfolding ? unfoldingNormalization_ : meshNormalization_;  // control: M's
}

int QuadMeshModel::pointOffset(const VertexRef& v) const {
  const int block = v.on == MeshSide::Mesh ? blockMesh_ : v.on == MeshSide::Unfolding ? blockUnfolding_ : blockControl_;
  assert(block >= 0 && "control points are addressed only in a spline-surface design");
  return problem_.layout().block(block).offset + 3 * v.vertex;
}

bool QuadMeshModel::inOnePatch(const int* vertices, int count) const {
  if (patchesOfVertex_.empty()) return true;
  for (int p : patchesOfVertex_[static_cast<std::size_t>(vertices[0])]) {
    bool all = true;
    for (int k = 1; k < count && all; ++k) {
      const auto& list = patchesOfVertex_[static_cast<std::size_t>(vertices[k])];
      all = std::find(list.begin(), list.end(), p) != list.end();
    }
    if (all) return true;
  }
  return false;
}

double QuadMeshModel::fairnessWeight(double roundZeroWeight, int round) const {
  return roundZeroWeight / std::pow(design_.schedule.fairnessDivisor, std::max(0, round));
}

void QuadMeshModel::buildProblem() {
  const int V = topology_.vertexCount();
  const int F = static_cast<int>(design_.faces.size());
  blockMesh_ = problem_.addBlock("mesh", 3 * V);
  blockUnfolding_ = problem_.addBlock("unfolding", 3 * V);
  {
    Eigen::MatrixX3d m = design_.mesh, u = design_.unfolding;
    meshNormalization_.normalizeRows(m);
    unfoldingNormalization_.normalizeRows(u);
    auto mx = problem_.blockValues(blockMesh_);
    auto ux = problem_.blockValues(blockUnfolding_);
    for (int i = 0; i < V; ++i) {
      mx.segment<3>(3 * i) = m.row(i).transpose();
      ux.segment<3>(3 * i) = u.row(i).transpose();
    }
  }
  engine::VariableLayout& layout = problem_.layout();
  const bool meshVariable = design_.variable != VariableMeshes::Unfolding;
  const bool unfoldingVariable = design_.variable != VariableMeshes::Mesh;
  if (!meshVariable) layout.setBlockFixed(blockMesh_);
  if (!unfoldingVariable) layout.setBlockFixed(blockUnfolding_);
  if (design_.unfoldingPlanar)
    for (int i = 0; i < V; ++i) layout.setFixed(blockUnfolding_, 3 * i + 2, 1);
  for (const VertexRef& v : design_.fixed)
    if (v.on != MeshSide::Control) layout.setFixed(v.on == MeshSide::Mesh ? blockMesh_ : blockUnfolding_, 3 * v.vertex, 3);

  std::vector<int> meshOffsets(V), unfoldingOffsets(V);
  for (int i = 0; i < V; ++i) {
    meshOffsets[i] = pointOffset({MeshSide::Mesh, i});
    unfoldingOffsets[i] = pointOffset({MeshSide::Unfolding, i});
  }
  if (design_.control) {
    // Algorithm 2: the control points are the design; S^k(M) follows them by a hard linear map.
    const ControlNet& net = *design_.control;
    const SplineRefinement refinement = splineRefinement(net);
    subdivision_ = refinement.subdivision;
    if (net.smoothness == 0 && refinement.patchVertices.size() > 1) {
      // Without smoothness asked, patches may meet at an angle: E_fair on S^k(M) stays within
      // patches (a polyline of S^k(M) crossing a shared side would round the kink).
      patchesOfVertex_.assign(static_cast<std::size_t>(V), {});
      for (std::size_t p = 0; p < refinement.patchVertices.size(); ++p)
        for (int v : refinement.patchVertices[p]) patchesOfVertex_[static_cast<std::size_t>(v)].push_back(static_cast<int>(p));
    }
    const int C = static_cast<int>(net.points.rows());
    blockControl_ = problem_.addBlock("control", 3 * C);
    Eigen::MatrixX3d c = net.points;
    meshNormalization_.normalizeRows(c);
    auto cx = problem_.blockValues(blockControl_);
    for (int j = 0; j < C; ++j) cx.segment<3>(3 * j) = c.row(j).transpose();
    if (!meshVariable) layout.setBlockFixed(blockControl_);
    for (const VertexRef& v : design_.fixed)
      if (v.on == MeshSide::Control) layout.setFixed(blockControl_, 3 * v.vertex, 3);
    std::vector<int> controlOffsets(C);
    for (int j = 0; j < C; ++j) controlOffsets[j] = layout.block(blockControl_).offset + 3 * j;
    problem_.addTerm(std::make_unique<terms::LinearPointMapTerm>(
                         "subdivision", Eigen::SparseMatrix<double, Eigen::RowMajor>(subdivision_), meshOffsets, controlOffsets),
                     kSubdivisionWeight, engine::Strength::Hard);
    // Smoothness across shared patch sides, when asked: a − 2b + c per side point (C1 ⇒ G1).
    const std::vector<std::array<int, 3>> smoothness = splineSmoothnessTriples(net);
    if (meshVariable && net.smoothness > 0 && !smoothness.empty())
      problem_.addTerm(std::make_unique<terms::PolylineFairnessTerm>("patch_smoothness", smoothness, controlOffsets),
                       net.smoothness, engine::Strength::Soft);
  }
  const QuadMeshWeights& w = design_.weights;
  if (design_.conformal) {
    blockFactors_ = problem_.addBlock("conformal factors", F);
    auto lambda = problem_.blockValues(blockFactors_);
    for (int f = 0; f < F; ++f)
      lambda[f] = design_.conformalFactors.empty() ? 1.0 : design_.conformalFactors[f];
    const int factorOffset = layout.block(blockFactors_).offset;
    isometryTerm_ = problem_.addTerm(std::make_unique<terms::CheckerboardConformalityTerm>(
                                         "conformality", design_.faces, meshOffsets, unfoldingOffsets, factorOffset),
                                     w.conformality, engine::Strength::Hard);
    factorTerm_ = problem_.addTerm(std::make_unique<terms::ConformalFactorTerm>("conformal_factor", factorOffset, F),
                                   w.conformalFactor, engine::Strength::Soft);
  } else {
    isometryTerm_ = problem_.addTerm(
        std::make_unique<terms::CheckerboardIsometryTerm>("isometry", design_.faces, meshOffsets, unfoldingOffsets),
        w.isometry, engine::Strength::Hard);
  }
  {
    // The size of an isometry row: the mean squared diagonal of M′ (normalized), the scale of a
    // row's ‖d‖² − ‖d′‖² (see solve(): the step-control band).
    const Eigen::VectorXd& x = problem_.x();
    double sum = 0.0;
    for (const Face& f : design_.faces) {
      auto at = [&x, &unfoldingOffsets](int v) { return Eigen::Vector3d(x.segment<3>(unfoldingOffsets[v])); };
      if (faceSize(f) == 4) sum += 0.5 * ((at(f[0]) - at(f[2])).squaredNorm() + (at(f[1]) - at(f[3])).squaredNorm());
      else sum += (at(f[0]) - at(f[1])).squaredNorm();
    }
    isometryRowScale_ = design_.faces.empty() ? 0.0 : sum / static_cast<double>(design_.faces.size());
  }
  if (!design_.glue.empty()) {
    std::vector<int> offsets = meshOffsets;
    offsets.insert(offsets.end(), unfoldingOffsets.begin(), unfoldingOffsets.end());
    std::vector<std::pair<int, int>> pairs;
    for (const GluePair& g : design_.glue) {
      const int shift = g.on == MeshSide::Mesh ? 0 : V;
      pairs.emplace_back(g.a + shift, g.b + shift);
    }
    glueTerm_ = problem_.addTerm(std::make_unique<terms::VertexCoincidenceTerm>("glue", pairs, offsets), w.position,
                                 engine::Strength::Hard);
  }
  for (std::size_t i = 0; i < design_.handles.size(); ++i) {
    const VertexHandle& h = design_.handles[i];
    Eigen::Vector3d target = normalizationOf(h.vertex.on).toNormalized(h.target);
    if (h.vertex.on == MeshSide::Unfolding && design_.unfoldingPlanar) target.z() = 0.0;
    const int id = problem_.addTerm(std::make_unique<terms::HandleTargetTerm>("handle", pointOffset(h.vertex), target),
                                    w.position * h.weight, engine::Strength::Soft);
    problem_.term(id).relaxable = true;
    handleTerms_.push_back(id);
  }
  const auto& triples = topology_.polylineTriples();
  std::vector<std::array<int, 3>> meshTriples;
  if (patchesOfVertex_.empty()) {
    meshTriples = triples;
  } else {
    std::copy_if(triples.begin(), triples.end(), std::back_inserter(meshTriples),
                 [this](const std::array<int, 3>& t) { return inOnePatch(t.data(), 3); });
  }
  if (meshVariable && w.fairnessMesh > 0 && !meshTriples.empty())
    fairnessMeshTerm_ = problem_.addTerm(
        std::make_unique<terms::PolylineFairnessTerm>("fairness_mesh", meshTriples, meshOffsets), w.fairnessMesh,
        engine::Strength::Soft);
  if (unfoldingVariable && w.fairnessUnfolding > 0 && !triples.empty())
    fairnessUnfoldingTerm_ = problem_.addTerm(
        std::make_unique<terms::PolylineFairnessTerm>("fairness_unfolding", triples, unfoldingOffsets),
        w.fairnessUnfolding, engine::Strength::Soft);
  if (design_.reference && meshVariable && (w.proximityPoint > 0 || w.proximityPlane > 0)) {
    Eigen::MatrixX3d reference = design_.reference->vertices;
    meshNormalization_.normalizeRows(reference);
    auto proximity = std::make_shared<const spatial::TriangleMeshProximity>(reference, design_.reference->triangles);
    // One foot-point set for both terms: the closest points of M's vertices are queried once per
    // linearization, not once per term.
    auto feet = std::make_shared<terms::ReferenceFootPoints>(proximity, meshOffsets);
    if (w.proximityPoint > 0)
      problem_.addTerm(std::make_unique<terms::ReferencePointDistanceTerm>("proximity_point", feet),
                       w.proximityPoint, engine::Strength::Soft);
    if (w.proximityPlane > 0)
      problem_.addTerm(std::make_unique<terms::ReferencePlaneDistanceTerm>("proximity_plane", feet),
                       w.proximityPlane, engine::Strength::Soft);
  }
  if (unfoldingVariable && design_.unfoldingPlanar) {
    // Degeneracy guard "unfolding_orientation" (hard, ARCHITECTURE §8): eq. 1 sees lengths only and
    // cannot tell a face of M′ from its mirror image; both triangles of every face keep a tenth of
    // the signed area they started with (faces that start clockwise are not guarded).
    std::vector<std::array<int, 3>> triangles;
    std::vector<double> minArea;
    auto u = problem_.blockValues(blockUnfolding_);
    for (const Face& f : design_.faces) {
      const int n = faceSize(f);
      for (int t = 0; t < n - 2; ++t) {
        const std::array<int, 3> tri = n == 3 ? std::array<int, 3>{f[0], f[1], f[2]}
                                     : t == 0 ? std::array<int, 3>{f[0], f[1], f[2]}
                                              : std::array<int, 3>{f[2], f[3], f[0]};
        const Eigen::Vector2d p0 = u.segment<2>(3 * tri[0]), p1 = u.segment<2>(3 * tri[1]), p2 = u.segment<2>(3 * tri[2]);
        const double area = 0.5 * ((p1.x() - p0.x()) * (p2.y() - p0.y()) - (p2.x() - p0.x()) * (p1.y() - p0.y()));
        triangles.push_back(tri);
        minArea.push_back(0.1 * area);
      }
    }
    problem_.addTerm(std::make_unique<terms::TriangleOrientationTerm>(
                         "unfolding_orientation", layout.block(blockUnfolding_).offset, triangles, minArea, 3),
                     1.0, engine::Strength::Hard);
  }
  // E_map compares second differences of M and M′ along polylines: across a side where patches
  // meet at an angle (no smoothness asked) it would resist the kink like E_fair; kept within patches.
  std::vector<std::array<int, 4>> quadruples;
  if (patchesOfVertex_.empty())
    quadruples = topology_.mappingQuadruples();
  else
    for (const auto& q : topology_.mappingQuadruples())
      if (inOnePatch(q.data(), 4)) quadruples.push_back(q);
  if (w.mapping > 0 && !quadruples.empty())
    mappingTerm_ = problem_.addTerm(
        std::make_unique<terms::MappingRegularityTerm>("mapping", quadruples, meshOffsets, unfoldingOffsets), w.mapping,
        engine::Strength::Soft);
  solver_ = std::make_unique<engine::GuidedProjectionSolver>(problem_, options_.linearSolver, options_.deadline);
}

QuadMeshSolveSummary QuadMeshModel::solve(const engine::SolverOptions& options) {
  const IsometrySchedule& s = design_.schedule;
  QuadMeshSolveSummary out;
  engine::SolveSummary& merged = out.summary;
  int round = std::max(0, options.firstIteration) / s.roundIterations;
  int stepsIntoRound = std::max(0, options.firstIteration) % s.roundIterations;
  int remaining = std::max(0, options.maxIterations);
  const double isoWeight = design_.conformal ? design_.weights.conformality : design_.weights.isometry;
  while (true) {
    const double fairMesh = fairnessWeight(design_.weights.fairnessMesh, round);
    const double fairUnfolding = fairnessWeight(design_.weights.fairnessUnfolding, round);
    if (fairnessMeshTerm_ >= 0) problem_.setWeight(fairnessMeshTerm_, fairMesh);
    if (fairnessUnfoldingTerm_ >= 0) problem_.setWeight(fairnessUnfoldingTerm_, fairUnfolding);
    const double roundFairness = fairnessMeshTerm_ >= 0 ? fairMesh : fairUnfolding;

    engine::SolverOptions o = options;
    o.maxIterations = std::min(remaining, s.roundIterations - stepsIntoRound);
    if (o.factorizationReuse.maxAge <= 0 && numUnknowns() >= options_.factorizationReuseFrom) {
      o.factorizationReuse.maxAge = s.roundIterations;
      o.factorizationReuse.tolerance = kReuseTolerance;
    }
    o.residualTolerance = std::max(options.residualTolerance, s.energyMin);
    // The band is absolute (|w r| of one hard row); isometry rows are ‖d‖² − ‖d′‖², of the size of
    // a squared diagonal (1.7e-3 on a 24 × 16 sheet of diameter 1), so the engine's band (0.1 for
    // batch solves, 1e-3 in sessions) let handles stretch the sheet by tens of per cent before it
    // noticed. With handles pulling against glue pairs, a row may take at most 10 % of its size.
    // Only then: without handles the band guards nothing (no target pulls against the hard rows)
    // and starts far from isometric — a hole pulled shut — stalled under it (cut and glue L-Err
    // 0.0038 % → 0.83 %); with handles but no glue, a solve started isometric (a solved spline
    // surface solved again) let the restarted fairness use the band and then stalled (0.011 % →
    // 2.4 %).
    if (isometryRowScale_ > 0 && isoWeight > 0 && !handleTerms_.empty() && glueTerm_ >= 0)
      o.stepControl.hardBand = std::min(o.stepControl.hardBand, 0.1 * isoWeight * isometryRowScale_);
    const int numbering = merged.iterations.empty() ? 0 : merged.iterations.back().iteration;
    if (options.callback) {
      o.callback = [&options, numbering, roundFairness, &merged](const engine::IterationRecord& record) {
        if (record.iteration == 0 && !merged.iterations.empty()) return true;  // shown already
        engine::IterationRecord shifted = record;
        shifted.iteration += numbering;
        shifted.fairnessWeight = roundFairness;
        return options.callback(shifted);
      };
    }
    engine::SolveSummary r = solver_->solve(o);
    for (std::size_t k = merged.iterations.empty() ? 0 : 1; k < r.iterations.size(); ++k) {
      engine::IterationRecord record = r.iterations[k];
      record.iteration += numbering;
      record.fairnessWeight = roundFairness;
      merged.iterations.push_back(std::move(record));
    }
    merged.termNames = r.termNames;
    merged.reason = r.reason;
    merged.converged = r.converged;
    merged.totalMs += r.totalMs;
    merged.keptEvaluations += r.keptEvaluations;
    out.rounds += 1;
    out.roundFairness.push_back(roundFairness);
    remaining -= r.stepsTaken();

    const double isoResidual =
        r.iterations.empty() ? 0.0 : r.iterations.back().termResiduals[isometryTerm_] / (isoWeight * isoWeight);
    if (isoWeight > 0 && isoResidual <= s.isometryMin) {
      out.isometryReached = true;
      break;
    }
    using engine::TerminationReason;
    if (r.reason == TerminationReason::Aborted || r.reason == TerminationReason::Diverged ||
        r.reason == TerminationReason::TimeBudget || r.reason == TerminationReason::Stalled)
      break;
    if (remaining <= 0 || round + 1 >= s.rounds) break;
    ++round;
    stepsIntoRound = 0;
  }
  if (out.isometryReached) {  // Algorithm 1's own stop (E_iso ≤ E_iso,min), not the last round's limit
    merged.converged = true;
    using engine::TerminationReason;
    if (merged.reason == TerminationReason::MaxIterations || merged.reason == TerminationReason::RelativeChange)
      merged.reason = TerminationReason::ResidualTolerance;  // a divergence or a time budget keeps its name
  }
  return out;
}

Eigen::MatrixX3d QuadMeshModel::meshVertices() const {
  if (blockControl_ >= 0) return subdivision_ * controlPoints();  // S^k(M) exactly
  const int V = topology_.vertexCount();
  Eigen::MatrixX3d m(V, 3);
  auto x = problem_.blockValues(blockMesh_);
  for (int i = 0; i < V; ++i) m.row(i) = x.segment<3>(3 * i).transpose();
  meshNormalization_.denormalizeRows(m);
  return m;
}

Eigen::MatrixX3d QuadMeshModel::controlPoints() const {
  if (blockControl_ < 0) return {};
  const int C = static_cast<int>(design_.control->points.rows());
  Eigen::MatrixX3d c(C, 3);
  auto x = problem_.blockValues(blockControl_);
  for (int j = 0; j < C; ++j) c.row(j) = x.segment<3>(3 * j).transpose();
  meshNormalization_.denormalizeRows(c);
  return c;
}

Eigen::MatrixX3d QuadMeshModel::unfoldingVertices() const {
  const int V = topology_.vertexCount();
  Eigen::MatrixX3d u(V, 3);
  auto x = problem_.blockValues(blockUnfolding_);
  for (int i = 0; i < V; ++i) u.row(i) = x.segment<3>(3 * i).transpose();
  unfoldingNormalization_.denormalizeRows(u);
  if (design_.unfoldingPlanar) u.col(2).setZero();
  return u;
}

QuadMeshDesign QuadMeshModel::design() const {
  QuadMeshDesign d = design_;
  if (d.control) d.control->points = controlPoints();
  d.mesh = meshVertices();
  d.unfolding = unfoldingVertices();
  if (blockFactors_ >= 0) {
    auto lambda = problem_.blockValues(blockFactors_);
    d.conformalFactors.assign(lambda.data(), lambda.data() + lambda.size());
  }
  return d;
}

void QuadMeshModel::setHandleTarget(int i, const Eigen::Vector3d& target) {
  VertexHandle& h = design_.handles.at(i);
  h.target = target;
  Eigen::Vector3d normalized = normalizationOf(h.vertex.on).toNormalized(target);
  if (h.vertex.on == MeshSide::Unfolding && design_.unfoldingPlanar) normalized.z() = 0.0;
  static_cast<terms::HandleTargetTerm&>(*problem_.term(handleTerms_.at(i)).term).setTarget(normalized);
}

void QuadMeshModel::setHandleWeight(int i, double weight) {
  design_.handles.at(i).weight = weight;
  problem_.setWeight(handleTerms_.at(i), design_.weights.position * weight);
}

QuadMeshQuality QuadMeshModel::quality() const {
  QuadMeshQuality q;
  const Eigen::MatrixX3d m = meshVertices(), u = unfoldingVertices();
  const auto& edges = topology_.edges();
  Eigen::VectorXd L(edges.size()), Lp(edges.size());
  q.edgeLengthError.resize(static_cast<Eigen::Index>(edges.size()));
  for (std::size_t e = 0; e < edges.size(); ++e) {
    L[e] = (m.row(edges[e][0]) - m.row(edges[e][1])).norm();
    Lp[e] = (u.row(edges[e][0]) - u.row(edges[e][1])).norm();
    q.edgeLengthError[e] = L[e] > 0 ? (Lp[e] - L[e]) / L[e] : 0.0;
    q.edgeLengthErrorMax = std::max(q.edgeLengthErrorMax, std::abs(q.edgeLengthError[e]));
  }
  q.lengthError = L.norm() > 0 ? (Lp - L).norm() / L.norm() : 0.0;
  const auto& faces = design_.faces;
  Eigen::VectorXd A(faces.size()), Ap(faces.size());
  for (std::size_t f = 0; f < faces.size(); ++f) {
    A[f] = faceArea(m, faces[f]);
    Ap[f] = faceArea(u, faces[f]);
    if (design_.unfoldingPlanar && signedPlanarArea(u, faces[f]) < 0) q.unfoldingFlippedFaces += 1;
  }
  q.areaError = A.norm() > 0 ? (Ap - A).norm() / A.norm() : 0.0;
  const double size = std::max(diameter(m), 1e-300);
  for (const Face& f : faces) {
    if (faceSize(f) == 3) {
      for (int k = 0; k < 3; ++k) {
        const int a = f[k], b = f[(k + 1) % 3];
        const double c = (m.row(a) - m.row(b)).squaredNorm() - (u.row(a) - u.row(b)).squaredNorm();
        q.isometryResidualMax = std::max(q.isometryResidualMax, std::abs(c) / (size * size));
      }
      continue;
    }
    const Eigen::Vector3d d0 = m.row(f[0]) - m.row(f[2]), d1 = m.row(f[1]) - m.row(f[3]);
    const Eigen::Vector3d e0 = u.row(f[0]) - u.row(f[2]), e1 = u.row(f[1]) - u.row(f[3]);
    const double c0 = d0.squaredNorm() - e0.squaredNorm(), c1 = d1.squaredNorm() - e1.squaredNorm(),
                 c2 = d0.dot(d1) - e0.dot(e1);
    q.isometryResidualMax =
        std::max(q.isometryResidualMax, std::max({std::abs(c0), std::abs(c1), std::abs(c2)}) / (size * size));
  }
  for (const GluePair& g : design_.glue) {
    const Eigen::MatrixX3d& p = g.on == MeshSide::Mesh ? m : u;
    q.glueGapMax = std::max(q.glueGapMax, (p.row(g.a) - p.row(g.b)).norm() / size);
  }
  const Eigen::MatrixX3d control = controlPoints();
  for (const VertexHandle& h : design_.handles) {
    if (h.weight <= 0) continue;
    const Eigen::MatrixX3d& p = h.vertex.on == MeshSide::Mesh ? m : h.vertex.on == MeshSide::Unfolding ? u : control;
    Eigen::Vector3d target = h.target;
    if (h.vertex.on == MeshSide::Unfolding && design_.unfoldingPlanar) target.z() = 0.0;
    q.handleDistanceMax = std::max(q.handleDistanceMax, (p.row(h.vertex.vertex).transpose() - target).norm());
  }
  return q;
}

QuadMeshCurvature QuadMeshModel::curvature() const {
  const Eigen::MatrixX3d mesh = meshVertices();
  QuadMeshCurvature c;
  // Vertex normals: the unit area-weighted normals of the inscribed parallelograms (the simplest
  // estimate of the Gauss image, 004_… §3.2). The eq. 3/5 solve (solveGaussImage) drifts toward
  // its degenerate solutions on developables — measured on the solved bent-sheet preset:
  // |K|/H² median 0.30 with it, 7e-4 with these; 0.96 against 1e-15 on the exact cone of
  // quad-cone-deficit — so the model reports these; solveGaussImage stays a library function.
  c.normals = unitVertexNormals(mesh, design_.faces);
  const std::vector<metrics::FaceCurvature> faces = metrics::checkerboardCurvature(mesh, c.normals, design_.faces);
  const Eigen::Index F = static_cast<Eigen::Index>(faces.size());
  c.gauss.resize(F);
  c.mean.resize(F);
  c.kappa1.resize(F);
  c.kappa2.resize(F);
  c.direction1.resize(F, 3);
  c.direction2.resize(F, 3);
  c.ruling.resize(F, 3);
  for (Eigen::Index f = 0; f < F; ++f) {
    const metrics::FaceCurvature& k = faces[static_cast<std::size_t>(f)];
    c.gauss[f] = k.gauss;
    c.mean[f] = k.mean;
    c.kappa1[f] = k.principalMax;
    c.kappa2[f] = k.principalMin;
    c.direction1.row(f) = k.directionMax.transpose();
    c.direction2.row(f) = k.directionMin.transpose();
    c.ruling.row(f) = k.ruling.transpose();
  }
  return c;
}

}  // namespace devsurf::models::quad_mesh
