#pragma once

#include <string>

#include "devsurf/spline/BSplineCurve.h"

namespace devsurf::models {

/// Refuses a pair of boundary curves between which a strip has no width (the strips between two
/// curves: quasi strips, conical strips). Either curve collapsed to one point (its control points'
/// extent within 1e-12 of the pair's), the second lying on the first (every one of 65 samples of it
/// within 1e-9 of the pair's extent from the first's polyline of 257 samples), or both on one
/// straight line (the samples' second principal extent within 1e-9 of the first).
/// @param[in] first, second  the two boundary curves, clamped, 3D
/// @param[in] firstName, secondName  their fields in the scene's model ("c1", "p"); the message
///            names `<name>.points`
/// @throws std::invalid_argument naming the field, e.g. "q.points: q lies on p; the strip between
///         them has no width"
void requireCurvePairWidth(const spline::BSplineCurve& first, const spline::BSplineCurve& second,
                           const std::string& firstName, const std::string& secondName);

}  // namespace devsurf::models
