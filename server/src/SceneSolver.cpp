#include "devsurf/server/SceneSolver.h"

#include <algorithm>
#include <cstdio>
#include <sstream>
#include <stdexcept>

#include "devsurf/cad/StepWriter.h"
#include "devsurf/io/OneLine.h"
#include "devsurf/io/CuttingPatternSvg.h"
#include "devsurf/io/FoldWriter.h"
#include "devsurf/io/SvgFoldPattern.h"
#include "devsurf/models/composite/CompositePieces.h"
#include "devsurf/models/conical_strip/ArcLengthCurve.h"
#include "devsurf/models/quad_mesh/SplineSurface.h"

namespace devsurf::server {

namespace quasi = models::quasi_strip;
namespace conical = models::conical_strip;

namespace {

/// A composite's quality: the largest relative change of length of an edge of its crease pattern.
constexpr double kEdgeStrainLimit = 0.1;

/// Entity 126 of a curve (periodic curves with their wrapped control points written out).
io::IgesCurve igesCurve(const spline::BSplineCurve& c, const std::string& label) {
  io::IgesCurve out;
  out.degree = c.degree();
  out.knots = c.knots.knots();
  const int slots = c.knots.numSlots();
  out.points.resize(slots, 3);
  if (c.isRational()) out.weights.resize(slots);
  for (int i = 0; i < slots; ++i) {
    const int k = c.knots.controlIndex(i);
    out.points.row(i) = c.points.row(k).leftCols(3);
    if (c.isRational()) out.weights[i] = c.weights[k];
  }
  out.label = label;
  return out;
}

/// Entity 128 of the ruled surface (1 − v)·side0(u) + v·side1(u) with both sides on `knots`.
io::IgesSurface igesRuledSurface(int degree, const std::vector<double>& knots, const Eigen::MatrixX3d& side0,
                                 const Eigen::MatrixX3d& side1, const std::string& label) {
  io::IgesSurface s;
  s.degreeU = degree;
  s.degreeV = 1;
  s.nu = static_cast<int>(side0.rows());
  s.nv = 2;
  s.knotsU = knots;
  s.knotsV = {0.0, 0.0, 1.0, 1.0};
  s.points.resize(2 * s.nu, 3);
  s.points.topRows(s.nu) = side0;
  s.points.bottomRows(s.nu) = side1;
  s.label = label;
  return s;
}

engine::TerminationReason engineReason(const std::string& name) {
  if (name == "residual_tolerance" || name == "gradient_tolerance" || name == "absolute_tolerance")
    return engine::TerminationReason::ResidualTolerance;
  if (name == "warp_tolerance") return engine::TerminationReason::ResidualTolerance;
  if (name == "relative_change" || name == "relative_decrease" || name == "line_search_failed" ||
      name == "step_rejected" || name == "warp_stalled")
    return engine::TerminationReason::RelativeChange;
  if (name == "time_budget") return engine::TerminationReason::TimeBudget;
  if (name == "aborted") return engine::TerminationReason::Aborted;
  if (name == "diverged") return engine::TerminationReason::Diverged;
  return engine::TerminationReason::MaxIterations;
}

}  // namespace

SceneSolver::SceneSolver(proto::Scene scene, engine::Deadline deadline)
    : scene_(std::move(scene)), deadline_(std::move(deadline)) {
  if (std::holds_alternative<proto::QuasiStripScene>(scene_.model)) {
    buildQuasiStrip(-1);
    return;
  }
  if (const auto* c = std::get_if<conical::ConicalStripDesign>(&scene_.model)) {
    try {
      conical::ConicalStripOptions options;
      options.deadline = deadline_;
      conical_ = std::make_unique<conical::ConicalStripModel>(*c, options);
    } catch (const std::invalid_argument& e) {
      throw proto::SceneError("model", "model", e.what());
    }
    return;
  }
  if (const auto* q = std::get_if<models::quad_mesh::QuadMeshDesign>(&scene_.model)) {
    initialQuadMesh_ = *q;
    models::quad_mesh::QuadMeshOptions options;
    options.normalize = scene_.solver.normalize;
    options.linearSolver = scene_.solver.compositeOptions().linearSolver;
    options.deadline = deadline_;
    try {
      quadMesh_ = std::make_unique<models::quad_mesh::QuadMeshModel>(initialQuadMesh_, options);
      if (initialQuadMesh_.control) {
        const models::quad_mesh::SplineSurfaceAnalysis before =
            models::quad_mesh::analyzeSplineSurface(*initialQuadMesh_.control, initialQuadMesh_.control->points);
        initialSpline_ = {before.gaussMaxScaled, before.gaussMeanScaled, before.normalJumpMaxDegrees};
      }
    } catch (const std::invalid_argument& e) {
      throw proto::SceneError("model", "model", e.what());
    }
    return;
  }
  if (const auto* c = std::get_if<models::composite::CompositeDesign>(&scene_.model)) {
    initialComposite_ = *c;
    models::composite::CompositeOptions options = scene_.solver.compositeOptions();
    options.deadline = deadline_;
    try {
      composite_ = std::make_unique<models::composite::CompositeModel>(initialComposite_, options);
    } catch (const std::invalid_argument& e) {
      throw proto::SceneError("model", "model", e.what());
    }
    return;
  }
  initial_ = std::get<models::strip::StripDesign>(scene_.model);
  models::strip::StripOptions options = scene_.solver.stripOptions();
  options.deadline = deadline_;
  try {
    strip_ = std::make_unique<models::strip::StripModel>(initial_, options);
  } catch (const std::invalid_argument& e) {
    throw proto::SceneError("model", "model", e.what());
  }
}

void SceneSolver::buildQuasiStrip(int iterations) {
  const proto::QuasiStripScene& q = std::get<proto::QuasiStripScene>(scene_.model);
  quasi::QuasiStripOptions options = q.options;
  // An override (≥ 0) wins, then the scene's max_iterations; else the optimizer's default.
  const int limit = iterations >= 0 ? iterations : q.maxIterations;
  if (iterations >= 0 || q.maxIterations > 0) {
    options.maxIterations = limit;
    options.lbfgs.maxIterations = limit;
    options.polishIterations = std::min(options.polishIterations, limit);
  }
  if (scene_.solver.timeBudgetMs > 0.0 && sceneTimeBudgetApplies_) {
    options.timeBudgetMs = scene_.solver.timeBudgetMs;
    options.lbfgs.timeBudgetMs = scene_.solver.timeBudgetMs;
  }
  options.deadline = deadline_;
  try {
    quasi_ = std::make_unique<quasi::QuasiStripModel>(q.design, options);
  } catch (const std::invalid_argument& e) {
    throw proto::SceneError("model", "model", e.what());
  }
}

const quasi::QuasiStripModel& SceneSolver::quasiStripModel() const {
  if (!quasi_) throw std::logic_error("SceneSolver: the scene is not a quasi_strip");
  return *quasi_;
}

const conical::ConicalStripModel& SceneSolver::conicalStripModel() const {
  if (!conical_) throw std::logic_error("SceneSolver: the scene is not a conical_strip");
  return *conical_;
}

models::quad_mesh::QuadMeshModel& SceneSolver::quadMeshModel() {
  if (!quadMesh_) throw std::logic_error("SceneSolver: the scene is not a quad_mesh");
  return *quadMesh_;
}

const models::quad_mesh::QuadMeshModel& SceneSolver::quadMeshModel() const {
  if (!quadMesh_) throw std::logic_error("SceneSolver: the scene is not a quad_mesh");
  return *quadMesh_;
}

models::strip::StripModel& SceneSolver::stripModel() {
  if (!strip_) throw std::logic_error("SceneSolver: the scene is not a strip");
  return *strip_;
}

models::composite::CompositeModel& SceneSolver::compositeModel() {
  if (!composite_) throw std::logic_error("SceneSolver: the scene is not a composite");
  return *composite_;
}

engine::SolveSummary SceneSolver::solve(int iterationsOverride,
                                        std::function<bool(const engine::IterationRecord&)> onIteration) {
  SolveLimits limits;
  limits.iterations = iterationsOverride;
  return solve(limits, std::move(onIteration));
}

proto::Scene SceneSolver::solvedScene(const proto::Scene& scene) {
  SceneSolver solver(scene);
  if (solver.keepsInputGeometry()) return scene;
  solver.solve();
  return solver.currentScene();
}

void SceneSolver::resetStepControl() {
  if (composite_) composite_->solver().resetStepControl();
  if (quadMesh_) quadMesh_->solver().resetStepControl();
  if (strip_) strip_->solver().resetStepControl();
}

nlohmann::json QualityVerdict::toJson() const {
  nlohmann::json list = nlohmann::json::array();
  for (const QualityCheck& c : checks)
    list.push_back({{"metric", c.metric}, {"value", c.value}, {"limit", c.limit}, {"ok", c.ok}});
  return {{"met", met}, {"checks", list}};
}

QualityVerdict SceneSolver::quality() const {
  if (quasi_) return {};  // Bo et al. give no thresholds
  return quality(metrics());
}

QualityVerdict SceneSolver::quality(const proto::Metrics& m) const {
  QualityVerdict v;
  if (quasi_) return v;  // Bo et al. give no thresholds; the warp angle is reported, not held
  auto atMost = [&v, &m](const std::string& name, double limit) {
    const auto it = m.find(name);
    if (it == m.end()) return;
    const bool ok = it->second <= limit;  // NaN fails
    v.checks.push_back({name, it->second, limit, ok});
    v.met = v.met && ok;
  };
  auto atLeast = [&v, &m](const std::string& name, double limit) {
    const auto it = m.find(name);
    if (it == m.end()) return;
    const bool ok = it->second >= limit;
    v.checks.push_back({name, it->second, limit, ok});
    v.met = v.met && ok;
  };
  if (composite_) {
    atMost("face_flatness_max", 1e-3);
    atMost("face_flatness_mean", 2e-4);
    atMost("vertex_curvature_max", 1e-3);
    atMost("development_flipped_faces", 0.0);
    atMost("development_length_error", 5e-3);
    // −cos of the sharpest turn between neighbouring legs of an S-edge polygon: 0 is a right
    // angle, 1 a polygon folded back on itself. The guard (PolygonBacktrackTerm) is a hinge with a
    // C¹ ramp of width 0.05, so a converged polygon held by it may sit slightly past 90°.
    atMost("crease_backtrack_max", 0.05);
    atLeast("ruling_length_min_ratio", 0.25);
    // No edge of the crease pattern stretched or shrunk by a tenth: a sheet torn or crumpled to
    // meet what it cannot (the length error, weighted by l², hides a short edge stretched several
    // times over; the shipped presets measure at most 0.067, the folded annulus's short edges).
    atMost("development_edge_strain_max", kEdgeStrainLimit);
    // A design folded by fold-angle targets reaches them: within 15 % of the largest target at
    // this amount, and 1° (a sheet that stays flat under a 90° target misses by 90°).
    if (m.count("fold_angle_error_max_deg") != 0) {
      double largest = 0.0;
      for (const models::composite::FoldAngleTarget& t : composite_->design().foldAngles)
        largest = std::max(largest, std::abs(t.angleDeg));
      const double amount = m.count("fold_amount") != 0 ? m.at("fold_amount") : 1.0;
      atMost("fold_angle_error_max_deg", 1.0 + 0.15 * amount * largest);
    }
  } else if (quadMesh_) {
    // Fig. 22: L-Err up to 0.38 % for solvable isometry tasks (8b), 4.2 % for the conformal map of
    // Fig. 4; glued pairs together; M′ not folded over.
    atMost("length_error", quadMesh_->design().conformal ? 0.05 : 5e-3);
    atMost("glue_gap_max", 1e-4);
    atMost("unfolding_flipped_faces", 0.0);
  } else if (conical_) {
    // Chu et al. give no thresholds; the greedy strip must not fold back on itself: no two
    // neighbouring patches' tangent planes meet at more than a right angle (the G1 adjustment then
    // twists the strip around that ruling instead of smoothing a bend).
    atMost("greedy_normal_jump_max_rad", 1.5707963267948966);  // π/2
  } else {
    atMost("warp_angle_max_deg", 0.05);
    atLeast("ruling_length_min_ratio", 0.25);
  }
  return v;
}

engine::SolveSummary SceneSolver::solve(const SolveLimits& limits,
                                        std::function<bool(const engine::IterationRecord&)> onIteration) {
  const int iterationsOverride = limits.iterations;
  engine::SolverOptions options = scene_.solver.solverOptions();
  if (iterationsOverride >= 0) options.maxIterations = iterationsOverride;
  if (limits.timeBudgetMs >= 0.0) options.timeBudgetMs = limits.timeBudgetMs;
  options.budgetClock = limits.budgetClock;
  options.budgetWallCapMs = limits.budgetWallCapMs;
  if (limits.hardTolerance >= 0.0) options.hardTolerance = limits.hardTolerance;
  if (limits.hardBand > 0.0) options.stepControl.hardBand = limits.hardBand;
  if (limits.correctionSteps >= 0) options.correctionSteps = limits.correctionSteps;
  options.firstIteration = std::max(0, limits.firstIteration);
  if (limits.regularization >= 0.0) options.regularization = limits.regularization;
  options.projectionOnly = limits.projectionOnly;
  options.holdTargetsInProjection = limits.holdTargetsInProjection;
  options.callback = std::move(onIteration);
  options.deadline = deadline_;
  if (quasi_) {
    if (iterationsOverride >= 0)
      buildQuasiStrip(iterationsOverride);
    else
      quasi_->setDeadline(deadline_);
    quasiSummary_ = quasi_->solve();
    // The model's reason may be compound ("warp_stalled, then guided projection: relative_change"):
    // the report's termination is the engine reason of the polish when it stopped on a tolerance of
    // its own, else of L-BFGS (the polish has a fixed step budget); result.termination is all of it.
    // The fallback to the initial mapping is named as such.
    const std::string& full = quasiSummary_.termination;
    const std::string polish = ", then guided projection: ";
    const std::size_t split = full.rfind(polish);
    std::string phase = split == std::string::npos ? full : full.substr(split + polish.size());
    if (split != std::string::npos && engineReason(phase) == engine::TerminationReason::MaxIterations)
      phase = full.substr(0, split);
    termination_ = full == quasi::kIdentityFallback ? full : engine::terminationReasonName(engineReason(phase));
    engine::SolveSummary summary;
    summary.termNames = {"objective"};
    double previousMs = 0.0;
    for (const quasi::QuasiStripIteration& it : quasiSummary_.iterations) {
      engine::IterationRecord r;
      r.iteration = it.iteration;
      r.termResiduals = {it.objective};
      r.objective = r.totalResidual = it.objective;
      r.stepNorm = it.stepNorm;
      r.totalMs = std::max(0.0, it.elapsedMs - (it.iteration == 0 ? it.elapsedMs : previousMs));
      previousMs = it.elapsedMs;
      summary.iterations.push_back(std::move(r));
    }
    summary.reason = engineReason(phase);
    summary.converged = quasiSummary_.converged;
    summary.totalMs = quasiSummary_.totalMs;
    if (options.callback && !summary.iterations.empty()) options.callback(summary.iterations.back());
    return summary;
  }
  if (conical_) {
    conical_->setDeadline(deadline_);
    const conical::ConicalStripSummary& cs = conical_->solve();
    termination_ = cs.termination;
    engine::SolveSummary summary;
    summary.iterations.emplace_back();
    summary.iterations.back().totalMs = cs.timeMs;
    summary.reason = engine::TerminationReason::ResidualTolerance;
    summary.converged = true;
    summary.totalMs = cs.timeMs;
    if (options.callback) options.callback(summary.iterations.back());
    return summary;
  }
  if (composite_) return composite_->solve(options);
  if (quadMesh_) {
    quadMeshSummary_ = quadMesh_->solve(options);
    return quadMeshSummary_.summary;
  }
  return strip_->solve(options);
}

proto::Scene SceneSolver::currentScene() const {
  proto::Scene s = scene_;
  if (keepsInputGeometry()) return s;  // the input curves do not move
  if (composite_) {
    s.model = composite_->design();
    return s;
  }
  if (quadMesh_) {
    s.model = quadMesh_->design();
    return s;
  }
  s.model = strip_->design();
  return s;
}

proto::Metrics SceneSolver::metrics() const {
  if (quasi_) {
    const quasi::QuasiStripResults& r = quasi_->results();
    proto::Metrics m;
    m["warp_angle_max_deg"] = r.warpAngleMaxDeg;
    m["warp_angle_mean_deg"] = r.warpAngleMeanDeg;
    m["warp_angle_max_deg_dense"] = r.warpAngleMaxDegDense;
    m["warp_angle_mean_deg_dense"] = r.warpAngleMeanDegDense;
    m["objective"] = r.objective;
    // Distance of the surface's boundaries from the input curves: zero up to round-off except
    // where a curve was extended beyond its end (§3.4).
    const quasi::QuasiStripDesign& d = quasi_->design();
    double deviation = 0.0;
    const spline::BSplineCurve* inputs[2] = {&d.c1, &d.c2};
    for (int side = 0; side < 2; ++side) {
      const conical::ArcLengthCurve curve(*inputs[side], 4);
      const double t0 = r.surface.knots.front(), t1 = r.surface.knots.back();
      for (int k = 0; k <= 200; ++k) {
        const Eigen::Vector3d x = r.surface.evaluate(side, t0 + (t1 - t0) * k / 200.0);
        deviation = std::max(deviation, curve.closestPoint(x, curve.domainBegin(), curve.domainEnd()).distance);
      }
    }
    m["deviation_max"] = deviation;
    m["rounds"] = quasiSummary_.rounds;
    m["selected_round"] = quasiSummary_.selectedRound;
    m["unknowns"] = quasi_->numUnknowns();
    return m;
  }
  if (conical_) {
    proto::Metrics m;
    if (!conical_->solved()) return m;
    const conical::ConicalStripResult& r = conical_->result();
    auto add = [&m](const std::string& prefix, const conical::ConicalStripMetrics& q) {
      m[prefix + "normal_variation"] = q.normalVariation + 0.0;  // no "-0" in the report
      m[prefix + "bending_energy"] = q.bendingEnergy;
      m[prefix + "n3"] = q.n3;
      m[prefix + "n4"] = q.n4;
      m[prefix + "deviation_max"] = q.deviationMax;
      m[prefix + "corner_deviation_max"] = q.cornerDeviationMax;
      m[prefix + "projection_residual_max"] = q.projectionResidualMax;
      m[prefix + "coplanarity_residual_max"] = q.coplanarityResidualMax;
      m[prefix + "normal_jump_max_rad"] = q.normalJumpMaxRad;
    };
    add("", r.metrics);
    add("greedy_", r.greedyMetrics);
    m["patches"] = static_cast<double>(r.patches.size());
    return m;
  }
  if (quadMesh_) return quadMeshMetrics();
  if (composite_) {
    const models::composite::CompositeQuality q = composite_->quality();
    const models::composite::CompositeDesign d = composite_->design();
    proto::Metrics m;
    m["face_flatness_max"] = q.faceFlatnessMax;
    m["face_flatness_mean"] = q.faceFlatnessMean;
    m["vertex_curvature_max"] = q.vertexCurvatureMax;
    m["crease_fold_residual_max"] = q.creaseFoldResidualMax;
    m["crease_fold_angle_max_deg"] = q.foldAngleMaxDeg;
    m["warp_angle_max_deg"] = q.warpAngleMaxDeg;
    m["warp_angle_mean_deg"] = q.warpAngleMeanDeg;
    auto point = [&d](const models::composite::PointRef& r) -> Eigen::Vector3d {
      if (r.isVertex()) return d.vertices.row(r.vertex).transpose();
      return d.edges[static_cast<std::size_t>(r.edge)].curve.points.row(r.index).transpose();
    };
    double handleError = 0.0;
    for (const models::composite::Handle& h : d.handles)
      if (h.weight > 0.0) handleError = std::max(handleError, (point(h.point) - h.position).norm());
    m["handle_distance_max"] = handleError;
    double moved = 0.0;
    if (d.vertices.rows() > 0) moved = (d.vertices - initialComposite_.vertices).rowwise().norm().maxCoeff();
    for (std::size_t e = 0; e < d.edges.size(); ++e) {
      const Eigen::MatrixXd& now = d.edges[e].curve.points;
      if (now.rows() > 0)
        moved = std::max(moved, (now - initialComposite_.edges[e].curve.points).rowwise().norm().maxCoeff());
    }
    m["displacement_max"] = moved;
    if (composite_->hasDevelopment()) {
      m["development_length_error"] = composite_->developmentLengthError();
      m["development_edge_strain_max"] = composite_->developmentEdgeStrainMax();
      m["development_flipped_faces"] = composite_->flippedDevelopmentFaces();
    }
    m["ruling_length_min_ratio"] = composite_->rulingLengthMinRatio();
    m["strip_width_min_ratio"] = composite_->stripWidthMinRatio();
    m["crease_backtrack_max"] = composite_->creaseBacktrackMax();
    if (!d.foldAngles.empty()) {
      m["fold_amount"] = composite_->foldAmount();
      m["fold_angle_error_max_deg"] = composite_->foldAngleErrorMaxDeg();
    }
    m["unknowns"] = composite_->numUnknowns();
    return m;
  }
  const metrics::StripQuality q = strip_->quality(1000);
  const models::strip::StripDesign d = strip_->design();
  proto::Metrics m;
  m["warp_angle_max_deg"] = q.warpAngleMaxDeg;
  m["warp_angle_mean_deg"] = q.warpAngleMeanDeg;
  m["developability_residual_max"] = q.developabilityResidualMax;
  double handleError = 0.0;
  for (const models::strip::Handle& h : d.handles) {
    if (h.weight <= 0.0) continue;  // a released drag handle
    const Eigen::MatrixXd& pts = h.point.curve == models::strip::Curve::A ? d.a.points : d.b.points;
    handleError = std::max(handleError, (pts.row(h.point.index).transpose() - h.position).norm());
  }
  m["handle_distance_max"] = handleError;
  m["displacement_max_a"] = (d.a.points - initial_.a.points).rowwise().norm().maxCoeff();
  m["displacement_max_b"] = (d.b.points - initial_.b.points).rowwise().norm().maxCoeff();
  m["ruling_length_min_ratio"] = strip_->rulingLengthMinRatio();
  m["strip_width_min_ratio"] = strip_->stripWidthMinRatio();
  m["unknowns"] = strip_->numUnknowns();
  if (d.approximation) {
    // Distances of the approximated points to the sampled surface (CGAL's AABB tree), not the
    // solver's own foot points; coverage within 1 % of the points' diagonal.
    try {
      for (const auto& [name, value] : referenceMetrics(d.approximation->points, 0.0))
        m["approximation_" + name.substr(std::string("reference_").size())] = value;
    } catch (const std::exception&) {
      // A degenerate surface has no distances; the other metrics say what went wrong.
    }
  }
  return m;
}

nlohmann::json SceneSolver::report(const engine::SolveSummary& summary, double timeMs) const {
  const proto::Metrics measured = metrics();
  nlohmann::json report = proto::reportToJson(summary, measured, proto::sceneToJson(currentScene()), timeMs);
  if (!termination_.empty()) report["termination"] = termination_;
  // The thresholds the shape is held to, as a session's `solved` message carries them: a solve can
  // end on its iteration count with the sheet stretched (fold targets it cannot reach), and a
  // batch user reads that here rather than from every metric.
  if (const QualityVerdict verdict = quality(measured); !verdict.checks.empty()) report["quality"] = verdict.toJson();
  if (quasi_) {
    report["result"] = proto::quasiStripResultJson(quasi_->results(), quasiSummary_);
    report["result"]["termination"] = quasiSummary_.termination;
  }
  if (conical_ && conical_->solved())
    report["result"] = proto::conicalStripResultJson(conical_->result(), conical_->summary());
  return report;
}

void SceneSolver::igesEntities(std::vector<io::IgesSurface>& surfaces, std::vector<io::IgesCurve>& curves) const {
  if (quadMesh_) {
    quadMeshIgesEntities(surfaces);
  } else if (composite_) {
    composite_->igesEntities(surfaces, curves);
  } else if (quasi_) {
    const quasi::RuledBSplineSurface& s = quasi_->results().surface;
    surfaces.push_back(igesRuledSurface(s.degree, s.knots, s.side0, s.side1, "STRIP"));
    curves.push_back(igesCurve(quasi_->design().c1, "C1"));
    curves.push_back(igesCurve(quasi_->design().c2, "C2"));
  } else if (conical_) {
    if (!conical_->solved()) throw ExportFailed("format: iges: the conical strip has not been solved");
    const std::vector<conical::ConicalPatch>& patches = conical_->result().patches;
    for (std::size_t k = 0; k < patches.size(); ++k) {
      const conical::ConicalPatch& p = patches[k];
      const int n = p.degree() + 1;
      std::vector<double> knots(2 * static_cast<std::size_t>(n), 0.0);
      std::fill(knots.begin() + n, knots.end(), 1.0);
      surfaces.push_back(igesRuledSurface(p.degree(), knots, p.a, p.b, "PATCH" + std::to_string(k)));
    }
    curves.push_back(igesCurve(conical_->design().p, "P"));
    curves.push_back(igesCurve(conical_->design().q, "Q"));
  } else {
    const models::strip::StripDesign d = strip_->design();
    const io::IgesCurve a = igesCurve(d.a, "A"), b = igesCurve(d.b, "B");
    if (d.a.isRational() || d.b.isRational()) {
      // The ruled surface between two NURBS curves is rational with the weights of both sides.
      io::IgesSurface s = igesRuledSurface(a.degree, a.knots, a.points, b.points, "STRIP");
      s.weights.resize(2 * s.nu);
      s.weights.head(s.nu) = a.weights.size() ? a.weights : Eigen::VectorXd::Ones(s.nu);
      s.weights.tail(s.nu) = b.weights.size() ? b.weights : Eigen::VectorXd::Ones(s.nu);
      surfaces.push_back(std::move(s));
    } else {
      surfaces.push_back(igesRuledSurface(a.degree, a.knots, a.points, b.points, "STRIP"));
    }
    curves.push_back(a);
    curves.push_back(b);
  }
}

void SceneSolver::exportTo(const std::string& spec) const {
  const std::size_t colon = spec.find(':');
  if (colon == std::string::npos || colon == 0 || colon + 1 == spec.size())
    throw std::invalid_argument("--export: expected FORMAT:FILE, e.g. obj:strip.obj, got \"" + spec + "\"");
  const std::string format = spec.substr(0, colon);
  const std::string path = spec.substr(colon + 1);
  const bool flatPattern = (format == "svg" && !(composite_ && composite_->hasDevelopment())) ||
                           (format == "fold" && cutAlongSeams());
  // The bytes of exportAs, written as they are (STL: in millimetres, triangles; a quad mesh's
  // triangle travels as a quad with its last vertex repeated, whose zero-area half is left out).
  if (quadMesh_ || format == "step" || format == "dxf" || format == "png" || format == "stl" || flatPattern) {
    ExportedFile file;
    try {
      file = exportAs(format);
    } catch (const std::invalid_argument& e) {
      throw std::invalid_argument("--export " + std::string(e.what()).substr(8));
    }
    // Staged and renamed, so that a failed write leaves no partial file under the requested name.
    const std::string staging = path + ".partial";
    std::FILE* out = std::fopen(staging.c_str(), "wb");
    if (!out) throw std::runtime_error("cannot write " + path);
    const bool ok = std::fwrite(file.content.data(), 1, file.content.size(), out) == file.content.size();
    if (std::fclose(out) != 0 || !ok || std::rename(staging.c_str(), path.c_str()) != 0) {
      std::remove(staging.c_str());
      throw std::runtime_error("cannot write " + path);
    }
    return;
  }
  if (format == "fold" || format == "svg") {
    // The messages start "format: <format>…"; on the command line they name the option instead.
    auto option = [](const std::exception& e) { return "--export " + std::string(e.what()).substr(8); };
    io::CreasePattern cp;
    try {
      cp = creasePattern(format);
    } catch (const ExportUnavailable& e) {
      throw ExportUnavailable(option(e));
    } catch (const ExportFailed& e) {
      throw ExportFailed(option(e));
    }
    if (format == "fold")
      io::writeFold(cp, path);
    else
      io::writeSvgFoldPattern(cp, path);
    return;
  }
  if (format == "iges") {
    io::IgesHeader header;
    header.fileName = path;
    header.units = scene_.units;
    std::vector<io::IgesSurface> surfaces;
    std::vector<io::IgesCurve> curves;
    igesEntities(surfaces, curves);
    io::writeIges(path, surfaces, curves, header);
    return;
  }
  if (format != "obj" && format != "off" && format != "ply" && format != "stl")
    throw std::invalid_argument("--export: unknown format \"" + format +
                                "\" (expected obj, off, ply, stl, iges, step, svg, dxf, png, or fold for composites with a development)");
  // OpenMesh chooses the writer by extension: write with the format's extension, then rename to
  // exactly the requested path.
  const std::string staging = path + ".partial." + format;
  const io::QuadMesh surface = sampledSurface();
  try {
    io::writeMesh(surface, staging);
  } catch (const std::runtime_error&) {  // the writer names the staging file: name the one asked for
    std::remove(staging.c_str());
    throw std::runtime_error("cannot write " + path);
  }
  if (std::rename(staging.c_str(), path.c_str()) != 0) {
    std::remove(staging.c_str());
    throw std::runtime_error("cannot write " + path);
  }
}

namespace {

/// Wavefront OBJ text of a quad mesh (1-based indices, one "f" line per quad).
std::string objText(const io::QuadMesh& mesh, const std::string& title) {
  std::ostringstream out;
  out.precision(9);
  out << "# devsurf: " << io::oneLine(title) << "\n";
  for (Eigen::Index i = 0; i < mesh.vertices.rows(); ++i)
    out << "v " << mesh.vertices(i, 0) << ' ' << mesh.vertices(i, 1) << ' ' << mesh.vertices(i, 2) << "\n";
  for (Eigen::Index q = 0; q < mesh.quads.rows(); ++q)
    out << "f " << mesh.quads(q, 0) + 1 << ' ' << mesh.quads(q, 1) + 1 << ' ' << mesh.quads(q, 2) + 1 << ' '
        << mesh.quads(q, 3) + 1 << "\n";
  return out.str();
}

}  // namespace

std::string SceneSolver::kindName() const {
  if (composite_) return "composite";
  if (quasi_) return "quasi_strip";
  if (conical_) return "conical_strip";
  if (quadMesh_) return "quad_mesh";
  return "strip";
}

void SceneSolver::checkExportFormat(const std::string& format) const {
  if (format == "png" || format == "obj" || format == "stl") return;
  if (format == "json") throw ExportUnavailable("format: json is the report itself (--out writes it to a file)");
  if (quadMesh_) {
    if (format == "unfolding_obj") return;
    if (format == "iges" || format == "step") {
      if (!initialQuadMesh_.control)
        throw ExportUnavailable("format: " + format + " exports B-spline surfaces; this quad_mesh scene is a mesh without "
                                "a control net (use obj, unfolding_obj, stl, svg, dxf, fold or png)");
      return;
    }
    if (format == "svg" || format == "fold" || format == "dxf") {
      if (!quadMesh_->design().unfoldingPlanar)
        throw ExportUnavailable("format: " + format + " draws a planar unfolding; this scene's M′ is a second surface "
                                "(unfolding.planar false)");
      return;
    }
    throw ExportUnavailable("format: expected json, obj, unfolding_obj, stl, svg, dxf, fold, png, or iges, step with a "
                            "control net, for a quad_mesh scene, got \"" + format + "\"");
  }
  if (format == "off" || format == "ply" || format == "iges" || format == "step") return;
  const bool development = composite_ && composite_->hasDevelopment();
  if (format == "svg" || format == "dxf") {
    if (development || cutAlongSeams() || hasFlatStripPattern()) return;
    creasePattern(format);  // throws: the composite's message (add a development)
    return;
  }
  if (format == "fold") {
    if (development || cutAlongSeams()) return;
    creasePattern(format);  // throws: not a composite, or no development
    return;
  }
  if (format == "unfolding_obj") throw ExportUnavailable(unfoldingObjUnavailable());
  throw ExportUnavailable("format: expected obj, off, ply, stl, iges, step, svg, dxf, png or fold, got \"" + format + "\"");
}

std::string SceneSolver::unfoldingObjUnavailable() const {
  return "format: unfolding_obj is the planar unfolding M′ of a quad_mesh scene; this scene is a " + kindName();
}

bool SceneSolver::cutAlongSeams() const {
  return composite_ && !composite_->hasDevelopment() &&
         models::composite::hasSeams(composite_->design(), composite_->topology());
}

io::CreasePattern SceneSolver::creasePattern(const std::string& format) const {
  if (!composite_)
    throw ExportUnavailable("format: " + format + " exports the crease pattern of a composite; this scene is a " +
                            kindName() + (hasFlatStripPattern() ? " (its flat pattern exports as svg and dxf)" : ""));
  if (!composite_->hasDevelopment())
    throw ExportUnavailable("format: " + format +
                            " needs a development; add \"development\": {\"samples\": n} to the composite model" +
                            (cutAlongSeams() ? " (its pieces cut along the seams export as svg, dxf and fold)" : ""));
  try {
    io::CreasePattern cp = composite_->creasePattern(scene_.name);
    cp.unitToMm = proto::millimetresPerUnit(scene_.units);
    cp.validate();
    return cp;
  } catch (const std::bad_alloc&) {
    throw;
  } catch (const std::exception& e) {
    throw ExportFailed("format: " + format + ": the development in its current state is not a valid crease pattern (" +
                       e.what() + ")");
  }
}

ExportedFile SceneSolver::exportAs(const std::string& format) const {
  if (format == "png") return fabricationExport(format);
  if (quadMesh_) return quadMeshExport(format);
  if (format == "unfolding_obj") throw ExportUnavailable(unfoldingObjUnavailable());
  if (format != "obj" && format != "off" && format != "ply" && format != "fold" && format != "svg" &&
      format != "iges" && format != "step" && format != "stl" && format != "dxf")
    throw ExportUnavailable("format: expected json, obj, off, ply, stl, iges, step, svg, dxf, png or fold, got \"" +
                            format + "\"");
  if (format == "stl" || format == "dxf") return fabricationExport(format);
  if (format == "off" || format == "ply") {
    // The sampled surface's quads, as the OBJ (and as `--export off:…`/`ply:…` write them):
    // OpenMesh's ASCII writers, in the scene's units, coordinates in single precision (OpenMesh's
    // points are floats; the OBJ carries 9 digits).
    try {
      return {io::meshString(sampledSurface(), format), "text/plain; charset=utf-8", format};
    } catch (const ExportFailed&) {
      throw;  // the surface's own reason (e.g. a strip not solved yet), said once
    } catch (const ExportUnavailable&) {
      throw;
    } catch (const std::bad_alloc&) {
      throw;
    } catch (const std::exception& e) {
      throw ExportFailed("format: " + format + ": the surface in its current state cannot be written (" +
                         std::string(e.what()) + ")");
    }
  }
  if (format == "iges" || format == "step") {
    io::IgesHeader header;
    header.fileName = (scene_.name.empty() ? std::string("devsurf") : scene_.name) + ".igs";
    header.units = scene_.units;
    std::vector<io::IgesSurface> surfaces;
    std::vector<io::IgesCurve> curves;
    try {
      igesEntities(surfaces, curves);
      if (format == "step") {
        cad::StepOptions options;
        options.units = scene_.units;
        return {cad::stepDocument(surfaces, options), "model/step", "step"};
      }
      return {io::igesDocument(surfaces, curves, header), "model/iges", "igs"};
    } catch (const ExportFailed&) {
      throw;
    } catch (const std::bad_alloc&) {
      throw;
    } catch (const std::exception& e) {
      throw ExportFailed("format: " + format + ": the model in its current state cannot be written as " +
                         (format == "step" ? "STEP" : "IGES") + " (" + std::string(e.what()) + ")");
    }
  }
  if (format == "svg" && !(composite_ && composite_->hasDevelopment()) && (cutAlongSeams() || hasFlatStripPattern()))
    return fabricationExport(format);
  if (format == "fold" && cutAlongSeams()) return fabricationExport(format);
  if (format == "fold" || format == "svg") {
    const io::CreasePattern cp = creasePattern(format);
    if (format == "fold") return {io::foldString(cp), "application/json", "fold"};
    return {io::svgFoldPattern(cp), "image/svg+xml", "svg"};
  }
  try {
    const io::QuadMesh mesh = sampledSurface();
    return {objText(mesh, scene_.name), "model/obj", "obj"};
  } catch (const std::bad_alloc&) {
    throw;
  } catch (const std::exception& e) {
    throw ExportFailed("format: obj: the surface in its current state cannot be sampled (" + std::string(e.what()) + ")");
  }
}

ExportedFile SceneSolver::exportScene(const nlohmann::json& scene, const std::string& format,
                                      const proto::ResourceLimits& limits, engine::Deadline deadline) {
  try {
    std::unique_ptr<SceneSolver> solver;
    try {
      solver = std::make_unique<SceneSolver>(proto::sceneFromJson(scene, limits), deadline);
    } catch (const proto::SceneError& e) {
      throw ExportFailed("format: " + format + ": the current scene no longer builds a model (" + e.what() + ")");
    }
    if (solver->keepsInputGeometry()) solver->solve();  // what they export is computed from the input
    return solver->exportAs(format);
  } catch (const engine::DeadlineExceeded& e) {
    throw ExportFailed("format: " + format + ": building the model to export it took too long (" + e.what() + ")");
  }
}

}  // namespace devsurf::server
