#pragma once

#include <functional>
#include <memory>
#include <stdexcept>
#include <string>

#include <nlohmann/json.hpp>

#include "devsurf/engine/GuidedProjectionSolver.h"
#include "devsurf/models/composite/CompositeModel.h"
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

/// The service behind `devsurf solve` (and later batch jobs and sessions): builds the model a
/// scene describes ("strip" or "composite"), runs guided projection and reports.
class SceneSolver {
 public:
  /// Builds the model (validation happened in proto::sceneFromJson).
  /// @throws proto::SceneError for designs the model rejects
  explicit SceneSolver(proto::Scene scene);

  /// Runs the scene's solver settings (iterations overridden when ≥ 0).
  /// @param[in] onIteration  optional per-iteration callback; return false to abort
  engine::SolveSummary solve(int iterationsOverride = -1,
                             std::function<bool(const engine::IterationRecord&)> onIteration = {});

  /// The scene with the current geometry (valid input to solve again).
  proto::Scene currentScene() const;
  /// The papers' quality measures plus handle and displacement figures (names carry units).
  proto::Metrics metrics() const;
  /// The full report of the last solve.
  nlohmann::json report(const engine::SolveSummary& summary, double timeMs) const;

  /// Whether the scene is a strip (otherwise a composite).
  bool isStrip() const { return strip_ != nullptr; }
  /// @throws std::logic_error if the scene is not a strip
  models::strip::StripModel& stripModel();
  /// @throws std::logic_error if the scene is not a composite
  models::composite::CompositeModel& compositeModel();
  /// Writes an export "format:path" (format obj, off, ply, stl: the sampled surface; composites:
  /// all faces in one mesh, see CompositeGeometry::merged; fold, svg: the crease pattern of a
  /// composite with a development, CompositeModel::creasePattern, FOLD 1.2 or SVG in mm).
  /// @throws ExportUnavailable for an unknown format or one that does not apply, ExportFailed when
  ///         the model's state cannot be exported (both std::invalid_argument),
  ///         std::runtime_error if writing fails
  void exportTo(const std::string& spec) const;
  /// The export as bytes: "obj" (sampled surface as quads: strips 200×8, composites every face at
  /// 50 samples per span, 8 across, as exportTo), "fold" (FOLD 1.2) and "svg" (fold pattern, mm)
  /// for composites with a development.
  /// Lengths are design units (obj) or scaled by the scene's "units" (fold: frame_unit; svg: mm).
  /// @throws ExportUnavailable for an unknown format or one that does not apply to this scene,
  ///         ExportFailed when the model's current state cannot be exported
  ExportedFile exportAs(const std::string& format) const;
  /// exportAs of a scene document (a session's current scene, a job's solved scene): builds the
  /// model first; a document or design the model now rejects is ExportFailed too.
  static ExportedFile exportScene(const nlohmann::json& scene, const std::string& format);

 private:
  /// The crease pattern of the composite's development in the scene's units, for `format`.
  /// @throws ExportUnavailable (not a composite, no development), ExportFailed (rejected state)
  io::CreasePattern creasePattern(const std::string& format) const;

  proto::Scene scene_;
  models::strip::StripDesign initial_;
  std::unique_ptr<models::strip::StripModel> strip_;
  models::composite::CompositeDesign initialComposite_;
  std::unique_ptr<models::composite::CompositeModel> composite_;
};

}  // namespace devsurf::server
