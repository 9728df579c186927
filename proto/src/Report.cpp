#include "devsurf/proto/Report.h"

namespace devsurf::proto {

using nlohmann::json;

json iterationToJson(const engine::SolveSummary& summary, const engine::IterationRecord& r) {
  json residuals = json::object();
  for (std::size_t t = 0; t < summary.termNames.size() && t < r.termResiduals.size(); ++t) {
    const std::string& name = summary.termNames[t];
    residuals[name] = residuals.value(name, 0.0) + r.termResiduals[t];
  }
  return {{"iteration", r.iteration},
          {"residuals", residuals},
          {"total", r.totalResidual},
          {"hard", r.hardResidual},
          {"step_norm", r.stepNorm},
          {"fairness_weight", r.fairnessWeight},
          {"time_ms",
           {{"assembly", r.assemblyMs},
            {"factorization", r.factorizationMs},
            {"solve", r.solveMs},
            {"total", r.totalMs}}}};
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

}  // namespace devsurf::proto
