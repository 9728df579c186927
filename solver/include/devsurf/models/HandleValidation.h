#pragma once

#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

namespace devsurf::models {

/// Checks the user constraints every model shares: each fixed point and handle target addresses
/// an existing point (`checkRef(ref, path)` throws), handle positions are finite and weights
/// positive. Messages start with the path inside the model ("handles[2].weight: …").
/// @tparam Fixed   a reference type accepted by checkRef
/// @tparam Handle  has members `point` (a reference), `position` (Eigen vector), `weight`
template <class Fixed, class Handle, class CheckRef>
void validateUserConstraints(const std::vector<Fixed>& fixed, const std::vector<Handle>& handles,
                             const CheckRef& checkRef) {
  auto path = [](const char* list, std::size_t i) { return std::string(list) + "[" + std::to_string(i) + "]"; };
  for (std::size_t i = 0; i < fixed.size(); ++i) checkRef(fixed[i], path("fixed", i));
  for (std::size_t i = 0; i < handles.size(); ++i) {
    const Handle& h = handles[i];
    checkRef(h.point, path("handles", i));
    if (!h.position.allFinite())
      throw std::invalid_argument(path("handles", i) + ".position: coordinates must be finite");
    if (!(h.weight > 0.0) || !std::isfinite(h.weight))
      throw std::invalid_argument(path("handles", i) + ".weight: must be a positive number");
  }
}

}  // namespace devsurf::models
