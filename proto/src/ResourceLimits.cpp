#include "devsurf/proto/ResourceLimits.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <set>

#include "devsurf/proto/Scene.h"

namespace devsurf::proto {
namespace {

namespace composite = models::composite;

// Measured constants (peak RSS of `devsurf solve`, see estimateResources). They describe this
// build's data structures; re-measure them when the engine's storage changes.
constexpr double kBaseBytes = 16.0 * 1024 * 1024;  ///< the process and a small model
/// Guided projection: per evaluation parameter and squared entries of its rows (the guards' and
/// developability rows' pair slots, the reduced pattern and its factor).
constexpr double kBytesPerRowPair = 24.0;
/// … and per evaluation parameter (normals, Jacobian values, per-row plans, sampled metrics).
constexpr double kBytesPerParameter = 14300.0;
/// Development: per sampled quad and squared entries of its isometry rows (5 pairs per quad).
constexpr double kBytesPerQuadPair = 29.0;
/// Development of a planar face: per pair of its corners (every diagonal is an isometry row).
constexpr double kBytesPerPlanarPair = 600.0;
/// Quasi strip: per pair slot of the eliminated normals' blocks (Σ over distinct kept-column sets
/// c(c+1)/2), per entry of the dense reduced matrix over the mapping (n(n+1)/2), per shape entry
/// of a sample's rows (Σ_i c_i).
constexpr double kQuasiBytesPerBlockSlot = 14.0;
constexpr double kQuasiBytesPerMatrixEntry = 160.0;
constexpr double kQuasiBytesPerSampleEntry = 500.0;
/// Conical strip: per sample of p and q (patches, their development, metrics, the result).
constexpr double kConicalBytesPerSample = 14.0 * 1024;

/// Spans of a curve: n − degree (open) or n (closed); an upper bound with repeated knots.
double spans(const spline::BSplineCurve& c) {
  const double n = static_cast<double>(c.points.rows());
  return c.knots.kind() == spline::KnotKind::Periodic ? n : std::max(1.0, n - c.degree());
}

/// Entries of one row that couples a point and a tangent of two curves of these degrees (and
/// `extra` more, e.g. a normal's 3).
double rowEntries(int degreeA, int degreeB, double extra) { return 3.0 * (degreeA + 1) + 3.0 * (degreeB + 1) + extra; }

void add(ResourceEstimate& e, std::string path, std::string what, double bytes) {
  e.parts.push_back({std::move(path), std::move(what), bytes});
}

std::string number(double x) {
  char buffer[64];
  std::snprintf(buffer, sizeof buffer, "%.0f", x);
  return buffer;
}

void estimateStrip(const models::strip::StripDesign& d, ResourceEstimate& e) {
  const int degree = d.a.degree();
  const bool rational = d.a.isRational() || d.b.isRational();
  const double params = spans(d.a) * (rational ? 6 * degree - 3 : 3 * degree - 2);
  const bool splineNormals = d.normals.type == models::strip::NormalRepresentation::Type::Spline;
  const double normalEntries = splineNormals ? 3.0 * (d.normals.degree + 1) : 3.0;
  const double entries = rowEntries(degree, degree, normalEntries);
  add(e, "model.a.points",
      "guided projection of " + number(params) + " evaluation parameters (degree " + std::to_string(degree) +
          ", rows of " + number(entries) + " entries)",
      params * (kBytesPerRowPair * entries * entries + kBytesPerParameter));
  if (splineNormals) {
    const double points = d.normals.points > 0 ? d.normals.points : static_cast<double>(d.a.points.rows());
    add(e, "model.normals.points", "normal spline of " + number(points) + " control points",
        points * kBytesPerParameter);
  }
  if (d.approximation) {
    // Eq. (9)–(11): six rows per reference point, dense over the curves' (and the normal spline's)
    // control points: values and structure of 3·2n + 9n + 6n + 3m entries.
    const double n = static_cast<double>(d.a.points.rows());
    const double m = splineNormals ? (d.normals.points > 0 ? d.normals.points : n) : 0.0;
    const double perPoint = 3.0 * 2.0 * n + 9.0 * n + 6.0 * n + 3.0 * m;
    add(e, "model.approximation.points",
        "approximation of " + number(static_cast<double>(d.approximation->points.rows())) + " reference points",
        static_cast<double>(d.approximation->points.rows()) * (perPoint * 16.0 + kBytesPerParameter));
  }
}

void estimateComposite(const composite::CompositeDesign& d, ResourceEstimate& e) {
  const int samples = d.developmentSamples;
  double faceBytes = 0.0, developmentBytes = 0.0, planarBytes = 0.0, params = 0.0, quads = 0.0, pairs = 0.0;
  std::size_t largestEdge = 0;
  double largestSpans = -1.0;
  for (const std::vector<int>& face : d.faces) {
    std::vector<const composite::CompositeEdge*> splines;
    for (int index : face)
      if (index >= 0 && static_cast<std::size_t>(index) < d.edges.size() &&
          d.edges[static_cast<std::size_t>(index)].type == composite::EdgeType::Spline) {
        splines.push_back(&d.edges[static_cast<std::size_t>(index)]);
        const double s = spans(d.edges[static_cast<std::size_t>(index)].curve);
        if (s > largestSpans) {
          largestSpans = s;
          largestEdge = static_cast<std::size_t>(index);
        }
      }
    if (splines.empty()) {  // planar: every pair of corners is a development row
      const double n = static_cast<double>(face.size());
      if (samples > 0) {
        planarBytes += kBytesPerPlanarPair * n * (n - 1) / 2;
        pairs += n * (n - 1) / 2;
      }
      continue;
    }
    // The face's two highest-degree S edges (a cone has one; its apex is a point: degree 0).
    double faceSpans = 0.0;
    std::vector<int> degrees;
    for (const composite::CompositeEdge* s : splines) {
      faceSpans = std::max(faceSpans, spans(s->curve));
      degrees.push_back(s->curve.degree());
    }
    std::sort(degrees.rbegin(), degrees.rend());
    const int degree = degrees[0];
    const double entries = rowEntries(degree, degrees.size() >= 2 ? degrees[1] : 0, 3.0);
    const double p = 2.0 + faceSpans * (3 * degree - 2);
    params += p;
    faceBytes += p * (kBytesPerRowPair * entries * entries + kBytesPerParameter);
    if (samples > 0) {
      const double q = faceSpans * samples, rowEntriesDev = entries + 1.0;  // two samples' points and 4 coordinates
      quads += q;
      developmentBytes += q * kBytesPerQuadPair * rowEntriesDev * rowEntriesDev;
    }
  }
  const std::string edgePath = largestSpans >= 0 ? "model.edges[" + std::to_string(largestEdge) + "].points" : "model.faces";
  add(e, edgePath, "guided projection of the faces (" + number(params) + " evaluation parameters)", faceBytes);
  // Every boundary sample of the development is projected onto its domain curve every iteration
  // (and onto every curve once, to choose it): at most all samples × all domain points.
  double domainPoints = 0.0;
  for (const composite::DomainCurve& c : d.developmentDomain.boundary) domainPoints += static_cast<double>(c.points.rows());
  if (samples > 0 && domainPoints > 0.0) {
    double sampled = static_cast<double>(d.vertices.rows());
    for (const composite::CompositeEdge& edge : d.edges)
      if (edge.type == composite::EdgeType::Spline) sampled += spans(edge.curve) * samples;
    e.work = {"model.development.domain.boundary",
              "projections of up to " + number(sampled) + " development samples onto " + number(domainPoints) +
                  " domain boundary points",
              sampled * domainPoints};
  }
  if (samples > 0) {
    add(e, "model.development.samples",
        "the development mesh (" + number(quads) + " sampled quads at " + std::to_string(samples) + " per span)",
        developmentBytes);
    if (planarBytes > 0.0)
      add(e, "model.faces", "the development of the planar faces (" + number(pairs) + " corner pairs)", planarBytes);
  }
}

void estimateQuasiStrip(const QuasiStripScene& q, ResourceEstimate& e) {
  const models::quasi_strip::QuasiStripDesign& d = q.design;
  const bool discrete = q.options.method == models::quasi_strip::MappingMethod::Discrete;
  const int K = std::max(2, d.samples);
  // Shape columns of each sample's rows (σ(t_i) depends on ε_0 … ε_last(i)) and the distinct
  // column sets (one block of the eliminated normals each).
  const int n = discrete ? K : std::max(d.mapping.coefficients, d.mapping.degree + 1);
  const int spanCount = std::max(1, n - d.mapping.degree);
  double sampleEntries = 0.0, blockSlots = 0.0;
  std::set<int> blocks;
  for (int i = 0; i < K; ++i) {
    const int c = discrete ? i + 1
                           : std::min(static_cast<int>(static_cast<double>(i) / (K - 1) * spanCount), spanCount - 1) +
                                 d.mapping.degree + 1;
    sampleEntries += c;
    blocks.insert(c);
  }
  for (int c : blocks) blockSlots += 0.5 * c * (c + 1.0);
  const double matrix = 0.5 * n * (n + 1.0);
  const double byMapping = kQuasiBytesPerBlockSlot * blockSlots + kQuasiBytesPerMatrixEntry * matrix;
  const double bySamples = kQuasiBytesPerSampleEntry * sampleEntries;
  const std::string mappingPath = discrete ? "model.samples" : "model.mapping.coefficients";
  add(e, mappingPath,
      "normal equations of the mapping (dense " + std::to_string(n) + " × " + std::to_string(n) + ", " +
          std::to_string(blocks.size()) + " blocks of sample normals)",
      byMapping);
  add(e, "model.samples", number(K) + " sample rulings × " + number(sampleEntries / K) + " mapping coefficients each",
      bySamples);
  e.work = {mappingPath, "a dense factorization of " + std::to_string(n) + " × " + std::to_string(n),
            static_cast<double>(n) * n * n / 3.0};
}

void estimateConicalStrip(const models::conical_strip::ConicalStripDesign& d, ResourceEstimate& e) {
  add(e, d.np >= d.nq ? "model.np" : "model.nq",
      number(d.np + d.nq) + " samples of p and q (patches, development, metrics)",
      kConicalBytesPerSample * (static_cast<double>(d.np) + d.nq));
}

/// Quad mesh (issue 13): per face and squared free entries of its isometry rows (3 rows of up to
/// 24 variables when both meshes move), and per vertex (x, terms' index lists, metrics, geometry).
constexpr double kQuadBytesPerRowPair = 24.0;
constexpr double kQuadBytesPerVertex = 2048.0;

void estimateQuadMesh(const models::quad_mesh::QuadMeshDesign& d, ResourceEstimate& e) {
  const double V = static_cast<double>(d.mesh.rows()), F = static_cast<double>(d.faces.size());
  const double perRow = d.variable == models::quad_mesh::VariableMeshes::Both ? 24.0 : 12.0;
  add(e, "model.faces", number(F) + " faces × 3 isometry rows of " + number(perRow) + " unknowns",
      kQuadBytesPerRowPair * 3.0 * F * perRow * perRow);
  add(e, "model.mesh", number(V) + " vertices of M and M′", kQuadBytesPerVertex * V);
  if (d.reference)
    add(e, "model.reference.faces", number(static_cast<double>(d.reference->triangles.rows())) +
                                            " reference triangles (search tree)",
        200.0 * static_cast<double>(d.reference->triangles.rows()));
}

/// Control points of the scene's curves and vertices, and the largest list (its path).
int countControlPoints(const Scene& scene, std::string& largestPath) {
  long total = 0, largest = -1;
  auto count = [&total, &largest, &largestPath](long n, const std::string& path) {
    total += n;
    if (n > largest) {
      largest = n;
      largestPath = path;
    }
  };
  if (const auto* s = std::get_if<models::strip::StripDesign>(&scene.model)) {
    count(s->a.points.rows(), "model.a.points");
    count(s->b.points.rows(), "model.b.points");
  } else if (const auto* c = std::get_if<composite::CompositeDesign>(&scene.model)) {
    count(c->vertices.rows(), "model.vertices");
    for (std::size_t i = 0; i < c->edges.size(); ++i)
      if (c->edges[i].type == composite::EdgeType::Spline)
        count(std::max<long>(0, c->edges[i].curve.points.rows() - 2), "model.edges[" + std::to_string(i) + "].points");
  } else if (const auto* q = std::get_if<QuasiStripScene>(&scene.model)) {
    count(q->design.c1.points.rows(), "model.c1.points");
    count(q->design.c2.points.rows(), "model.c2.points");
  } else if (const auto* k = std::get_if<models::conical_strip::ConicalStripDesign>(&scene.model)) {
    count(k->p.points.rows(), "model.p.points");
    count(k->q.points.rows(), "model.q.points");
  } else if (const auto* m = std::get_if<models::quad_mesh::QuadMeshDesign>(&scene.model)) {
    count(m->mesh.rows(), "model.mesh.vertices");
  }
  return static_cast<int>(std::min<long>(total, 2147483647L));
}

}  // namespace

std::string formatBytes(double bytes) {
  char buffer[64];
  if (bytes >= 1024.0 * 1024 * 1024)
    std::snprintf(buffer, sizeof buffer, "%.1f GiB", bytes / (1024.0 * 1024 * 1024));
  else if (bytes >= 1024.0 * 1024)
    std::snprintf(buffer, sizeof buffer, "%.0f MiB", bytes / (1024.0 * 1024));
  else
    std::snprintf(buffer, sizeof buffer, "%.0f KiB", bytes / 1024.0);
  return buffer;
}

ResourceEstimate estimateResources(const Scene& scene) {
  ResourceEstimate e;
  if (const auto* s = std::get_if<models::strip::StripDesign>(&scene.model))
    estimateStrip(*s, e);
  else if (const auto* c = std::get_if<composite::CompositeDesign>(&scene.model))
    estimateComposite(*c, e);
  else if (const auto* q = std::get_if<QuasiStripScene>(&scene.model))
    estimateQuasiStrip(*q, e);
  else if (const auto* k = std::get_if<models::conical_strip::ConicalStripDesign>(&scene.model))
    estimateConicalStrip(*k, e);
  else if (const auto* m = std::get_if<models::quad_mesh::QuadMeshDesign>(&scene.model))
    estimateQuadMesh(*m, e);
  std::stable_sort(e.parts.begin(), e.parts.end(),
                   [](const ResourcePart& x, const ResourcePart& y) { return x.bytes > y.bytes; });
  e.bytes = kBaseBytes;
  for (const ResourcePart& p : e.parts) e.bytes += p.bytes;
  return e;
}

void checkResourceLimits(const Scene& scene, const ResourceLimits& limits) {
  std::string largest;
  const int points = countControlPoints(scene, largest);
  if (points > limits.maxControlPoints)
    throw SceneError(largest, "limit",
                     "the scene has " + std::to_string(points) + " control points; this server allows " +
                         std::to_string(limits.maxControlPoints) + " per scene");
  if (scene.solver.iterations > limits.maxIterations)
    throw SceneError("solver.iterations", "limit",
                     "at most " + std::to_string(limits.maxIterations) + " iterations, got " +
                         std::to_string(scene.solver.iterations));
  if (const auto* q = std::get_if<QuasiStripScene>(&scene.model); q && q->maxIterations > limits.maxIterations)
    throw SceneError("model.max_iterations", "limit",
                     "at most " + std::to_string(limits.maxIterations) + " iterations, got " +
                         std::to_string(q->maxIterations));
  const ResourceEstimate e = estimateResources(scene);
  if (!(e.bytes <= limits.memoryBudgetBytes)) {
    const ResourcePart& driver = e.parts.front();
    throw SceneError(driver.path, "limit",
                     "the model would need about " + formatBytes(e.bytes) + " of memory, over the budget of " +
                         formatBytes(limits.memoryBudgetBytes) + "; most of it for " + driver.what + " (" +
                         formatBytes(driver.bytes) + ")");
  }
  if (e.work.bytes > limits.maxWorkPerIteration) {
    char operations[64];
    std::snprintf(operations, sizeof operations, "%.1e", e.work.bytes);
    char limit[64];
    std::snprintf(limit, sizeof limit, "%.0e", limits.maxWorkPerIteration);
    throw SceneError(e.work.path, "limit",
                     std::string("one iteration would take about ") + operations + " operations for " + e.work.what +
                         ", over the limit of " + limit + " (about a second) that no time budget can interrupt");
  }
}

}  // namespace devsurf::proto
