// Strips onto a user's shape: the service behind `devsurf fit`, `devsurf cover`, POST /api/fits,
// /api/covers and /api/references (issue 15, 000_… §4.2, Fig. 10).
#include "devsurf/server/ShapeFitting.h"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <random>
#include <sstream>

#include "devsurf/models/composite/CompositeFromStrips.h"
#include "devsurf/models/strip/StripCover.h"
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

void requireRegion(const Eigen::MatrixX3d& points, long needed, const std::string& source, const std::string& what) {
  if (points.rows() < needed)
    throw ApproximationInputError("radius", "radius: the region holds " + std::to_string(points.rows()) +
                                                " points of " + source + "; " + what + " needs at least " +
                                                std::to_string(needed));
  if (!((points.colwise().maxCoeff() - points.colwise().minCoeff()).norm() > 0.0))
    throw ApproximationInputError("radius", "radius: the region's points all coincide");
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
    else if (key == "crease" && cover) {
      if (value == "none") r.crease = models::composite::CreaseKind::None;
      else if (value == "fold") r.crease = models::composite::CreaseKind::Fold;
      else throw ApproximationInputError(key, "crease: expected none or fold, got \"" + value + "\"");
    } else if (key == "name") r.name = nameParameter(key, value);
    else if (key == "units") r.units = unitsParameter(key, value);
    else {
      throw ApproximationInputError(key, key + ": unknown parameter (centre, radius, thin, seed, control_points, " +
                                             (cover ? std::string("strips, rounds, crease") : std::string("iterations, rulings, flat")) +
                                             ", name, units, format)");
    }
  }
  // The sweeps run in the caller's thread (a request's): bounded to about ten seconds.
  if (cover && r.strips * r.rounds > 400)
    throw ApproximationInputError("rounds", "rounds: strips × rounds is at most 400 (" + std::to_string(r.strips) +
                                                " × " + std::to_string(r.rounds) + ")");
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

RegionFitResult coverShapeWithStrips(const reference::ReferenceShape& shape, const std::string& source,
                                     const RegionFitRequest& request) {
  const auto [points, normals] = regionOf(shape, request);
  requireRegion(points, 6L * request.strips, source, std::to_string(request.strips) + " strips");
  models::strip::RegionCoverOptions options;
  options.strips = request.strips;
  options.thinRadius = request.thin;
  options.seed = request.seed;
  options.placement.controlPoints = request.controlPoints;
  options.pairing.rounds = request.rounds;
  models::strip::RegionCover cover;
  try {
    cover = models::strip::coverRegion(points, normals, options);
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
  // No fairness: it pulls the composite off the shape (a sphere cap: RMS 0.25 % → 1 % of the
  // diagonal in 10 iterations at ε_fair = ε_reg = 1e-3); ε_reg = 1e-2 keeps it in place.
  scene.solver.iterations = 20;
  scene.solver.regularization = 1e-2;
  scene.solver.fairness = 0.0;
  nlohmann::json& summary = result.summary;
  summary = {{"region_points", points.rows()}, {"strips", request.strips}, {"steep_fraction", cover.steepFraction}};
  summary["pairings"] = nlohmann::json::array();
  for (const auto& p : cover.pairings)
    summary["pairings"].push_back({{"first", p.first},
                                   {"first_curve", models::strip::curveName(p.firstCurve)},
                                   {"second", p.second},
                                   {"second_curve", models::strip::curveName(p.secondCurve)},
                                   {"reversed", p.reversed}});
  summary["rounds"] = nlohmann::json::array();
  for (const auto& r : cover.paired.rounds)
    summary["rounds"].push_back({{"gap_max", r.gapMax}, {"gap_mean", r.gapMean}, {"warp_angle_max_deg", r.warpMaxDeg}});
  if (cover.steepFraction > 0.05)
    result.warnings.push_back(std::to_string(std::lround(100 * cover.steepFraction)) +
                              " % of the region's normals are more than 75° from its mean plane's: the region wraps "
                              "around the shape and bands across a plane do not describe it (a smaller radius)");
  const double warp = cover.paired.rounds.empty() ? 0.0 : cover.paired.rounds.back().warpMaxDeg;
  if (warp > 1.0) {
    std::ostringstream text;
    text << "after the last sweep a strip is " << warp
         << "° from developable; the composite may not solve (a smaller region, more strips or more rounds)";
    result.warnings.push_back(text.str());
  }
  summary["warnings"] = result.warnings;
  long covered = 0;
  for (const auto& band : cover.layout.bands) covered += static_cast<long>(band.size());
  result.covered.resize(covered, 3);
  long row = 0;
  for (const auto& band : cover.layout.bands)
    for (const int j : band) result.covered.row(row++) = points.row(j);
  return result;
}

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
