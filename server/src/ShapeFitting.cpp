// Strips onto a user's shape: the service behind `devsurf fit`, `devsurf cover`, POST /api/fits,
// /api/covers and /api/references (issue 15, 000_… §4.2, Fig. 10).
#include "devsurf/server/ShapeFitting.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <random>
#include <sstream>

#include "devsurf/models/composite/CompositeFromStrips.h"
#include "devsurf/models/composite/CompositeModel.h"
#include "devsurf/models/strip/StripCover.h"
#include "devsurf/models/strip/StripShapeCover.h"
#include "devsurf/reference/PointNormals.h"
#include "devsurf/reference/PointThinning.h"

namespace devsurf::server {

namespace {

/// "x,y,z" → a finite point. @throws ApproximationInputError naming the field
Eigen::Vector3d pointParameter(const std::string& field, const std::string& value) {
  Eigen::Vector3d p;
  std::size_t start = 0;
  for (int c = 0; c < 3; ++c) {
    const std::size_t comma = value.find(',', start);
    if ((c < 2) != (comma != std::string::npos))
      throw ApproximationInputError(field, field + ": expected x,y,z, got \"" + value + "\"");
    const std::string part = value.substr(start, c < 2 ? comma - start : std::string::npos);
    std::size_t used = 0;
    try {
      p[c] = std::stod(part, &used);
    } catch (const std::exception&) {
      used = 0;
    }
    if (part.empty() || used != part.size() || !std::isfinite(p[c]))
      throw ApproximationInputError(field, field + ": expected x,y,z with finite numbers, got \"" + value + "\"");
    start = comma + 1;
  }
  return p;
}

/// The region's points (a ball, or all of the shape) and their normals when the shape has them.
std::pair<Eigen::MatrixX3d, Eigen::MatrixX3d> regionOf(const reference::ReferenceShape& shape,
                                                       const RegionFitRequest& request) {
  std::vector<int> region;
  if (request.centre) region = models::strip::pointsInBall(shape.points, *request.centre, request.radius);
  else {
    region.resize(static_cast<std::size_t>(shape.points.rows()));
    std::iota(region.begin(), region.end(), 0);
  }
  Eigen::MatrixX3d points(static_cast<Eigen::Index>(region.size()), 3), normals(0, 3);
  if (shape.normals.rows() > 0) normals.resize(points.rows(), 3);
  for (std::size_t k = 0; k < region.size(); ++k) {
    points.row(static_cast<Eigen::Index>(k)) = shape.points.row(region[k]);
    if (shape.normals.rows() > 0) normals.row(static_cast<Eigen::Index>(k)) = shape.normals.row(region[k]);
  }
  return {points, normals};
}

/// @param[in] field  the parameter to change: "radius" for a ball, else what asked for the points
void requireRegion(const Eigen::MatrixX3d& points, long needed, const std::string& source, const std::string& what,
                   const std::string& field = "radius") {
  const std::string region = field == "radius" ? "the region" : "the shape";
  if (points.rows() < needed)
    throw ApproximationInputError(field, field + ": " + region + " holds " + std::to_string(points.rows()) +
                                             " points of " + source + "; " + what + " needs at least " +
                                             std::to_string(needed));
  if (!((points.colwise().maxCoeff() - points.colwise().minCoeff()).norm() > 0.0))
    throw ApproximationInputError(field, field + ": " + region + "'s points all coincide");
}

}  // namespace

RegionFitRequest regionFitRequestFromQuery(const std::multimap<std::string, std::string>& params, bool cover) {
  RegionFitRequest r;
  for (const auto& [key, value] : params) {
    if (key == "format") continue;  // read by the route
    if (key == "centre" || key == "center") r.centre = pointParameter(key, value);
    else if (key == "radius") r.radius = numberParameter(key, value, 0.0, 1e12, true);
    else if (key == "thin") r.thin = numberParameter(key, value, 0.0, 1e12, true);
    else if (key == "seed") r.seed = static_cast<std::uint32_t>(integerParameter(key, value, 0, 4294967295L));
    else if (key == "control_points") r.controlPoints = static_cast<int>(integerParameter(key, value, 4, 200));
    else if (key == "iterations") r.iterations = static_cast<int>(integerParameter(key, value, 0, 10000));
    else if (key == "rulings" && !cover) {
      if (value == "auto") r.rulings = models::strip::RegionStripOptions::Rulings::Auto;
      else if (value == "across") r.rulings = models::strip::RegionStripOptions::Rulings::AcrossLongest;
      else if (value == "along") r.rulings = models::strip::RegionStripOptions::Rulings::AlongLongest;
      else throw ApproximationInputError(key, "rulings: expected auto, across or along, got \"" + value + "\"");
    } else if (key == "flat" && !cover) {
      if (value != "true" && value != "false")
        throw ApproximationInputError(key, "flat: expected true or false, got \"" + value + "\"");
      r.flat = value == "true";
    } else if (key == "strips" && cover) r.strips = static_cast<int>(integerParameter(key, value, 1, 64));
    else if (key == "rounds" && cover) r.rounds = static_cast<int>(integerParameter(key, value, 0, 100));
    else if (key == "regions" && cover) r.regions = static_cast<int>(integerParameter(key, value, 1, 32));
    else if (key == "overhang") r.overhang = numberParameter(key, value, 0.0, 10.0, false);
    else if (key == "crease" && cover) {
      if (value == "none") r.crease = models::composite::CreaseKind::None;
      else if (value == "fold") r.crease = models::composite::CreaseKind::Fold;
      else throw ApproximationInputError(key, "crease: expected none or fold, got \"" + value + "\"");
    } else if (key == "name") r.name = nameParameter(key, value);
    else if (key == "units") r.units = unitsParameter(key, value);
    else {
      throw ApproximationInputError(key, key + ": unknown parameter (centre, radius, thin, seed, control_points, " +
                                             (cover ? std::string("strips, rounds, crease, regions") : std::string("iterations, rulings, flat")) +
                                             ", overhang, name, units, format)");
    }
  }
  // The sweeps run in the caller's thread (a request's): bounded to about ten seconds.
  if (cover && r.strips * r.rounds > 400)
    throw ApproximationInputError("rounds", "rounds: strips × rounds is at most 400 (" + std::to_string(r.strips) +
                                                " × " + std::to_string(r.rounds) + ")");
  if (cover && r.regions * r.strips * std::max(r.rounds, 1) > 1600)
    throw ApproximationInputError("regions", "regions: regions × strips × rounds is at most 1600 (" +
                                                 std::to_string(r.regions) + " × " + std::to_string(r.strips) + " × " +
                                                 std::to_string(r.rounds) + ")");
  if (r.centre.has_value() != (r.radius > 0.0))
    throw ApproximationInputError(r.centre ? "radius" : "centre", "centre and radius go together");
  return r;
}

RegionFitResult fitStripToShape(const reference::ReferenceShape& shape, const std::string& source,
                                const RegionFitRequest& request) {
  const auto [points, normals] = regionOf(shape, request);
  requireRegion(points, 6, source, "a strip");
  // 000_… §4.2: thin like Poisson sampling; the ball's plane gives each kept point its normal.
  reference::ThinningOptions thinning;
  thinning.radius = request.thin > 0.0 ? request.thin : reference::suggestedThinningRadius(points, normals.rows() > 0);
  thinning.seed = request.seed;
  const reference::ThinnedCloud thin = reference::thinPointCloud(points, normals, thinning);
  models::strip::ApproximationTarget target = models::strip::approximationTargetFrom(thin.points, thin.normals);
  const Eigen::Index kept = target.points.rows();
  if (kept < 6)
    throw ApproximationInputError("thin", "thin: " + std::to_string(kept) +
                                              " thinned points have a fitted normal; a smaller radius keeps more");
  // Fig. 10a: a strip placed by PCA over the region, then eq. (9)–(11) with a normal spline.
  models::strip::RegionStripOptions placement;
  placement.controlPoints = request.controlPoints;
  placement.rulings = request.rulings;
  placement.liftToHeightField = !request.flat;
  models::strip::StripDesign design = models::strip::flatStripOverRegion(target.points, placement);
  design.normals.type = models::strip::NormalRepresentation::Type::Spline;
  design.normals.points = placement.controlPoints;
  target.overhangWeight = request.overhang;
  design.approximation = std::move(target);
  RegionFitResult result;
  proto::Scene& scene = result.scene;
  scene.name = request.name.empty() ? "strip fitted to " + source : request.name;
  scene.description = "A developable strip approximating " + std::to_string(kept) + " thinned points of " + source +
                      " (devsurf fit; Tang et al. 2016 §4.2).";
  scene.units = request.units;
  scene.model = std::move(design);
  // Fig. 17, row 10 (approximating the bunny): ε₁ = 0.001 and fairness 0.001.
  scene.solver.iterations = request.iterations;
  scene.solver.regularization = 1e-3;
  scene.solver.fairness = 1e-3;
  result.summary = {{"region_points", points.rows()}, {"thinned_points", kept}, {"thin_radius", thinning.radius}};
  return result;
}

namespace {

models::strip::RegionCoverOptions regionCoverOptions(const RegionFitRequest& request) {
  models::strip::RegionCoverOptions options;
  options.strips = request.strips;
  options.thinRadius = request.thin;
  options.seed = request.seed;
  options.placement.controlPoints = request.controlPoints;
  options.pairing.rounds = request.rounds;
  options.pairing.deadline = request.timeLimitMs > 0.0
                                 ? engine::Deadline::after(request.timeLimitMs, "the cover's time limit")
                                 : engine::Deadline();
  options.overhangWeight = request.overhang;
  return options;
}

nlohmann::json sweepRounds(const models::strip::RegionCover& cover) {
  nlohmann::json rounds = nlohmann::json::array();
  for (const auto& r : cover.paired.rounds)
    rounds.push_back({{"gap_max", r.gapMax}, {"gap_mean", r.gapMean}, {"warp_angle_max_deg", r.warpMaxDeg}});
  return rounds;
}

double lastSweepWarp(const models::strip::RegionCover& cover) {
  return cover.paired.rounds.empty() ? 0.0 : cover.paired.rounds.back().warpMaxDeg;
}

std::string steepWarning(const std::string& where, double steepFraction) {
  return std::to_string(std::lround(100 * steepFraction)) + " % of " + where +
         "'s normals are more than 75° from its mean plane's: the region wraps around the shape and bands across a "
         "plane do not describe it";
}

std::string warpWarning(const std::string& where, double warp) {
  std::ostringstream text;
  text << "after the last sweep a strip of " << where << " is " << warp
       << "° from developable; the composite may not solve";
  return text.str();
}

/// The whole cover's warp limit (the composite presets' fabrication threshold)…
constexpr double kRegionWarpLimitDeg = 0.05;
/// … and a region's own: its composite is kept when its solve ends within half the whole's, as
/// the union's solve moves the parts again. At 0.5° parts that ended near it drove the union's
/// solve to 0.8°; at 0.05° a part that ended at 0.046° went to 0.134° in the union (CGAL's
/// bunny in 32 regions).
constexpr double kPartWarpLimitDeg = 0.5 * kRegionWarpLimitDeg;
/// The same for the faces' flatness (Tang et al. Fig. 17's δ, 1e-3 for fabrication): a part is
/// kept within half of it (a part at 0.9e-3 ended the union at 1.05e-3).
constexpr double kPartFlatnessLimit = 0.5e-3;
/// A region's composite is kept when none of its curves turns back by more than this between
/// neighbouring samples (max(0, −cos θ)): a curve that doubles back is a piece that overlaps
/// itself. The curve, not its control polygon (crease_backtrack_max): on CGAL's bunny two
/// regions' control polygons turned back (0.49, 0.66) along curves that turn by at most 90°,
/// and one curve itself doubled back (0.74).
constexpr double kRegionReversalLimit = 0.05;

/// Largest max(0, −cos θ) of the turn between consecutive chords of every S edge sampled at 400
/// parameters (chords shorter than 1e-9 of the edge's length skipped).
double curveReversalMax(const models::composite::CompositeDesign& design) {
  double worst = 0.0;
  for (const models::composite::CompositeEdge& edge : design.edges) {
    if (edge.type != models::composite::EdgeType::Spline || edge.curve.points.rows() < 2) continue;
    const Eigen::MatrixXd samples = edge.curve.evaluate(edge.curve.knots.uniformSamples(401), 0);
    double length = 0.0;
    for (Eigen::Index k = 1; k < samples.rows(); ++k) length += (samples.row(k) - samples.row(k - 1)).norm();
    Eigen::RowVectorXd previous = Eigen::RowVectorXd::Zero(samples.cols());
    for (Eigen::Index k = 1; k < samples.rows(); ++k) {
      const Eigen::RowVectorXd chord = samples.row(k) - samples.row(k - 1);
      if (!(chord.norm() > 1e-9 * length)) continue;
      if (previous.norm() > 0.0) worst = std::max(worst, -previous.normalized().dot(chord.normalized()));
      previous = chord;
    }
  }
  return worst;
}
/// ε_reg of a cover of several regions (see coverShapeByRegions).
constexpr double kUnionRegularization = 1.0;

/// The solver settings of a cover's composite scene. No fairness: it pulls the composite off the
/// shape (a sphere cap: RMS 0.25 % → 1 % of the diagonal in 10 iterations at ε_fair = ε_reg =
/// 1e-3); ε_reg = 1e-2 keeps it in place.
void setCoverSolver(proto::Scene& scene) {
  scene.solver.iterations = 20;
  scene.solver.regularization = 1e-2;
  scene.solver.fairness = 0.0;
}

/// One region's paired strips joined as a composite and solved as its scene would be.
struct RegionComposite {
  models::composite::CompositeDesign design;
  double warpDeg = std::numeric_limits<double>::quiet_NaN();  ///< largest warp after the solve
  double flatness = std::numeric_limits<double>::quiet_NaN();  ///< face_flatness_max after the solve
  double reversal = 0.0;  ///< curveReversalMax after the solve
  std::string failure;  ///< why the strips could not be joined or solved ("" when they were)
};

/// @throws engine::DeadlineExceeded when the request's time runs out
RegionComposite solvedRegionComposite(const models::strip::RegionCover& cover, models::composite::CreaseKind crease,
                                      const engine::Deadline& deadline) {
  RegionComposite out;
  try {
    proto::Scene scene;
    scene.model = models::composite::compositeFromStrips(cover.paired.strips, cover.pairings, crease);
    setCoverSolver(scene);
    models::composite::CompositeModel model(std::get<models::composite::CompositeDesign>(scene.model));
    engine::SolverOptions options = scene.solver.solverOptions();
    options.deadline = deadline;
    model.solve(options);
    out.design = model.design();
    out.warpDeg = model.quality().warpAngleMaxDeg;
    out.flatness = model.quality().faceFlatnessMax;
    out.reversal = curveReversalMax(out.design);
  } catch (const engine::DeadlineExceeded&) {
    throw;
  } catch (const std::exception& e) {
    out.failure = e.what();
  }
  return out;
}

/// Appends the points of a cover's bands (the region as covered) to `covered`.
void appendCoveredPoints(const models::strip::RegionCover& cover, const Eigen::MatrixX3d& points,
                         const std::vector<int>& rows, std::vector<Eigen::RowVector3d>& covered) {
  for (const auto& band : cover.layout.bands)
    for (const int j : band) covered.push_back(points.row(rows.empty() ? j : rows[static_cast<std::size_t>(j)]));
}

Eigen::MatrixX3d stackRows(const std::vector<Eigen::RowVector3d>& rows) {
  Eigen::MatrixX3d out(static_cast<Eigen::Index>(rows.size()), 3);
  for (std::size_t k = 0; k < rows.size(); ++k) out.row(static_cast<Eigen::Index>(k)) = rows[k];
  return out;
}

/// Fig. 10e: the region segmented, each part covered by its own strips, one composite of all.
RegionFitResult coverShapeByRegions(const reference::ReferenceShape& shape, const std::string& source,
                                    const RegionFitRequest& request) {
  // Normals oriented over the whole shape (a mesh's own, a file's, or fitted and propagated), so
  // that the two sides of an ear fall into different regions.
  const Eigen::MatrixX3d allNormals = reference::orientedPointNormals(shape);
  std::vector<int> rows;
  if (request.centre) rows = models::strip::pointsInBall(shape.points, *request.centre, request.radius);
  else {
    rows.resize(static_cast<std::size_t>(shape.points.rows()));
    std::iota(rows.begin(), rows.end(), 0);
  }
  Eigen::MatrixX3d points(static_cast<Eigen::Index>(rows.size()), 3), normals(points.rows(), 3);
  for (std::size_t k = 0; k < rows.size(); ++k) {
    points.row(static_cast<Eigen::Index>(k)) = shape.points.row(rows[k]);
    normals.row(static_cast<Eigen::Index>(k)) = allNormals.row(rows[k]);
  }
  requireRegion(points, 6L * request.strips * request.regions, source,
                std::to_string(request.regions) + " regions of " + std::to_string(request.strips) + " strips",
                request.centre ? "radius" : "regions");
  models::strip::ShapeCoverOptions options;
  options.regions = request.regions;
  options.seed = request.seed;
  const double keep = options.region.keep;
  options.region = regionCoverOptions(request);
  options.region.keep = keep;
  options.deadline = options.region.pairing.deadline;  // one limit for the whole request
  const models::strip::ShapeCover cover = models::strip::coverShapeByRegions(points, normals, options);

  RegionFitResult result;
  nlohmann::json& summary = result.summary;
  summary = {{"region_points", points.rows()}, {"strips", request.strips}, {"regions", nlohmann::json::array()}};
  std::vector<models::composite::CompositeDesign> parts;
  int stripCount = 0;
  std::vector<Eigen::RowVector3d> covered;
  int coveredRegions = 0;
  for (std::size_t r = 0; r < cover.regions.size(); ++r) {
    const models::strip::ShapeRegionCover& region = cover.regions[r];
    const std::string name = "region " + std::to_string(r);
    nlohmann::json entry = {{"points", region.points.size()}, {"covered", region.covered}};
    if (!region.covered) {
      entry["skipped"] = region.skipped;
      result.warnings.push_back(name + " (" + std::to_string(region.points.size()) + " points) is not covered: " +
                                region.skipped);
      summary["regions"].push_back(std::move(entry));
      continue;
    }
    const models::strip::RegionCover& c = region.cover;
    // A region whose strips did not end developable, or whose own composite does not start so
    // (a pairing's gap left large: one strip takes the other's curve), would spoil the whole
    // composite's solve: it is left out.
    std::ostringstream why;
    RegionComposite part;
    if (!(lastSweepWarp(c) <= 1.0)) why << "its strips ended " << lastSweepWarp(c) << "° from developable";
    else {
      part = solvedRegionComposite(c, request.crease, options.deadline);
      entry["composite_warp_angle_max_deg"] = std::isfinite(part.warpDeg) ? nlohmann::json(part.warpDeg) : nlohmann::json();
      entry["composite_face_flatness_max"] = std::isfinite(part.flatness) ? nlohmann::json(part.flatness) : nlohmann::json();
      if (!part.failure.empty()) why << "its strips do not make a composite: " << part.failure;
      else if (!(part.warpDeg <= kPartWarpLimitDeg))
        why << "its strips joined as a composite solve to " << part.warpDeg << "° from developable";
      else if (!(part.flatness <= kPartFlatnessLimit))
        why << "its strips joined as a composite solve to faces " << part.flatness << " from flat (face_flatness_max)";
      else if (!(part.reversal <= kRegionReversalLimit))
        why << "a curve of its strips doubles back (max(0, −cos) of its turn " << part.reversal << ")";
    }
    if (!why.str().empty()) {
      entry["covered"] = false;
      entry["skipped"] = why.str();
      entry["rounds"] = sweepRounds(c);
      result.warnings.push_back(name + " (" + std::to_string(region.points.size()) + " points) is not covered: " + why.str());
      summary["regions"].push_back(std::move(entry));
      continue;
    }
    ++coveredRegions;
    entry["first_face"] = stripCount;
    entry["steep_fraction"] = c.steepFraction;
    entry["rounds"] = sweepRounds(c);
    if (c.steepFraction > 0.05) result.warnings.push_back(steepWarning(name, c.steepFraction));
    stripCount += static_cast<int>(c.paired.strips.size());
    parts.push_back(std::move(part.design));
    std::vector<int> shapeRows;
    for (const int j : region.points) shapeRows.push_back(rows[static_cast<std::size_t>(j)]);
    appendCoveredPoints(c, shape.points, shapeRows, covered);
    summary["regions"].push_back(std::move(entry));
  }
  if (coveredRegions == 0)
    throw ApproximationInputError("regions", "regions: none of the " + std::to_string(cover.regions.size()) +
                                                 " regions could be covered (region 0: " +
                                                 summary["regions"][0].value("skipped", std::string()) +
                                                 "); fewer regions or more strips");
  proto::Scene& scene = result.scene;
  scene.name = request.name.empty() ? std::to_string(coveredRegions) + " regions covering " + source : request.name;
  scene.description = "A composite of " + std::to_string(stripCount) + " developable strips in " +
                      std::to_string(coveredRegions) + " parts covering " + (request.centre ? "a region of " : "") +
                      source + ": the shape segmented by normal, each part covered by strips side by side " +
                      "with paired boundaries (devsurf cover --regions; Tang et al. 2016 Fig. 10e).";
  scene.units = request.units;
  // The parts as their own solves left them, then solved together as the scene will be. The
  // solver works in coordinates normalized by the whole shape, where a small part's moves are
  // small and ε_reg = 1e-2 holds it too loosely (CGAL's bunny in 38 regions: a part solved to
  // 0.004° alone went to 45° in the union). At ε_reg = 0.1 a second solve of a union could still
  // spike (0.02° → 3.0° → 0.02°); at 0.3 one of four seeds crept 0.04° → 0.07° → 0.19° over three
  // solves; at 1.0 all four stay within 0.025°. The parts come solved: holding them hard costs
  // nothing but the stiffness of a drag.
  setCoverSolver(scene);
  scene.solver.regularization = kUnionRegularization;
  models::composite::CompositeModel union_(models::composite::disjointUnion(parts));
  // Twice the scene's iterations: the parts moved from their own solves' normalization settle
  // (CGAL's bunny, seed 2: 0.31° after 20, 0.02° after 40).
  engine::SolverOptions unionOptions = scene.solver.solverOptions();
  unionOptions.maxIterations *= 2;
  unionOptions.deadline = options.deadline;
  const engine::SolveSummary solved = union_.solve(unionOptions);
  scene.model = union_.design();
  const models::composite::CompositeQuality quality = union_.quality();
  summary["face_flatness_max"] = quality.faceFlatnessMax;
  summary["warp_angle_max_deg"] = std::isfinite(quality.warpAngleMaxDeg) ? nlohmann::json(quality.warpAngleMaxDeg) : nlohmann::json();
  if (!(quality.warpAngleMaxDeg <= kRegionWarpLimitDeg)) {
    std::ostringstream text;
    text << "the parts solved together end " << quality.warpAngleMaxDeg << "° from developable ("
         << engine::terminationReasonName(solved.reason) << ")";
    result.warnings.push_back(text.str());
  }
  summary["covered_regions"] = coveredRegions;
  summary["warnings"] = result.warnings;
  result.covered = stackRows(covered);
  return result;
}

RegionFitResult coverOneRegion(const reference::ReferenceShape& shape, const std::string& source,
                               const RegionFitRequest& request);

}  // namespace

RegionFitResult coverShapeWithStrips(const reference::ReferenceShape& shape, const std::string& source,
                                     const RegionFitRequest& request) {
  try {
    if (request.regions > 1) return coverShapeByRegions(shape, source, request);
    return coverOneRegion(shape, source, request);
  } catch (const engine::DeadlineExceeded& e) {
    // The request's thread is bounded: the work asked for did not fit in its time.
    throw ApproximationInputError(request.regions > 1 ? "regions" : "rounds",
                                  std::string(request.regions > 1 ? "regions: " : "rounds: ") + e.what() +
                                      "; fewer regions, strips or rounds",
                                  true);
  }
}

namespace {

RegionFitResult coverOneRegion(const reference::ReferenceShape& shape, const std::string& source,
                               const RegionFitRequest& request) {
  const auto [points, normals] = regionOf(shape, request);
  requireRegion(points, 6L * request.strips, source, std::to_string(request.strips) + " strips");
  models::strip::RegionCover cover;
  try {
    cover = models::strip::coverRegion(points, normals, regionCoverOptions(request));
  } catch (const std::invalid_argument& e) {
    // Too few points in the layout's rectangle or a band: the region is the user's to change.
    throw ApproximationInputError("radius", std::string("radius: ") + e.what());
  }
  RegionFitResult result;
  proto::Scene& scene = result.scene;
  scene.name = request.name.empty() ? std::to_string(request.strips) + " strips covering " + source : request.name;
  scene.description = "A composite of " + std::to_string(request.strips) + " developable strips covering " +
                      (request.centre ? "a region of " : "") + source +
                      ", fitted side by side with paired boundaries (devsurf cover; Tang et al. 2016 Fig. 10).";
  scene.units = request.units;
  // Fig. 10d → e: the paired strips initialize a composite (one face per strip).
  scene.model = models::composite::compositeFromStrips(cover.paired.strips, cover.pairings, request.crease);
  setCoverSolver(scene);
  nlohmann::json& summary = result.summary;
  summary = {{"region_points", points.rows()}, {"strips", request.strips}, {"steep_fraction", cover.steepFraction}};
  summary["pairings"] = nlohmann::json::array();
  for (const auto& p : cover.pairings)
    summary["pairings"].push_back({{"first", p.first},
                                   {"first_curve", models::strip::curveName(p.firstCurve)},
                                   {"second", p.second},
                                   {"second_curve", models::strip::curveName(p.secondCurve)},
                                   {"reversed", p.reversed}});
  summary["rounds"] = sweepRounds(cover);
  if (cover.steepFraction > 0.05) result.warnings.push_back(steepWarning("the region", cover.steepFraction) + " (a smaller radius)");
  if (lastSweepWarp(cover) > 1.0)
    result.warnings.push_back(warpWarning("the region", lastSweepWarp(cover)) + " (a smaller region, more strips or more rounds)");
  summary["warnings"] = result.warnings;
  std::vector<Eigen::RowVector3d> covered;
  appendCoveredPoints(cover, points, {}, covered);
  result.covered = stackRows(covered);
  return result;
}

}  // namespace

nlohmann::json referencePreview(const reference::ReferenceShape& shape, int maxPoints) {
  const Eigen::Index n = shape.points.rows();
  std::vector<Eigen::Index> rows(static_cast<std::size_t>(n));
  std::iota(rows.begin(), rows.end(), Eigen::Index{0});
  if (n > maxPoints) {
    std::mt19937 rng(1);
    std::shuffle(rows.begin(), rows.end(), rng);
    rows.resize(static_cast<std::size_t>(maxPoints));
    std::sort(rows.begin(), rows.end());
  }
  std::vector<double> flat;
  flat.reserve(3 * rows.size());
  for (const Eigen::Index j : rows)
    for (int c = 0; c < 3; ++c) flat.push_back(shape.points(j, c));
  const Eigen::RowVector3d lo = shape.points.colwise().minCoeff(), hi = shape.points.colwise().maxCoeff();
  return {{"points", shape.points.rows()},
          {"triangles", shape.triangles.rows()},
          {"shown", rows.size()},
          {"positions", flat},
          {"bounding_box", {{lo(0), lo(1), lo(2)}, {hi(0), hi(1), hi(2)}}},
          {"diagonal", shape.diagonal()}};
}

}  // namespace devsurf::server
