#pragma once

#include <cstddef>
#include <string>
#include <vector>

namespace devsurf::proto {

struct Scene;

/// The limits on what one scene may ask of the solver (ARCHITECTURE §8: every input that scales
/// work is bounded), in one place. Per-field maxima that never change are the schema's
/// (`scene.schema.json`: `maximum`, `maxItems`, e.g. mapping.coefficients ≤ 10 000, np ≤ 10 000);
/// these are the ones that sum over a scene or that a server configures (`devsurf serve` flags,
/// docs/protocol.md "Limits"). sceneFromJson applies them to every scene it reads: REST sessions
/// and jobs, the CLI, a session's structural edits (set_params, set_solver, …) and journal replay.
struct ResourceLimits {
  /// Control points of all curves plus a composite's vertices, per scene (`--max-control-points`).
  int maxControlPoints = 20000;
  /// solver.iterations and a quasi_strip's max_iterations (`--max-iterations`, jobs: their own).
  int maxIterations = 10000;
  /// Estimated peak memory of the model a scene builds, bytes (`--memory-budget-mb`; see
  /// estimateResources). A design over it is refused before anything is allocated.
  double memoryBudgetBytes = 512.0 * 1024.0 * 1024.0;
  /// Estimated elementary operations of one solver iteration, which no deadline can interrupt
  /// (a dense factorization, the projections onto a development domain): about a second.
  double maxWorkPerIteration = 1e9;
};

/// One part of a model's estimated memory: what it is, the field that drives it, and its size.
struct ResourcePart {
  std::string path;   ///< the scene field that drives it: "model.mapping.coefficients", "model.np"
  std::string what;   ///< in words: "normal equations of the mapping (dense 10000 × 10000)"
  double bytes = 0.0;
};

/// What building and solving a scene's model is estimated to take (before anything is built).
struct ResourceEstimate {
  double bytes = 0.0;               ///< peak memory, all parts and a fixed base
  std::vector<ResourcePart> parts;  ///< largest first
  /// The largest uninterruptible step: elementary operations of one iteration where they grow
  /// faster than memory (a quasi strip's dense factorization n³/3, a development domain's
  /// projections: boundary samples × domain points); 0 when nothing of the kind. `work.bytes`
  /// holds the operations.
  ResourcePart work;
};

/// Peak memory of the model of `scene`, estimated from its sizes alone (no model is built): the
/// engine's per-row and per-block structures for guided projection (Σ over rows of entries² pair
/// slots, the blocks of eliminated normals), the quasi strip's dense mapping block (coefficients²,
/// and samples × coefficients), the conical strip's samples, the composite's development mesh.
/// The constants are measured peak RSS of `devsurf solve` on scaled examples (strips of 300–10 000
/// control points of degree 3 and 9, quasi strips of 50–2 000 coefficients and 25–100 000
/// samples, conical strips of 55–20 000 samples, composites with 4–6 000 points per S edge and
/// development samples 0–64); the estimate is within about 30 % of them, mostly above.
ResourceEstimate estimateResources(const Scene& scene);

/// Checks a converted scene against the limits.
/// @throws SceneError with rule "limit", naming the field (`model.a.points`, `solver.iterations`,
///         `model.mapping.coefficients` — the part that drives an estimate over the budget,
///         `model.development.domain.boundary` — work per iteration over maxWorkPerIteration)
void checkResourceLimits(const Scene& scene, const ResourceLimits& limits);

/// "1.5 GiB", "300 MiB", "12 KiB" (for messages).
std::string formatBytes(double bytes);

}  // namespace devsurf::proto
