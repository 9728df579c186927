#pragma once

#include <array>
#include <stdexcept>
#include <string>
#include <variant>

#include <nlohmann/json.hpp>

#include "devsurf/engine/GuidedProjectionSolver.h"
#include "devsurf/models/composite/CompositeModel.h"
#include "devsurf/models/conical_strip/ConicalStripModel.h"
#include "devsurf/models/quad_mesh/QuadMeshModel.h"
#include "devsurf/models/quasi_strip/QuasiStripModel.h"
#include "devsurf/models/strip/StripModel.h"
#include "devsurf/proto/JsonSchemaValidator.h"
#include "devsurf/proto/ResourceLimits.h"

namespace devsurf::proto {

/// Largest magnitude of a coordinate in a scene (scene units). Larger ones are refused by name
/// (`model.b.points[3][2]`): the solver works in normalized coordinates, and the norms of far larger
/// ones overflow.
inline constexpr double kMaxCoordinate = 1e9;  // quoted as "±1e9" in the error

/// A document that failed validation: `path` is the JSON path ("model.a.points[3]"), `rule` the
/// schema keyword or semantic rule broken, what() the full message "path: message".
class SceneError : public std::runtime_error {
 public:
  SceneError(std::string path, std::string rule, const std::string& message);
  const std::string& path() const { return path_; }
  const std::string& rule() const { return rule_; }

 private:
  std::string path_, rule_;
};

/// The `solver` object of a scene, with the documented defaults of scene.schema.json.
struct SolverSettings {
  int iterations = 20;
  double fairness = 0.01;
  double fairnessDecay = 0.8;
  double regularization = 1e-2;
  double unitNormalWeight = 0.1;
  /// Composite crease-row softening breakpoints ξ1…ξ4 (003_… §5.5); (0, 0, 1, 1) = off.
  std::array<double, 4> softening = {0.0, 0.0, 1.0, 1.0};
  double developabilityWeight = 1.0;
  double handleWeight = 1.0;
  double timeBudgetMs = 0.0;
  double residualTolerance = 1e-14;
  double relativeChangeTolerance = 1e-9;
  std::string linearSolver = "auto";
  bool normalize = true;
  bool stepControl = true;      ///< "step_control": engine::StepControlOptions::enabled
  double hardBand = 0.1;        ///< "hard_band": engine::StepControlOptions::hardBand (batch solves;
                                ///< sessions stream with SessionSettings::dragHardBand)
  double hardTolerance = 0.0;   ///< "hard_tolerance": engine::SolverOptions::hardTolerance
  bool normalSplines = false;   ///< "normal_splines": models::composite::CompositeOptions::normalSplines
  std::string creaseNormals = "auto";  ///< "crease_normals": models::composite::CompositeOptions::creaseNormals
  std::string developmentSolve = "coupled";  ///< "development_solve": models::composite::CompositeOptions::developmentSolve

  engine::SolverOptions solverOptions() const;
  models::strip::StripOptions stripOptions() const;
  models::composite::CompositeOptions compositeOptions() const;
};

/// Scene kind "quasi_strip" (Bo et al.): the design (two curves, mapping, samples, end-point
/// fixing, extension) and the model's own settings (method, optimizer, λ1, λ2, iteration limit).
/// The scene's `solver` object applies only through `time_budget_ms`.
struct QuasiStripScene {
  models::quasi_strip::QuasiStripDesign design;
  models::quasi_strip::QuasiStripOptions options;
  /// Scene field "max_iterations": iterations of the chosen optimizer; 0 = the optimizer's default
  /// (L-BFGS options.lbfgs.maxIterations = 3000, guided projection options.maxIterations = 200).
  int maxIterations = 0;
};

/// One variant per model kind ("strip", "composite", "quasi_strip", "conical_strip", "quad_mesh").
/// conical_strip (Chu et al.) is its design alone: the greedy construction has no solver settings.
/// quad_mesh (Jiang et al. 2020) carries its own weights and Algorithm-1 schedule; of the scene's
/// solver object it uses iterations (all rounds together), regularization, tolerances, time budget,
/// linear solver, normalize and step control (not fairness/fairness_decay).
using ModelData = std::variant<models::strip::StripDesign, models::composite::CompositeDesign, QuasiStripScene,
                               models::conical_strip::ConicalStripDesign, models::quad_mesh::QuadMeshDesign>;

/// The scene kind of a model ("strip", "composite", "quasi_strip", "conical_strip", "quad_mesh").
const char* modelKind(const ModelData& model);

/// A scene document (format "devsurf-scene", version 1): a saved design, a batch job, a CLI
/// input and a session's starting point.
struct Scene {
  std::string name;
  /// One plain sentence for lists and the start page's cards (scene field "summary"); empty: the
  /// web app shows the first sentence of `description`.
  std::string summary;
  std::string description;
  /// Length unit of the design coordinates (scene field "units": "mm", "cm", "m" or "in"; default
  /// "mm"): what one model unit is on paper. Scales the fold/svg exports of the development.
  std::string units = "mm";
  ModelData model;
  SolverSettings solver;
};

/// Millimetres per design unit of a scene's "units" ("mm" 1, "cm" 10, "m" 1000, "in" 25.4).
/// @throws std::invalid_argument for any other unit
double millimetresPerUnit(const std::string& units);

/// The embedded JSON Schemas of proto/schemas (every *.schema.json).
const SchemaRegistry& schemaRegistry();
/// Any embedded document of proto/schemas by file name (e.g. "openapi.json").
/// @throws std::out_of_range
const nlohmann::json& embeddedDocument(const std::string& name);

/// Validates against scene.schema.json, then checks what a schema cannot say (degrees and knots
/// that match, indices in range, knot vector rules), converts, and checks the result against
/// `limits` (checkResourceLimits: control points per scene, iterations, the estimated memory)
/// before any model is built.
/// @throws SceneError naming the JSON path and rule of the first problem found (rule "limit" for
///         a resource limit)
Scene sceneFromJson(const nlohmann::json& document, const ResourceLimits& limits = {});
/// Parses text first (a parse error is a SceneError with path "(root)" and rule "json").
Scene sceneFromText(const std::string& text, const ResourceLimits& limits = {});

/// Where a scene's control points are: the centre and the diagonal of their bounding box (handles
/// and the development left out).
struct SceneExtent {
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();
  double diagonal = 0.0;
};
SceneExtent sceneExtent(const Scene& scene);

/// How far from a scene's centre, in multiples of its diagonal, a dragged point or a handle may be
/// put (an edit farther away is refused, naming "position").
inline constexpr double kMaxReach = 100.0;

/// The scene as a document that sceneFromJson reads back (curves keep their structure; knots are
/// written only when they differ from the default clamped uniform ones).
nlohmann::json sceneToJson(const Scene& scene);

/// A curve in the scene's JSON form, and back.
nlohmann::json curveToJson(const spline::BSplineCurve& curve);
spline::BSplineCurve curveFromJson(const nlohmann::json& j, const std::string& path);

}  // namespace devsurf::proto
