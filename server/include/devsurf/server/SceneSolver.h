#pragma once

#include <array>
#include <functional>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "devsurf/engine/Deadline.h"
#include "devsurf/engine/GuidedProjectionSolver.h"
#include "devsurf/io/IgesWriter.h"
#include "devsurf/io/PolygonMesh.h"
#include "devsurf/io/QuadMesh.h"
#include "devsurf/models/composite/CompositeModel.h"
#include "devsurf/models/conical_strip/ConicalStripModel.h"
#include "devsurf/models/quad_mesh/QuadMeshModel.h"
#include "devsurf/models/quasi_strip/QuasiStripModel.h"
#include "devsurf/models/strip/StripModel.h"
#include "devsurf/proto/Report.h"
#include "devsurf/proto/Scene.h"

namespace devsurf::server {

/// An export produced in memory (for HTTP responses).
struct ExportedFile {
  std::string content;
  std::string mediaType;  ///< e.g. "model/obj", "application/json", "image/svg+xml"
  std::string extension;  ///< file name extension without the dot ("obj", "fold", "svg")
};

/// The export format does not apply to this scene (e.g. svg of a strip, or of a composite without
/// a development) or is unknown; what() says why.
class ExportUnavailable : public std::invalid_argument {
 public:
  using std::invalid_argument::invalid_argument;
};

/// The export format applies, but the model's current state cannot be exported (e.g. its
/// development is not a valid crease pattern: a face turned clockwise, after an edit); what()
/// says which format and why.
class ExportFailed : public std::invalid_argument {
 public:
  using std::invalid_argument::invalid_argument;
};

/// Per-call limits of SceneSolver::solve that override the scene's solver settings (< 0: the
/// scene's own).
struct SolveLimits {
  int iterations = -1;         ///< iterations at most (quasi_strip: the optimizer's limit)
  double timeBudgetMs = -1.0;  ///< time budget (0 = none) …
  /// … measured by this clock: a session's budgets count the CPU time of its solving thread, so a
  /// busy machine delays a drag's or a release's result instead of cutting it short.
  engine::BudgetClock budgetClock = engine::BudgetClock::Wall;
  double budgetWallCapMs = 0.0;  ///< engine::SolverOptions::budgetWallCapMs (0 = none)
  double hardTolerance = -1.0; ///< stop once every hard row is within this (0 = not used)
  double hardBand = -1.0;      ///< step control's band (engine::StepControlOptions::hardBand)
  int correctionSteps = -1;    ///< engine::SolverOptions::correctionSteps
  int firstIteration = 0;      ///< engine::SolverOptions::firstIteration (where the schedule resumes)
  double regularization = -1.0; ///< ε_reg of every step
  bool projectionOnly = false;  ///< engine::SolverOptions::projectionOnly
  bool holdTargetsInProjection = false;  ///< engine::SolverOptions::holdTargetsInProjection
};

/// One quality threshold of issue 5 (000_… Fig. 17 and the drag-stress suite) against a metric.
struct QualityCheck {
  std::string metric;  ///< report metric name
  double value = 0.0;
  double limit = 0.0;  ///< value ≤ limit passes (≥ for *_min_ratio metrics)
  bool ok = false;
};

/// Whether a state meets the quality thresholds of its kind: composites face_flatness_max ≤ 1e-3,
/// face_flatness_mean ≤ 2e-4, vertex_curvature_max ≤ 1e-3, development_flipped_faces = 0,
/// development_length_error ≤ 5e-3, crease_backtrack_max ≤ 0 (with a development: the last
/// three), ruling_length_min_ratio ≥ 0.25; strips warp_angle_max_deg ≤ 0.05 and
/// ruling_length_min_ratio ≥ 0.25. Kinds that keep their input curves have none (met = true).
struct QualityVerdict {
  bool met = true;
  std::vector<QualityCheck> checks;
  nlohmann::json toJson() const;  ///< {"met", "checks": [{"metric","value","limit","ok"}…]}
};

/// The service behind `devsurf solve`, batch jobs and sessions: builds the model a scene describes
/// ("strip", "composite", "quasi_strip", "conical_strip"), solves it and reports.
///
/// strip and composite move the scene's geometry (guided projection). quasi_strip (Bo et al.: a
/// mapping between two fixed curves, L-BFGS or guided projection) and conical_strip (Chu et al.:
/// a greedy construction, no iterations) leave the input curves where they are: their scene stays
/// the input, and what they compute is the report's `result`. Their solve() returns an
/// engine::SolveSummary adapted from the model's own summary (quasi_strip: one record per
/// optimizer iteration with the objective of eq. 9 as the only residual, "objective";
/// conical_strip: the initial record only); the model's own termination reason is the report's.
class SceneSolver {
 public:
  /// Builds the model (validation happened in proto::sceneFromJson).
  /// @param deadline  bounds the construction and every solve() until setDeadline() (a job's time
  ///                  limit, a session's budget for a structural edit); default: never
  /// @throws proto::SceneError for designs the model rejects, engine::DeadlineExceeded once
  ///         `deadline` has passed
  explicit SceneSolver(proto::Scene scene, engine::Deadline deadline = {});

  /// The deadline of the next solves (engine::Deadline{}: none).
  void setDeadline(engine::Deadline deadline) { deadline_ = std::move(deadline); }
  /// Whether the scene's `solver.time_budget_ms` cuts quasi_strip solves short (default true).
  /// Sessions turn it off: they solve those strips whole from the scene, and a restart solves the
  /// same scene again, so the result must not depend on the clock; their own deadline bounds the
  /// work and refuses instead of truncating.
  void setSceneTimeBudgetApplies(bool applies) { sceneTimeBudgetApplies_ = applies; }

  /// Runs the scene's solver settings (iterations overridden when ≥ 0; quasi_strip: the optimizer's
  /// iteration limit; conical_strip: ignored). Every kind checks the deadline (setDeadline)
  /// between iterations and inside its long loops.
  /// @throws engine::DeadlineExceeded once it has passed (the model is then not to be used)
  /// @param[in] onIteration  optional per-iteration callback; return false to abort (quasi_strip
  ///            and conical_strip cannot be interrupted: it is called once, with the last record)
  engine::SolveSummary solve(int iterationsOverride = -1,
                             std::function<bool(const engine::IterationRecord&)> onIteration = {});
  /// solve() with per-call limits (iterations, time budget, hard tolerance).
  engine::SolveSummary solve(const SolveLimits& limits,
                             std::function<bool(const engine::IterationRecord&)> onIteration = {});
  /// The quality thresholds of this kind against metrics() (see QualityVerdict).
  QualityVerdict quality() const;
  /// The same against metrics already computed (a report computes them once).
  QualityVerdict quality(const proto::Metrics& m) const;
  /// Starts the step control of the model's solver afresh (a new drag; see
  /// engine::StepControlOptions). No-op for kinds without guided projection.
  void resetStepControl();

  /// The scene with the current geometry (valid input to solve again).
  proto::Scene currentScene() const;
  /// The papers' quality measures plus handle and displacement figures (names carry units).
  proto::Metrics metrics() const;
  /// One-sided distances from a user's reference points to the current surface (issue 15): the
  /// sampled surface of the obj export (quad meshes: M) as triangles. Names: reference_points,
  /// reference_distance_max, …_rms, …_max_relative, …_rms_relative (÷ the reference's bounding-box
  /// diagonal), reference_coverage (fraction within reference_coverage_tolerance; ≤ 0 asks for 1%
  /// of that diagonal).
  /// @param[in] reference  r×3 points in the scene's units
  /// @param[out] distances  when given, each point's distance (for colouring the points)
  proto::Metrics referenceMetrics(const Eigen::MatrixX3d& reference, double tolerance,
                                  Eigen::VectorXd* distances = nullptr) const;
  /// The surface as the obj export samples it: strips 200×8, composites 50×8 per face, conical
  /// patches 25×5, quad meshes M (a triangle repeats its last vertex).
  io::QuadMesh sampledSurface() const;
  /// The full report of the last solve.
  nlohmann::json report(const engine::SolveSummary& summary, double timeMs) const;
  /// The report's `termination` of the last solve for quasi_strip (an engine reason name, or
  /// "identity_fallback" when the model kept σ(t) = t) and conical_strip ("completed"); empty for
  /// the other kinds (their summary's reason is the report's).
  const std::string& termination() const { return termination_; }

  /// Whether the scene is a strip.
  bool isStrip() const { return strip_ != nullptr; }
  /// Whether the scene is a composite.
  bool isComposite() const { return composite_ != nullptr; }
  bool isQuasiStrip() const { return quasi_ != nullptr; }
  bool isConicalStrip() const { return conical_ != nullptr; }
  bool isQuadMesh() const { return quadMesh_ != nullptr; }
  /// Whether the model keeps the scene's geometry and computes a `result` (quasi_strip,
  /// conical_strip): such scenes are solved before they are exported.
  bool keepsInputGeometry() const { return quasi_ != nullptr || conical_ != nullptr; }
  /// @throws std::logic_error if the scene is not a strip
  models::strip::StripModel& stripModel();
  /// @throws std::logic_error if the scene is not a composite
  models::composite::CompositeModel& compositeModel();
  /// @throws std::logic_error if the scene is not a quasi_strip
  const models::quasi_strip::QuasiStripModel& quasiStripModel() const;
  /// @throws std::logic_error if the scene is not a conical_strip
  const models::conical_strip::ConicalStripModel& conicalStripModel() const;
  /// @throws std::logic_error if the scene is not a quad_mesh
  models::quad_mesh::QuadMeshModel& quadMeshModel();
  const models::quad_mesh::QuadMeshModel& quadMeshModel() const;
  /// Writes an export "format:path" (format obj, off, ply, stl: the sampled surface, stl as
  /// io::triangulateQuads' triangles; composites: all faces in one mesh, see CompositeGeometry::merged; fold, svg: the crease pattern of a
  /// composite with a development, CompositeModel::creasePattern, FOLD 1.2 or SVG in mm; iges:
  /// the B-spline surfaces and boundary curves, see exportAs).
  /// @throws ExportUnavailable for an unknown format or one that does not apply, ExportFailed when
  ///         the model's state cannot be exported (both std::invalid_argument),
  ///         std::runtime_error if writing fails
  void exportTo(const std::string& spec) const;
  /// Whether `format` applies to this scene's kind and set-up (a development, seams, a control
  /// net, a planar unfolding), as exportAs and exportTo would find it: what can be known before a
  /// solve. An export that passes may still fail on the solved state (ExportFailed).
  /// @throws ExportUnavailable with exportAs's message ("format: …") when it does not apply
  void checkExportFormat(const std::string& format) const;
  /// The scene's kind as the scene file names it ("strip", "composite", "quasi_strip", …).
  std::string kindName() const;
  /// ExportUnavailable's message for unfolding_obj of a kind other than quad_mesh.
  std::string unfoldingObjUnavailable() const;
  /// The export as bytes: "obj" (sampled surface as quads: strips 200×8, composites every face at
  /// 50 samples per span, 8 across, as exportTo; quasi_strip the converted surface over the
  /// trimmed range 200×8; conical_strip every patch 24×4), "fold" (FOLD 1.2) and "svg" (fold
  /// pattern, mm) for composites with a development, "step" (STEP AP214 through OpenCascade, media
  /// type model/step: the surfaces of "iges" as faces, patches of a control net sewn into shells),
  /// "iges" (IGES 5.3, media type model/iges) for every kind with B-spline surfaces (quad_mesh:
  /// only with a control net, its bicubic patches, u along columns, v along rows): B-spline surfaces as entity 128 with u along the curves and v across the rulings
  /// (v = 0 on the first curve), curves as entity 126 — strip: the surface (degree (m, 1)) and
  /// a, b; composite: CompositeModel::igesEntities; quasi_strip: the converted surface (degree
  /// (p·d, 1), u = c1's parameter over the trimmed range) and c1, c2; conical_strip: every patch
  /// (degree (3 or 2, 1), u ∈ [0, 1]) and p, q.
  /// Lengths are design units (obj, iges: the header's units are the scene's "units") or scaled by
  /// the scene's "units" (fold: frame_unit; svg: mm).
  /// @throws ExportUnavailable for an unknown format or one that does not apply to this scene,
  ///         ExportFailed when the model's current state cannot be exported
  ExportedFile exportAs(const std::string& format) const;
  /// exportAs of a scene document (a session's current scene, a job's solved scene): builds the
  /// model first (and solves it when it keepsInputGeometry()) within `limits` and `deadline`; a
  /// document or design the model now rejects, or a build over the deadline, is ExportFailed too.
  static ExportedFile exportScene(const nlohmann::json& scene, const std::string& format,
                                  const proto::ResourceLimits& limits = {}, engine::Deadline deadline = {});
  /// The scene solved as `devsurf solve` solves it (its own solver settings): where demo sessions
  /// start. Kinds that keep their input geometry return the scene itself.
  /// @throws proto::SceneError for designs the model rejects
  static proto::Scene solvedScene(const proto::Scene& scene);

 private:
  /// The crease pattern of the composite's development in the scene's units, for `format`.
  /// @throws ExportUnavailable (not a composite, no development), ExportFailed (rejected state)
  io::CreasePattern creasePattern(const std::string& format) const;

  /// A flat pattern to cut out: the unfolding in design units, its faces counter-clockwise, the
  /// vertex pairs glued together in 3D and a title.
  struct CuttingParts {
    Eigen::MatrixX2d vertices;
    Eigen::MatrixX3d spaceVertices;  ///< each vertex on the surface (the folded form)
    std::vector<io::PolygonFace> faces;
    std::vector<std::array<int, 2>> gluePairs;
    std::string title;
  };
  /// The flat pattern of a scene without a crease pattern: a composite cut along its seams (its
  /// pieces, models::composite::unfoldPieces) or a strip, quasi strip or conical strip (the obj
  /// export's sampled surface, points within 1e-9 of its diagonal welded, each connected sheet
  /// unfolded from its edge lengths by spatial::unfoldPieces; no glue pairs).
  /// @throws ExportUnavailable for other scenes, ExportFailed when the state cannot be unfolded
  CuttingParts cuttingParts(const std::string& format) const;
  /// The parts as io::cuttingPatternSvg at true size in mm (strips with their mesh lines, which
  /// are rulings; pieces without).
  std::string cuttingPatternSvg(const CuttingParts& parts) const;
  /// Whether the scene is a strip, quasi strip or conical strip (a flat pattern by unfolding).
  bool hasFlatStripPattern() const;
  /// exportAs for "stl" (every kind), "png" (a 320 × 240 picture of the sampled surface,
  /// surfaceThumbnailPng), "svg" of strips and pieces, and "dxf" of composites, strips and pieces
  /// (SceneSolverFabrication.cpp).
  ExportedFile fabricationExport(const std::string& format) const;
  /// A composite without a development whose shared S edges include seams (see cuttingParts).
  bool cutAlongSeams() const;

  /// The export's B-spline entities (exportAs "iges").
  void igesEntities(std::vector<io::IgesSurface>& surfaces, std::vector<io::IgesCurve>& curves) const;
  /// quad_mesh: metrics() and exportAs() (SceneSolverQuadMesh.cpp).
  proto::Metrics quadMeshMetrics() const;
  ExportedFile quadMeshExport(const std::string& format) const;
  /// A spline-surface quad_mesh's patches as entity-128 records (bicubic, PATCH<k>).
  void quadMeshIgesEntities(std::vector<io::IgesSurface>& surfaces) const;
  /// (Re)builds the quasi_strip model with the scene's options and an iteration limit (< 0: the
  /// scene's max_iterations, or the optimizer's default without one).
  void buildQuasiStrip(int iterations);

  proto::Scene scene_;
  engine::Deadline deadline_;
  bool sceneTimeBudgetApplies_ = true;
  models::strip::StripDesign initial_;
  std::unique_ptr<models::strip::StripModel> strip_;
  models::composite::CompositeDesign initialComposite_;
  std::unique_ptr<models::composite::CompositeModel> composite_;
  std::unique_ptr<models::quasi_strip::QuasiStripModel> quasi_;
  models::quasi_strip::QuasiStripSummary quasiSummary_;
  std::unique_ptr<models::conical_strip::ConicalStripModel> conical_;
  std::unique_ptr<models::quad_mesh::QuadMeshModel> quadMesh_;
  models::quad_mesh::QuadMeshDesign initialQuadMesh_;
  models::quad_mesh::QuadMeshSolveSummary quadMeshSummary_;
  /// The spline M^∞ of the scene's own control points (max, mean |K|·d², normal jump), analysed
  /// once: the report's "…_initial" metrics.
  struct InitialSplineMetrics {
    double gaussMaxScaled = 0.0, gaussMeanScaled = 0.0, normalJumpMaxDegrees = 0.0;
  } initialSpline_;
  std::string termination_;  ///< the model's own termination reason (quasi_strip, conical_strip)
};

}  // namespace devsurf::server
