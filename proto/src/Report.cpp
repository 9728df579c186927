#include "devsurf/proto/Report.h"

namespace devsurf::proto {

using nlohmann::json;

json iterationToJson(const engine::SolveSummary& summary, const engine::IterationRecord& r) {
  json residuals = json::object();
  for (std::size_t t = 0; t < summary.termNames.size() && t < r.termResiduals.size(); ++t) {
    const std::string& name = summary.termNames[t];
    residuals[name] = residuals.value(name, 0.0) + r.termResiduals[t];
  }
  json out = {{"iteration", r.iteration},
          {"residuals", residuals},
          {"total", r.totalResidual},
          {"hard", r.hardResidual},
          {"hard_max", r.hardResidualMax},
          {"step_scale", r.stepScale},
          {"pull_limit", r.pullLimit},
          {"step_norm", r.stepNorm},
          {"fairness_weight", r.fairnessWeight},
          {"time_ms",
           {{"assembly", r.assemblyMs},
            {"factorization", r.factorizationMs},
            {"solve", r.solveMs},
            {"evaluation", r.evaluationMs},
            {"total", r.totalMs}}}};
  if (summary.alternating) out["alternating_step_scale"] = r.alternatingStepScale;
  return out;
}

json reportToJson(const engine::SolveSummary& summary, const Metrics& metrics,
                  const json& solvedScene, double timeMs) {
  json history = json::array();
  for (const engine::IterationRecord& r : summary.iterations) history.push_back(iterationToJson(summary, r));
  json m = json::object();
  for (const auto& [name, value] : metrics) m[name] = value;
  return {{"format", "devsurf-report"},
          {"version", 1},
          {"iterations", summary.stepsTaken()},
          {"converged", summary.converged},
          {"termination", engine::terminationReasonName(summary.reason)},
          {"time_ms", timeMs},
          {"history", history},
          {"metrics", m},
          {"scene", solvedScene}};
}

namespace {

template <typename Matrix>
json rowsJson(const Matrix& m) {
  json rows = json::array();
  for (Eigen::Index i = 0; i < m.rows(); ++i) {
    json row = json::array();
    for (Eigen::Index k = 0; k < m.cols(); ++k) row.push_back(m(i, k));
    rows.push_back(std::move(row));
  }
  return rows;
}

}  // namespace

json quasiStripResultJson(const models::quasi_strip::QuasiStripResults& r,
                          const models::quasi_strip::QuasiStripSummary& summary) {
  namespace quasi = models::quasi_strip;
  const quasi::Mapping& m = r.mapping;
  const quasi::RuledBSplineSurface& s = r.surface;
  return {{"kind", "quasi_strip"},
          {"optimizer", summary.optimizer == quasi::Optimizer::Lbfgs ? "lbfgs" : "guided_projection"},
          {"rounds", summary.rounds},
          {"selected_round", summary.selectedRound},
          {"selection", summary.selection},
          {"mapping",
           {{"degree", m.degree},
            {"knots", m.knots},
            {"coefficients", std::vector<double>(m.coefficients.data(), m.coefficients.data() + m.coefficients.size())}}},
          {"surface",
           {{"degrees", {1, s.degree}},
            {"knots", {std::vector<double>{0.0, 0.0, 1.0, 1.0}, s.knots}},
            {"control_points", {rowsJson(s.side0), rowsJson(s.side1)}}}},
          {"trim", {r.trimBegin, r.trimEnd}},
          {"extension",
           {{"c1_begin", r.extension.c1Begin},
            {"c1_end", r.extension.c1End},
            {"c2_begin", r.extension.c2Begin},
            {"c2_end", r.extension.c2End}}},
          {"samples", {{"t", r.sampleParameters}, {"warp_angle_deg", r.sampleWarpDeg}}}};
}

json conicalStripResultJson(const models::conical_strip::ConicalStripResult& r,
                            const models::conical_strip::ConicalStripSummary& summary) {
  namespace conical = models::conical_strip;
  json patches = json::array();
  for (const conical::ConicalPatch& p : r.patches) {
    const Eigen::Vector3d& o = p.projectionPoint;
    patches.push_back({{"type", conical::patchTypeName(p.type)},
                       {"base", p.baseSide == conical::StripSide::P ? "p" : "q"},
                       {"scale", p.scale},
                       {"projection_point", o.allFinite() && p.scale != 0.0 ? json::array({o.x(), o.y(), o.z()}) : json()},
                       {"a", rowsJson(p.a)},
                       {"b", rowsJson(p.b)},
                       {"p_samples", {p.pBegin, p.pEnd}},
                       {"q_samples", {p.qBegin, p.qEnd}}});
  }
  json unfolded = json::array();
  for (const conical::UnfoldedPatch& u : r.unfolded) unfolded.push_back({{"a", rowsJson(u.a)}, {"b", rowsJson(u.b)}});
  return {{"kind", "conical_strip"},
          {"patches", std::move(patches)},
          {"unfolded", std::move(unfolded)},
          {"summary",
           {{"forced_triangles", summary.forcedTriangles},
            {"fold_backs_taken", summary.foldBacksTaken},
            {"quad_candidates_tested", summary.quadCandidatesTested},
            {"quad_candidates_feasible", summary.quadCandidatesFeasible},
            {"greedy_ms", summary.greedyMs},
            {"g1_ms", summary.g1Ms},
            {"metrics_ms", summary.metricsMs}}}};
}

}  // namespace devsurf::proto
