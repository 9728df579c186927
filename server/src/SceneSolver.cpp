#include "devsurf/server/SceneSolver.h"

#include <algorithm>
#include <cstdio>
#include <sstream>
#include <stdexcept>

#include "devsurf/io/FoldWriter.h"
#include "devsurf/io/SvgFoldPattern.h"

namespace devsurf::server {

SceneSolver::SceneSolver(proto::Scene scene) : scene_(std::move(scene)) {
  if (const auto* c = std::get_if<models::composite::CompositeDesign>(&scene_.model)) {
    initialComposite_ = *c;
    try {
      composite_ = std::make_unique<models::composite::CompositeModel>(initialComposite_,
                                                                       scene_.solver.compositeOptions());
    } catch (const std::invalid_argument& e) {
      throw proto::SceneError("model", "model", e.what());
    }
    return;
  }
  initial_ = std::get<models::strip::StripDesign>(scene_.model);
  try {
    strip_ = std::make_unique<models::strip::StripModel>(initial_, scene_.solver.stripOptions());
  } catch (const std::invalid_argument& e) {
    throw proto::SceneError("model", "model", e.what());
  }
}

models::strip::StripModel& SceneSolver::stripModel() {
  if (!strip_) throw std::logic_error("SceneSolver: the scene is not a strip");
  return *strip_;
}

models::composite::CompositeModel& SceneSolver::compositeModel() {
  if (!composite_) throw std::logic_error("SceneSolver: the scene is not a composite");
  return *composite_;
}

engine::SolveSummary SceneSolver::solve(int iterationsOverride,
                                        std::function<bool(const engine::IterationRecord&)> onIteration) {
  engine::SolverOptions options = scene_.solver.solverOptions();
  if (iterationsOverride >= 0) options.maxIterations = iterationsOverride;
  options.callback = std::move(onIteration);
  if (composite_) return composite_->solve(options);
  return strip_->solve(options);
}

proto::Scene SceneSolver::currentScene() const {
  proto::Scene s = scene_;
  if (composite_) {
    s.model = composite_->design();
    return s;
  }
  s.model = strip_->design();
  return s;
}

proto::Metrics SceneSolver::metrics() const {
  if (composite_) {
    const models::composite::CompositeQuality q = composite_->quality();
    const models::composite::CompositeDesign d = composite_->design();
    proto::Metrics m;
    m["face_flatness_max"] = q.faceFlatnessMax;
    m["face_flatness_mean"] = q.faceFlatnessMean;
    m["vertex_curvature_max"] = q.vertexCurvatureMax;
    m["crease_fold_residual_max"] = q.creaseFoldResidualMax;
    m["crease_fold_angle_max_deg"] = q.foldAngleMaxDeg;
    m["warp_angle_max_deg"] = q.warpAngleMaxDeg;
    m["warp_angle_mean_deg"] = q.warpAngleMeanDeg;
    auto point = [&d](const models::composite::PointRef& r) -> Eigen::Vector3d {
      if (r.isVertex()) return d.vertices.row(r.vertex).transpose();
      return d.edges[static_cast<std::size_t>(r.edge)].curve.points.row(r.index).transpose();
    };
    double handleError = 0.0;
    for (const models::composite::Handle& h : d.handles)
      handleError = std::max(handleError, (point(h.point) - h.position).norm());
    m["handle_distance_max"] = handleError;
    double moved = 0.0;
    if (d.vertices.rows() > 0) moved = (d.vertices - initialComposite_.vertices).rowwise().norm().maxCoeff();
    for (std::size_t e = 0; e < d.edges.size(); ++e) {
      const Eigen::MatrixXd& now = d.edges[e].curve.points;
      if (now.rows() > 0)
        moved = std::max(moved, (now - initialComposite_.edges[e].curve.points).rowwise().norm().maxCoeff());
    }
    m["displacement_max"] = moved;
    if (composite_->hasDevelopment()) m["development_length_error"] = composite_->developmentLengthError();
    m["unknowns"] = composite_->numUnknowns();
    return m;
  }
  const metrics::StripQuality q = strip_->quality(1000);
  const models::strip::StripDesign d = strip_->design();
  proto::Metrics m;
  m["warp_angle_max_deg"] = q.warpAngleMaxDeg;
  m["warp_angle_mean_deg"] = q.warpAngleMeanDeg;
  m["developability_residual_max"] = q.developabilityResidualMax;
  double handleError = 0.0;
  for (const models::strip::Handle& h : d.handles) {
    const Eigen::MatrixXd& pts = h.point.curve == models::strip::Curve::A ? d.a.points : d.b.points;
    handleError = std::max(handleError, (pts.row(h.point.index).transpose() - h.position).norm());
  }
  m["handle_distance_max"] = handleError;
  m["displacement_max_a"] = (d.a.points - initial_.a.points).rowwise().norm().maxCoeff();
  m["displacement_max_b"] = (d.b.points - initial_.b.points).rowwise().norm().maxCoeff();
  m["unknowns"] = strip_->numUnknowns();
  return m;
}

nlohmann::json SceneSolver::report(const engine::SolveSummary& summary, double timeMs) const {
  return proto::reportToJson(summary, metrics(), proto::sceneToJson(currentScene()), timeMs);
}

void SceneSolver::exportTo(const std::string& spec) const {
  const std::size_t colon = spec.find(':');
  if (colon == std::string::npos || colon == 0 || colon + 1 == spec.size())
    throw std::invalid_argument("--export: expected FORMAT:FILE, e.g. obj:strip.obj, got \"" + spec + "\"");
  const std::string format = spec.substr(0, colon);
  const std::string path = spec.substr(colon + 1);
  if (format == "fold" || format == "svg") {
    // The messages start "format: <format>…"; on the command line they name the option instead.
    auto option = [](const std::exception& e) { return "--export " + std::string(e.what()).substr(8); };
    io::CreasePattern cp;
    try {
      cp = creasePattern(format);
    } catch (const ExportUnavailable& e) {
      throw ExportUnavailable(option(e));
    } catch (const ExportFailed& e) {
      throw ExportFailed(option(e));
    }
    if (format == "fold")
      io::writeFold(cp, path);
    else
      io::writeSvgFoldPattern(cp, path);
    return;
  }
  if (format != "obj" && format != "off" && format != "ply" && format != "stl")
    throw std::invalid_argument("--export: unknown format \"" + format +
                                "\" (expected obj, off, ply, stl, or fold, svg for composites with a development)");
  // OpenMesh chooses the writer by extension: write with the format's extension, then rename to
  // exactly the requested path.
  const std::string staging = path + ".partial." + format;
  if (composite_) {
    io::writeMesh(composite_->geometry(50, 8).merged, staging);
  } else {
    const models::strip::StripGeometry g = strip_->geometry(200, 8, 2);
    io::writeMesh(g.surface, staging);
  }
  if (std::rename(staging.c_str(), path.c_str()) != 0) {
    std::remove(staging.c_str());
    throw std::runtime_error("cannot write " + path);
  }
}

namespace {

/// Wavefront OBJ text of a quad mesh (1-based indices, one "f" line per quad).
std::string objText(const io::QuadMesh& mesh, const std::string& title) {
  std::ostringstream out;
  out.precision(9);
  out << "# devsurf: " << title << "\n";
  for (Eigen::Index i = 0; i < mesh.vertices.rows(); ++i)
    out << "v " << mesh.vertices(i, 0) << ' ' << mesh.vertices(i, 1) << ' ' << mesh.vertices(i, 2) << "\n";
  for (Eigen::Index q = 0; q < mesh.quads.rows(); ++q)
    out << "f " << mesh.quads(q, 0) + 1 << ' ' << mesh.quads(q, 1) + 1 << ' ' << mesh.quads(q, 2) + 1 << ' '
        << mesh.quads(q, 3) + 1 << "\n";
  return out.str();
}

}  // namespace

io::CreasePattern SceneSolver::creasePattern(const std::string& format) const {
  if (!composite_)
    throw ExportUnavailable("format: " + format + " exports the crease pattern of a composite; this scene is a strip");
  if (!composite_->hasDevelopment())
    throw ExportUnavailable("format: " + format +
                            " needs a development; add \"development\": {\"samples\": n} to the composite model");
  try {
    io::CreasePattern cp = composite_->creasePattern(scene_.name);
    cp.unitToMm = proto::millimetresPerUnit(scene_.units);
    cp.validate();
    return cp;
  } catch (const std::bad_alloc&) {
    throw;
  } catch (const std::exception& e) {
    throw ExportFailed("format: " + format + ": the development in its current state is not a valid crease pattern (" +
                       e.what() + ")");
  }
}

ExportedFile SceneSolver::exportAs(const std::string& format) const {
  if (format != "obj" && format != "fold" && format != "svg")
    throw ExportUnavailable("format: expected json, obj, fold or svg, got \"" + format + "\"");
  if (format == "fold" || format == "svg") {
    const io::CreasePattern cp = creasePattern(format);
    if (format == "fold") return {io::foldString(cp), "application/json", "fold"};
    return {io::svgFoldPattern(cp), "image/svg+xml", "svg"};
  }
  try {
    const io::QuadMesh mesh = composite_ ? composite_->geometry(50, 8).merged : strip_->geometry(200, 8, 2).surface;
    return {objText(mesh, scene_.name), "model/obj", "obj"};
  } catch (const std::bad_alloc&) {
    throw;
  } catch (const std::exception& e) {
    throw ExportFailed("format: obj: the surface in its current state cannot be sampled (" + std::string(e.what()) + ")");
  }
}

ExportedFile SceneSolver::exportScene(const nlohmann::json& scene, const std::string& format) {
  std::unique_ptr<SceneSolver> solver;
  try {
    solver = std::make_unique<SceneSolver>(proto::sceneFromJson(scene));
  } catch (const proto::SceneError& e) {
    throw ExportFailed("format: " + format + ": the current scene no longer builds a model (" + e.what() + ")");
  }
  return solver->exportAs(format);
}

}  // namespace devsurf::server
