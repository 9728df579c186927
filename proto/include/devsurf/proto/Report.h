#pragma once

#include <map>
#include <string>

#include <nlohmann/json.hpp>

#include "devsurf/engine/GuidedProjectionSolver.h"

namespace devsurf::proto {

/// Named metrics; names carry their units (warp_angle_max_deg, …).
using Metrics = std::map<std::string, double>;

/// Per-iteration history as the report and the WebSocket stream carry it: weighted squared
/// residuals summed by term name, step norm, fairness weight and times.
nlohmann::json iterationToJson(const engine::SolveSummary& summary,
                               const engine::IterationRecord& record);

/// The report document (report.schema.json) of a solve.
nlohmann::json reportToJson(const engine::SolveSummary& summary, const Metrics& metrics,
                            const nlohmann::json& solvedScene, double timeMs);

}  // namespace devsurf::proto
