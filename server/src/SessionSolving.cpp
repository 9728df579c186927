// Session: solving — the geometry each solve publishes, a drag's frames, releases in two phases, the fold slider's release, polish
// and settle — and publishing each solve.
#include "devsurf/server/Session.h"

#include <algorithm>
#include <chrono>
#include <cmath>

#include "devsurf/proto/Geometry.h"

#include "SessionPointRefs.h"

namespace devsurf::server {
namespace {

using nlohmann::json;
namespace composite = models::composite;
namespace qm = models::quad_mesh;

}  // namespace

using detail::nonFiniteMetric;

const engine::Problem& Session::problem() const {
  if (isComposite()) return solver_->compositeModel().problem();
  if (solver_->isQuadMesh()) return solver_->quadMeshModel().problem();
  return solver_->stripModel().problem();
}

json Session::geometryJson(json* iterateMetrics) const {
  if (keepsInput()) {
    if (iterateMetrics) *iterateMetrics = json(solver_->metrics());
    if (solver_->isConicalStrip()) return proto::conicalStripGeometryJson(solver_->conicalStripModel());
    return proto::quasiStripGeometryJson(solver_->quasiStripModel(), settings_.surfaceSamples);
  }
  if (solver_->isQuadMesh()) {
    const qm::QuadMeshModel& model = solver_->quadMeshModel();
    const qm::QuadMeshQuality q = model.quality();
    if (iterateMetrics)
      *iterateMetrics = {{"length_error", q.lengthError}, {"edge_length_error_max", q.edgeLengthErrorMax},
                         {"area_error", q.areaError},
                         {"isometry_residual_max", q.isometryResidualMax}, {"glue_gap_max", q.glueGapMax},
                         {"unfolding_flipped_faces", q.unfoldingFlippedFaces}};
    // Approximating a reference (issue 15): its distance to M, every iterate (watch it fit).
    if (iterateMetrics && model.reference()) {
      try {
        for (const auto& [name, value] : solver_->referenceMetrics(model.reference()->vertices, 0.0))
          (*iterateMetrics)["approximation_" + name.substr(std::string("reference_").size())] = value;
      } catch (const std::exception&) {
        // A degenerate M has no distances; the length error says what went wrong.
      }
    }
    return proto::quadMeshGeometryJson(model, q);
  }
  if (isComposite()) {
    const composite::CompositeModel& model = solver_->compositeModel();
    const composite::CompositeQuality q = model.quality();
    if (iterateMetrics)
      *iterateMetrics = {{"face_flatness_max", q.faceFlatnessMax}, {"face_flatness_mean", q.faceFlatnessMean},
                         {"vertex_curvature_max", q.vertexCurvatureMax},
                         {"crease_fold_residual_max", q.creaseFoldResidualMax},
                         {"crease_fold_angle_max_deg", q.foldAngleMaxDeg},
                         {"warp_angle_max_deg", q.warpAngleMaxDeg}, {"warp_angle_mean_deg", q.warpAngleMeanDeg},
                         {"ruling_length_min_ratio", model.rulingLengthMinRatio()},
                         {"crease_backtrack_max", model.creaseBacktrackMax()}};
    if (iterateMetrics && model.hasDevelopment())
      (*iterateMetrics)["development_flipped_faces"] = model.flippedDevelopmentFaces();
    return proto::compositeGeometryJson(model, q, settings_.compositeSamplesPerSpan);
  }
  if (iterateMetrics) {
    const metrics::StripQuality q = solver_->stripModel().quality(200);
    *iterateMetrics = {{"warp_angle_max_deg", q.warpAngleMaxDeg}, {"warp_angle_mean_deg", q.warpAngleMeanDeg},
                       {"ruling_length_min_ratio", solver_->stripModel().rulingLengthMinRatio()}};
  }
  json geometry = proto::stripGeometryJson(solver_->stripModel(), settings_.surfaceSamples);
  // A fitted strip: how close it is to its reference points, every iterate (watch it fit); each
  // point's distance rides with the geometry, so the web app colours the points by it.
  if (const auto& target = solver_->stripModel().approximation()) {
    try {
      Eigen::VectorXd distances;
      const proto::Metrics measured = solver_->referenceMetrics(target->points, 0.0, &distances);
      if (iterateMetrics)
        for (const auto& [name, value] : measured)
          (*iterateMetrics)["approximation_" + name.substr(std::string("reference_").size())] = value;
      geometry["approximation_distances"] = std::vector<double>(distances.data(), distances.data() + distances.size());
      geometry["approximation_tolerance"] = measured.at("reference_coverage_tolerance");
    } catch (const std::exception&) {
      // A degenerate surface has no distances; the warp metrics say what went wrong.
    }
  }
  return geometry;
}

void Session::publishSolve(bool final) {
  const std::int64_t seq = seq_.load();
  json metrics;
  json geometry = geometryJson(&metrics);
  const std::string bad = nonFiniteMetric(metrics);
  if (!bad.empty()) return rollBack("the solve gave a non-finite " + bad);
  if (!showState()) return;
  const std::string residual = solver_->isQuasiStrip() ? "objective" : "normal_variation";
  broadcast({{"type", "iterate"}, {"seq", seq}, {"revision", revision_}, {"iteration", lastSummary_.stepsTaken()},
             {"residuals", {{residual, metrics.value(residual, 0.0)}}},
             {"metrics", metrics},
             {"time_ms", lastSummary_.totalMs},
             {"geometry", std::move(geometry)}},
            Delivery::Latest, "iterate");
  if (final) {
    broadcast({{"type", "solved"}, {"seq", seq}, {"revision", revision_}, {"metrics", metrics},
               {"reason", solver_->keepsInputGeometry() && !solver_->termination().empty()
                              ? solver_->termination()
                              : std::string(engine::terminationReasonName(lastSummary_.reason))},
               {"iterations", lastSummary_.stepsTaken()}});
  }
}

SolveLimits Session::pointDragLimits(SolveLimits limits) const {
  if (isComposite() && solver_->compositeModel().hasDevelopment()) {
    limits.hardBand = solver_->compositeModel().rulingCreases() ? settings_.developedDragHardBandRulingCreases
                                                                 : settings_.developedDragHardBand;
    limits.correctionSteps = settings_.developedCorrectionSteps;
  }
  return limits;
}

SolveLimits Session::foldLimits(SolveLimits limits) const {
  if (isComposite() && solver_->compositeModel().hasDevelopment()) limits.correctionSteps = settings_.developedCorrectionSteps;
  return limits;
}

bool Session::runSolver(SolveLimits limits, bool final) {
  if (keepsInput()) {  // solved whole when the model was rebuilt
    publishSolve(final);
    return true;
  }
  const std::int64_t seq = seq_.load();
  if (!(limits.hardBand > 0.0)) limits.hardBand = settings_.dragHardBand;
  limits.firstIteration = scheduleIteration_;
  // The solve budgets of a session (drag frames, releases, solve) count the CPU time of this
  // thread: on a busy machine a drag frame or a release takes longer but ends where it would on an
  // idle one (a release's fold under a CI run's load once stopped at 35° of 90°), within
  // budgetWallCap times its budget of wall time. Newer work still interrupts a solve at once
  // (onIteration), so the pointer does not wait for a frame's budget.
  limits.budgetClock = engine::BudgetClock::ThreadCpu;
  if (limits.timeBudgetMs > 0.0) limits.budgetWallCapMs = settings_.budgetWallCap * limits.timeBudgetMs;
  bool interrupted = false;
  std::string failure;  // a state that must not be shown: rolled back after the solve returns
  int streamedIteration = 0;
  // An iterate as the participants get it (geometry, metrics, residuals by term name), made
  // durable first (checkpoint): whatever a participant is shown, a restart restores.
  auto stream = [this, seq, &streamedIteration, &failure](const engine::IterationRecord& r) {
    const auto started = std::chrono::steady_clock::now();
    json residuals = json::object();
    const engine::Problem& terms = problem();  // per-term residuals by name (same names summed)
    for (int t = 0; t < terms.numTerms(); ++t) {
      const std::string& n = terms.term(t).term->name();
      residuals[n] = residuals.value(n, 0.0) + r.termResiduals[t];
    }
    json metrics;
    json geometry = geometryJson(&metrics);
    if (const std::string bad = nonFiniteMetric(metrics); !bad.empty()) {
      failure = "the solve gave a non-finite " + bad;
      return false;
    }
    if (!checkpoint(&failure)) return false;
    broadcast({{"type", "iterate"}, {"seq", seq}, {"revision", revision_}, {"iteration", r.iteration},
               {"residuals", residuals},
               {"hard_max", r.hardResidualMax},
               {"step_scale", r.stepScale},
               {"metrics", std::move(metrics)},
               {"time_ms", r.totalMs},
               {"geometry", std::move(geometry)}},
              Delivery::Latest, "iterate");
    streamedIteration = r.iteration;
    lastStreamed_ = std::chrono::steady_clock::now();
    lastStreamMs_ = std::chrono::duration<double, std::milli>(lastStreamed_ - started).count();
    return true;
  };
  // Every iterate is streamed unless the last one went out less than streamIntervalMs ago (the
  // geometry of a large model costs more than its iteration: folded annulus 50 vs 12 ms); the
  // last iterate of every solve always goes out.
  auto onIteration = [this, &interrupted, &stream](const engine::IterationRecord& r) {
    if (r.iteration == 0) return !(interrupted = hasQueuedWork());
    changed_ = true;
    if (counters_) counters_->recordIteration(r.totalMs);
    const double since = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - lastStreamed_).count();
    // The first step of every solve goes out at once (a drag message's answer: the latency the
    // pointer feels), the rest at most every interval.
    if ((r.iteration == 1 || since >= std::max(settings_.streamIntervalMs, 2.0 * lastStreamMs_)) && !stream(r))
      return false;  // a state that must not be shown: stop here, roll back below
    return !(interrupted = hasQueuedWork());
  };
  const engine::SolveSummary summary = solver_->solve(limits, onIteration);
  scheduleIteration_ += summary.stepsTaken();
  // The last iterate goes out unless newer work interrupted the solve (that work's first step
  // follows at once and supersedes it).
  if (failure.empty() && !interrupted && summary.stepsTaken() > 0 &&
      streamedIteration != summary.iterations.back().iteration)
    stream(summary.iterations.back());
  if (!failure.empty()) {
    rollBack(failure);
    return true;  // the interaction ended here: nothing more to show
  }
  if (summary.reason == engine::TerminationReason::Diverged) {
    if (counters_) counters_->recordError("diverged");
    broadcast({{"type", "error"}, {"code", "diverged"}, {"seq", seq},
               {"message", "the solver diverged; the session keeps its last good state"}});
  }
  if (final && interrupted) settlePending_ = true;  // settle() finishes it once the session is idle
  if (final && !interrupted) {
    settlePending_ = false;
    if (!showState()) return true;  // what a client reads after `solved` is what a restart restores
    if (foldTargetsChangedUnsent_) {
      // The release took the drag's folds as the design's targets: the scene every client holds
      // (and saves to a file) gets them, with the amount they go with.
      foldTargetsChangedUnsent_ = false;
      broadcastUpdate();
    }
    broadcast({{"type", "solved"}, {"seq", seq}, {"revision", revision_}, {"metrics", metricsJson()},
               {"reason", engine::terminationReasonName(summary.reason)},
               {"iterations", summary.stepsTaken()},
               {"quality", solver_->quality().toJson()},
               {"undo", undoCountsJson()}});
  }
  return !interrupted;
}

void Session::release(const json& target, int iterations) {
  const engine::ThreadCpuClock::time_point start = engine::ThreadCpuClock::now();
  // Phase 1: the handle catches up with the pointer as far as the hard rows allow.
  SolveLimits withHandle;
  withHandle.iterations = iterations;
  withHandle.timeBudgetMs = settings_.releaseHandleShare * settings_.releaseTimeBudgetMs;
  const bool finished = keepsInput() || iterations == 0 || runSolver(pointDragLimits(withHandle), false);
  releaseDragHandle(target);
  if (!finished) {  // newer work waits: it continues from here, and settle() ends the release later
    settlePending_ = true;
    settleAfterDrag_ = true;
    return;
  }
  // A design folded by fold-angle targets keeps the fold the drag left: its angles become the
  // targets at the slider's amount, held through the projections (holdsFoldTargets). A flat one
  // (0 %) that the drag folded takes the amount it folded to first; one it did not fold the way its
  // creases go (a mountain pulled up as a valley) keeps its targets, and the projections hold the
  // sheet to them — flat — rather than leave it folded at 0 %.
  if (hasFoldAngles() && dragHandles_.empty()) {
    if (solver_->compositeModel().captureFoldTargets()) foldTargetsChangedUnsent_ = true;
    solver_->compositeModel().holdFoldTargets(true);
    if (!(solver_->compositeModel().foldAmount() > 0.0)) {
      // Still at 0 %: the targets pull the sheet back flat first (the projections alone stop at
      // once — a hinge turned rigidly breaks no hard row), as the slider's own release does, but
      // with plain steps (the drag's band; foldLimits' correction steps are not measured here).
      SolveLimits withTargets;
      withTargets.iterations = iterations;
      withTargets.timeBudgetMs = settings_.releaseHandleShare * settings_.releaseTimeBudgetMs;
      if (!runSolver(withTargets, false)) {
        settlePending_ = true;
        return;
      }
    }
  }
  polishRelease(start, iterations, hasFoldAngles());
}

bool Session::hasFoldAngles() const {
  // From the model, not a copy of the scene: asked on every drag message.
  return isComposite() && solver_->compositeModel().hasFoldTargets();
}

bool Session::holdsFoldTargets() const {
  // A design folded by its fold-angle targets keeps them through a release's projections: a curved
  // fold's sheet, its short edges strained at the crease ends, would otherwise project back to the
  // flat drawing — the one state every hard row meets exactly (one drag unfolded a drawn sheet).
  return hasFoldAngles() && solver_->compositeModel().foldAmount() > 0.0;
}

void Session::releaseFold(int iterations) {
  const engine::ThreadCpuClock::time_point start = engine::ThreadCpuClock::now();
  // Phase 1: the creases catch up with the slider's amount as far as the hard rows allow (the
  // fold-angle rows are relaxable, like a handle).
  SolveLimits withTargets;
  withTargets.iterations = iterations;
  withTargets.timeBudgetMs = settings_.releaseHandleShare * settings_.releaseTimeBudgetMs;
  const bool finished = iterations == 0 || runSolver(foldLimits(withTargets), false);
  if (!finished) {
    settlePending_ = true;
    return;
  }
  polishRelease(start, iterations, true);  // the slider's position holds through the projections
}

void Session::polishRelease(engine::ThreadCpuClock::time_point start, int iterations, bool holdFoldTargets) {
  using Clock = engine::ThreadCpuClock;  // as every budget of a session (runSolver)
  // Phase 2: projection steps (no handles, no fairness) until every hard row is within the
  // tolerance: feasibility restored with the least motion.
  SolveLimits polish;
  // To quality within the time budget, not to a count: cheap models (a strip iterates in ~0.2 ms)
  // may need several hundred projections to bring a badly bent strip to the tolerance.
  polish.iterations = std::max(iterations, settings_.maxIterationsPerRequest);
  polish.hardTolerance = settings_.releaseHardTolerance;
  polish.projectionOnly = true;
  polish.holdTargetsInProjection = holdFoldTargets;
  polish.regularization = settings_.polishRegularization;
  polish.timeBudgetMs = std::max(
      1.0, settings_.releaseTimeBudgetMs - std::chrono::duration<double, std::milli>(Clock::now() - start).count());
  runSolver(polish, true);
}

void Session::settle() {
  settlePending_ = false;
  const bool afterDrag = settleAfterDrag_;
  settleAfterDrag_ = false;
  SolveLimits polish;
  polish.iterations = settings_.maxIterationsPerRequest;
  polish.hardTolerance = settings_.releaseHardTolerance;
  polish.projectionOnly = true;
  // As release(): a design folded by its targets takes the fold it has as targets. At 0 % only
  // after a drag's release: the slider let go at 0 % and interrupted must not jump back up to
  // what the sheet had not yet unfolded.
  if (hasFoldAngles() && dragHandles_.empty() && (holdsFoldTargets() || afterDrag)) {
    // Only a drag's release sends the new targets: after a fold of the slider they are its own
    // angles again (to rounding), and an `update` would carry a whole scene to every client each
    // time the session goes idle between two frames of a Play.
    if (solver_->compositeModel().captureFoldTargets() && afterDrag) foldTargetsChangedUnsent_ = true;
    solver_->compositeModel().holdFoldTargets(true);
  }
  polish.holdTargetsInProjection = hasFoldAngles();
  polish.regularization = settings_.polishRegularization;
  polish.timeBudgetMs = settings_.releaseTimeBudgetMs;
  runSolver(polish, true);
}

}  // namespace devsurf::server
