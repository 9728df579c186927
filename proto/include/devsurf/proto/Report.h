#pragma once

#include <map>
#include <string>

#include <nlohmann/json.hpp>

#include "devsurf/engine/GuidedProjectionSolver.h"
#include "devsurf/models/conical_strip/ConicalStripModel.h"
#include "devsurf/models/quasi_strip/QuasiStripModel.h"

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

/// The report's `result` of a quasi_strip (report.schema.json#/$defs/quasi_strip_result): mapping
/// {degree, knots, coefficients}, the converted surface {degrees [1, p·d], knots [[0,0,1,1], t knots],
/// control_points [side on c1, side on c2]}, trim [t_begin, t_end], extension, samples {t, warp_angle_deg}.
nlohmann::json quasiStripResultJson(const models::quasi_strip::QuasiStripResults& results,
                                    const models::quasi_strip::QuasiStripSummary& summary);

/// The report's `result` of a conical_strip (report.schema.json#/$defs/conical_strip_result): patches
/// {type, base "p"|"q", scale, projection_point (null for a cylinder), a, b, p_samples, q_samples},
/// unfolded [{a, b}] (2D), summary counts and times.
nlohmann::json conicalStripResultJson(const models::conical_strip::ConicalStripResult& result,
                                      const models::conical_strip::ConicalStripSummary& summary);

}  // namespace devsurf::proto
