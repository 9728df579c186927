// libFuzzer harness: a scene file as `devsurf solve` and POST /api/sessions read it — bounded
// parse, schema, index and number checks, model validation — and every accepted design built,
// one iteration run (quasi_strip: one optimizer iteration; conical_strip: the greedy
// construction) and its metrics read. Every input must end in a SceneError, an
// std::invalid_argument (the daemon's 422) or finite metrics; anything else aborts the run.
//
// Bounded for speed, so that a long run reaches 10^6 executions: what scales the cost of a build
// without reaching other code is clamped after the parse (quasi_strip samples ≤ 40 and mapping
// coefficients ≤ 16, conical_strip np, nq ≤ 24, composite development samples ≤ 4, at most 2
// solver iterations), and designs with more than 64 control points or 64 composite vertices are
// parsed and validated only. The daemon's own limits on these sizes are tested elsewhere.

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <string>
#include <type_traits>
#include <variant>

#include "devsurf/proto/Scene.h"
#include "devsurf/server/SceneSolver.h"

namespace {

using namespace devsurf;

constexpr int kMaxControlPoints = 64;

/// Clamps the sizes that scale a build; false when the design is too large to build here.
bool boundForSpeed(proto::Scene& scene) {
  scene.solver.iterations = std::min(scene.solver.iterations, 2);
  return std::visit(
      [](auto& model) {
        using T = std::decay_t<decltype(model)>;
        if constexpr (std::is_same_v<T, models::strip::StripDesign>) {
          return model.a.points.rows() + model.b.points.rows() <= kMaxControlPoints;
        } else if constexpr (std::is_same_v<T, models::composite::CompositeDesign>) {
          Eigen::Index points = model.vertices.rows();
          for (const auto& edge : model.edges) points += edge.curve.points.rows();
          model.developmentSamples = std::min(model.developmentSamples, 4);
          return points <= kMaxControlPoints;
        } else if constexpr (std::is_same_v<T, proto::QuasiStripScene>) {
          model.design.samples = std::min(model.design.samples, 40);
          model.design.mapping.coefficients = std::min(model.design.mapping.coefficients, 16);
          model.maxIterations = 1;
          return model.design.c1.points.rows() + model.design.c2.points.rows() <= kMaxControlPoints;
        } else if constexpr (std::is_same_v<T, models::quad_mesh::QuadMeshDesign>) {
          return model.mesh.rows() <= 4 * kMaxControlPoints &&
                 (!model.reference || model.reference->triangles.rows() <= 4 * kMaxControlPoints);
        } else {
          model.np = std::min(model.np, 24);
          model.nq = std::min(model.nq, 24);
          return model.p.points.rows() + model.q.points.rows() <= kMaxControlPoints;
        }
      },
      scene.model);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size > (1u << 20)) return 0;
  const std::string text(reinterpret_cast<const char*>(data), size);
  proto::Scene scene;
  try {
    scene = proto::sceneFromText(text);
  } catch (const proto::SceneError&) {
    return 0;
  }
  if (!boundForSpeed(scene)) return 0;
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
