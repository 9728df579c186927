// libFuzzer harness: a scene file as `devsurf solve` and POST /api/sessions read it — bounded
// parse, schema, index and number checks, model validation — and, when it is accepted and small,
// the model built and one iteration run. Every input must end in a SceneError, an
// std::invalid_argument (the daemon's 422) or finite metrics; anything else aborts the run.

#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <string>

#include "devsurf/proto/Scene.h"
#include "devsurf/server/SceneSolver.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace devsurf;
  if (size > (1u << 20)) return 0;
  const std::string text(reinterpret_cast<const char*>(data), size);
  proto::Scene scene;
  try {
    scene = proto::sceneFromText(text);
  } catch (const proto::SceneError&) {
    return 0;
  }
  if (size > 20000) return 0;  // building large designs is slow; the parse above is what matters
  try {
    server::SceneSolver solver(scene);
    server::SolveLimits limits;
    limits.iterations = 1;
    solver.solve(limits);
    for (const auto& [name, value] : solver.metrics())
      if (!std::isfinite(value)) std::abort();  // a non-finite metric is a defect
  } catch (const std::invalid_argument&) {
  }
  return 0;
}
