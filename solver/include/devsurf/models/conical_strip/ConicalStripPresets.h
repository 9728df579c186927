#pragma once

#include "devsurf/models/conical_strip/ConicalStripModel.h"

namespace devsurf::models::conical_strip {

/// A stand-in for the first example of Chu et al. (Fig. 10–11; the paper's curves are not
/// published): a twisted helical band, one turn, like the rim of a spiral chute.
///
///   P(θ) = (16 cos θ, 16 sin θ, 2θ + 0.8 sin 2θ)                θ ∈ [0, 2π]
///   Q(θ) = (19 cos θ, 19 sin θ, 2θ + 0.5 + 0.8 cos 2θ)
///
/// each given as a clamped uniform cubic B-spline whose 40 control points are the formula at
/// equally spaced θ. The inner edge P (≈ 101 units) and the outer edge Q (≈ 120 units) have the
/// length ratio of the paper's samples (65/55), so 55 and 65 samples are ≈ 1.9 units apart on
/// both; the band is 3.0–3.4 units wide and its tilt swings between −12° and +28° twice per
/// turn (the vertical wobbles are 90° out of phase). Parameters as in the paper's Fig. 11:
/// Np/Nq = 55/65, H3 = H4 = 4, ra = 1.2, normal variation.
ConicalStripDesign figure11LikeDesign();

}  // namespace devsurf::models::conical_strip
