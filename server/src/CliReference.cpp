// `devsurf reference`: what a user's shape holds, thinned when asked (issue 15).
#include <algorithm>
#include <cstdint>
#include <fstream>
#include <iomanip>
#include <limits>
#include <optional>
#include <sstream>
#include <variant>
#include <cmath>
#include <ostream>
#include <stdexcept>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "CliArguments.h"
#include "devsurf/models/composite/CompositeFromStrips.h"
#include "devsurf/models/strip/StripCover.h"
#include "devsurf/models/strip/StripFromRegion.h"
#include "devsurf/proto/Scene.h"
#include "devsurf/reference/PointThinning.h"
#include "devsurf/reference/ReferenceShape.h"
#include "devsurf/server/Cli.h"

namespace devsurf::server {

int referenceCommand(const std::vector<std::string>& args, std::ostream& out, std::ostream& err) {
  std::string shapePath, outPath;
  reference::ThinningOptions thinning;
  try {
    for (std::size_t i = 0; i < args.size(); ++i) {
      const std::string& a = args[i];
      auto value = [&args, &i]() -> const std::string& { return cli::flagValue(args, i); };
      if (a == "--thin") thinning.radius = cli::parseLength(a, value());
      else if (a == "--seed") thinning.seed = static_cast<std::uint32_t>(cli::parseNumber(a, value(), 0, 4294967295L));
      else if (a == "--out") outPath = value();
      else if (!a.empty() && a[0] == '-') throw std::invalid_argument("unknown option " + a);
      else if (shapePath.empty()) shapePath = a;
      else throw std::invalid_argument("unexpected argument " + a);
    }
    if (shapePath.empty()) throw std::invalid_argument("missing SHAPE (a point cloud or mesh file)");
    if (!outPath.empty() && thinning.radius <= 0.0) throw std::invalid_argument("--out: writes the thinned cloud; give --thin");
  } catch (const std::invalid_argument& e) {
    err << "devsurf reference: " << e.what() << "\nusage: devsurf reference SHAPE [--thin RADIUS] [--seed N] [--out CLOUD.xyz]\n";
    return 2;
  }
  try {
    const reference::ReferenceShape shape = reference::readReferenceShape(shapePath);
    const Eigen::RowVector3d lo = shape.points.colwise().minCoeff(), hi = shape.points.colwise().maxCoeff();
    nlohmann::json report = {{"file", shapePath},
                             {"format", shape.format},
                             {"points", shape.points.rows()},
                             {"triangles", shape.triangles.rows()},
                             {"faces_skipped", shape.facesSkipped},
                             {"normals", shape.normals.rows() > 0},
                             {"bounding_box", {{lo(0), lo(1), lo(2)}, {hi(0), hi(1), hi(2)}}},
                             {"diagonal", shape.diagonal()}};
    if (thinning.radius > 0.0) {
      const reference::ThinnedCloud thin = reference::thinPointCloud(shape.points, shape.normals, thinning);
      long fitted = 0;
      for (const char f : thin.fitted) fitted += f;
      std::vector<double> flatness(thin.flatness.data(), thin.flatness.data() + thin.flatness.size());
      double median = 0.0;
      if (!flatness.empty()) {
        std::nth_element(flatness.begin(), flatness.begin() + static_cast<long>(flatness.size() / 2), flatness.end());
        median = flatness[flatness.size() / 2];
      }
      report["thinned"] = {{"radius", thinning.radius},
                           {"seed", thinning.seed},
                           {"points", thin.points.rows()},
                           {"normals_fitted", fitted},
                           {"flatness_median", median}};
      if (!outPath.empty()) {
        std::ofstream file(outPath);
        file << std::setprecision(std::numeric_limits<double>::max_digits10);
        for (Eigen::Index k = 0; k < thin.points.rows(); ++k)
          file << thin.points(k, 0) << ' ' << thin.points(k, 1) << ' ' << thin.points(k, 2) << ' ' << thin.normals(k, 0)
               << ' ' << thin.normals(k, 1) << ' ' << thin.normals(k, 2) << '\n';
        if (!file) {
          err << "devsurf reference: cannot write " << outPath << "\n";
          return 1;
        }
        report["thinned"]["written"] = outPath;
      }
    }
    out << report.dump(2) << "\n";
    return 0;
  } catch (const std::invalid_argument& e) {
    err << "devsurf reference: " << e.what() << "\n";
    return 2;
  } catch (const std::exception& e) {
    err << "devsurf reference: " << e.what() << "\n";
    return 1;
  }
}

namespace {

/// "x,y,z" → a finite point. @throws std::invalid_argument naming the flag
Eigen::Vector3d parsePoint(const std::string& flag, const std::string& value) {
  Eigen::Vector3d p;
  std::size_t start = 0;
  for (int c = 0; c < 3; ++c) {
    const std::size_t comma = value.find(',', start);
    if ((c < 2) != (comma != std::string::npos))
      throw std::invalid_argument(flag + ": expected x,y,z, got \"" + value + "\"");
    const std::string part = value.substr(start, c < 2 ? comma - start : std::string::npos);
    std::size_t used = 0;
    try {
      p[c] = std::stod(part, &used);
    } catch (const std::exception&) {
      used = 0;
    }
    if (part.empty() || used != part.size() || !std::isfinite(p[c]))
      throw std::invalid_argument(flag + ": expected x,y,z with finite numbers, got \"" + value + "\"");
    start = comma + 1;
  }
  return p;
}

/// Writes a scene made by a command as JSON to `outPath` (stdout when empty), after reading it
/// back through the same checks as `devsurf solve`. False (with the message on err) if the file
/// cannot be written.
bool writeScene(const proto::Scene& scene, const std::string& outPath, const std::string& command, std::ostream& out,
                std::ostream& err) {
  const nlohmann::json document = proto::sceneToJson(scene);
  proto::sceneFromJson(document);
  if (outPath.empty()) {
    out << document.dump(2) << "\n";
    return true;
  }
  std::ofstream file(outPath);
  file << document.dump(2) << "\n";
  if (!file) {
    err << "devsurf " << command << ": cannot write " << outPath << "\n";
    return false;
  }
  return true;
}

constexpr const char* kFitUsage =
    "usage: devsurf fit SHAPE [--centre X,Y,Z --radius R] [--thin RADIUS] [--seed N]\n"
    "                   [--control-points N] [--rulings auto|across|along] [--flat]\n"
    "                   [--iterations N] [--name NAME] [--units mm|cm|m|in] [--out SCENE.json]\n";

}  // namespace

int fitCommand(const std::vector<std::string>& args, std::ostream& out, std::ostream& err) {
  std::string shapePath, outPath, name, units = "mm";
  std::optional<Eigen::Vector3d> centre;
  double radius = 0.0, thinRadius = 0.0;
  std::uint32_t seed = 1;
  int iterations = 60;
  models::strip::RegionStripOptions placement;
  try {
    for (std::size_t i = 0; i < args.size(); ++i) {
      const std::string& a = args[i];
      auto value = [&args, &i]() -> const std::string& { return cli::flagValue(args, i); };
      if (a == "--centre" || a == "--center") centre = parsePoint(a, value());
      else if (a == "--radius") radius = cli::parseLength(a, value());
      else if (a == "--thin") thinRadius = cli::parseLength(a, value());
      else if (a == "--seed") seed = static_cast<std::uint32_t>(cli::parseNumber(a, value(), 0, 4294967295L));
      else if (a == "--control-points") placement.controlPoints = static_cast<int>(cli::parseNumber(a, value(), 4, 200));
      else if (a == "--iterations") iterations = static_cast<int>(cli::parseNumber(a, value(), 0, 10000));
      else if (a == "--flat") placement.liftToHeightField = false;
      else if (a == "--rulings") {
        const std::string& r = value();
        if (r == "auto") placement.rulings = models::strip::RegionStripOptions::Rulings::Auto;
        else if (r == "across") placement.rulings = models::strip::RegionStripOptions::Rulings::AcrossLongest;
        else if (r == "along") placement.rulings = models::strip::RegionStripOptions::Rulings::AlongLongest;
        else throw std::invalid_argument("--rulings: expected auto, across or along, got \"" + r + "\"");
      } else if (a == "--name") name = value();
      else if (a == "--units") units = value();
      else if (a == "--out") outPath = value();
      else if (!a.empty() && a[0] == '-') throw std::invalid_argument("unknown option " + a);
      else if (shapePath.empty()) shapePath = a;
      else throw std::invalid_argument("unexpected argument " + a);
    }
    if (shapePath.empty()) throw std::invalid_argument("missing SHAPE (a point cloud or mesh file)");
    if (centre.has_value() != (radius > 0.0)) throw std::invalid_argument("--centre and --radius go together");
    proto::millimetresPerUnit(units);
  } catch (const std::invalid_argument& e) {
    err << "devsurf fit: " << e.what() << "\n" << kFitUsage;
    return 2;
  }
  try {
    const reference::ReferenceShape shape = reference::readReferenceShape(shapePath);
    // The region: a ball (a brush stroke), or the whole shape.
    std::vector<int> region;
    if (centre) region = models::strip::pointsInBall(shape.points, *centre, radius);
    else for (Eigen::Index j = 0; j < shape.points.rows(); ++j) region.push_back(static_cast<int>(j));
    if (region.size() < 6)
      throw std::invalid_argument("--radius: the region holds " + std::to_string(region.size()) +
                                  " points of " + shapePath + "; a strip needs at least 6");
    Eigen::MatrixX3d points(static_cast<Eigen::Index>(region.size()), 3), normals(0, 3);
    if (shape.normals.rows() > 0) normals.resize(points.rows(), 3);
    for (std::size_t k = 0; k < region.size(); ++k) {
      points.row(static_cast<Eigen::Index>(k)) = shape.points.row(region[k]);
      if (shape.normals.rows() > 0) normals.row(static_cast<Eigen::Index>(k)) = shape.normals.row(region[k]);
    }
    const double diagonal = (points.colwise().maxCoeff() - points.colwise().minCoeff()).norm();
    if (!(diagonal > 0.0)) throw std::invalid_argument("--radius: the region's points all coincide");
    // 000_… §4.2: thin like Poisson sampling; the ball's plane gives each kept point its normal.
    reference::ThinningOptions thinning;
    thinning.radius = thinRadius > 0.0 ? thinRadius : 0.03 * diagonal;
    thinning.seed = seed;
    const reference::ThinnedCloud thin = reference::thinPointCloud(points, normals, thinning);
    models::strip::ApproximationTarget target = models::strip::approximationTargetFrom(thin.points, thin.normals);
    const std::size_t kept = static_cast<std::size_t>(target.points.rows());
    if (kept < 6)
      throw std::invalid_argument("--thin: " + std::to_string(kept) +
                                  " thinned points have a fitted normal; a smaller radius keeps more");
    // Fig. 10a: a strip placed by PCA over the region, then eq. (9)–(11) with a normal spline.
    models::strip::StripDesign design = models::strip::flatStripOverRegion(target.points, placement);
    design.normals.type = models::strip::NormalRepresentation::Type::Spline;
    design.normals.points = placement.controlPoints;
    design.approximation = std::move(target);
    proto::Scene scene;
    scene.name = name.empty() ? "strip fitted to " + shapePath : name;
    scene.description = "A developable strip approximating " + std::to_string(kept) +
                        " thinned points of " + shapePath + " (devsurf fit; Tang et al. 2016 §4.2).";
    scene.units = units;
    scene.model = std::move(design);
    // Fig. 17, row 10 (approximating the bunny): ε₁ = 0.001 and fairness 0.001.
    scene.solver.iterations = iterations;
    scene.solver.regularization = 1e-3;
    scene.solver.fairness = 1e-3;
    if (!writeScene(scene, outPath, "fit", out, err)) return 1;
    if (!outPath.empty())
      err << "devsurf fit: " << outPath << ": a strip over " << kept << " of " << region.size()
          << " region points (thinned at " << thinning.radius << ")\n";
    return 0;
  } catch (const std::invalid_argument& e) {
    err << "devsurf fit: " << e.what() << "\n";
    return 2;
  } catch (const std::exception& e) {
    err << "devsurf fit: " << e.what() << "\n";
    return 1;
  }
}

int mergeCommand(const std::vector<std::string>& args, std::ostream& out, std::ostream& err) {
  std::vector<std::string> paths;
  std::string outPath, name;
  try {
    for (std::size_t i = 0; i < args.size(); ++i) {
      const std::string& a = args[i];
      if (a == "--out") outPath = cli::flagValue(args, i);
      else if (a == "--name") name = cli::flagValue(args, i);
      else if (!a.empty() && a[0] == '-') throw std::invalid_argument("unknown option " + a);
      else paths.push_back(a);
    }
    if (paths.size() != 2) throw std::invalid_argument("expected two strip scenes, got " + std::to_string(paths.size()));
  } catch (const std::invalid_argument& e) {
    err << "devsurf merge: " << e.what() << "\nusage: devsurf merge FIRST.json SECOND.json [--name NAME] [--out SCENE.json]\n";
    return 2;
  }
  std::vector<proto::Scene> scenes;
  for (const std::string& path : paths) {
    std::ifstream file(path, std::ios::binary);
    if (!file) {
      err << "devsurf merge: cannot open " << path << "\n";
      return 2;
    }
    std::ostringstream text;
    text << file.rdbuf();
    try {
      scenes.push_back(proto::sceneFromText(text.str()));
    } catch (const std::exception& e) {
      err << "devsurf merge: " << path << ": " << e.what() << "\n";
      return 2;
    }
    if (!std::holds_alternative<models::strip::StripDesign>(scenes.back().model)) {
      err << "devsurf merge: " << path << ": model.kind: expected \"strip\", got \""
          << proto::modelKind(scenes.back().model) << "\"\n";
      return 2;
    }
  }
  try {
    // Fig. 10c: the control-point sequences joined, end points averaged; solved again by `solve`.
    const models::strip::StripMerge merge = models::strip::mergeStrips(
        std::get<models::strip::StripDesign>(scenes[0].model), std::get<models::strip::StripDesign>(scenes[1].model));
    proto::Scene scene = scenes[0];
    scene.name = name.empty() ? scenes[0].name + " + " + scenes[1].name : name;
    scene.description = "Strips of " + paths[0] + " and " + paths[1] + " merged (devsurf merge; Tang et al. 2016 Fig. 10c).";
    scene.model = merge.merged;
    if (!writeScene(scene, outPath, "merge", out, err)) return 1;
    err << "devsurf merge: joined with a gap of " << merge.gap << (merge.reversedFirst ? "; first reversed" : "")
        << (merge.reversedSecond ? "; second reversed" : "") << (merge.swappedSecond ? "; second's a and b exchanged" : "")
        << "\n";
    return 0;
  } catch (const std::invalid_argument& e) {
    err << "devsurf merge: " << e.what() << "\n";
    return 2;
  } catch (const std::exception& e) {
    err << "devsurf merge: " << e.what() << "\n";
    return 1;
  }
}

namespace {

constexpr const char* kCoverUsage =
    "usage: devsurf cover SHAPE [--centre X,Y,Z --radius R] [--strips K] [--thin RADIUS] [--seed N]\n"
    "                     [--control-points N] [--rounds N] [--crease none|fold] [--name NAME]\n"
    "                     [--units mm|cm|m|in] [--region-out POINTS.xyz] [--out SCENE.json]\n";

/// The region's points (a ball, or all of the shape) and their normals when the file has them.
std::pair<Eigen::MatrixX3d, Eigen::MatrixX3d> regionOf(const reference::ReferenceShape& shape,
                                                       const std::optional<Eigen::Vector3d>& centre, double radius) {
  std::vector<int> region;
  if (centre) region = models::strip::pointsInBall(shape.points, *centre, radius);
  else for (Eigen::Index j = 0; j < shape.points.rows(); ++j) region.push_back(static_cast<int>(j));
  Eigen::MatrixX3d points(static_cast<Eigen::Index>(region.size()), 3), normals(0, 3);
  if (shape.normals.rows() > 0) normals.resize(points.rows(), 3);
  for (std::size_t k = 0; k < region.size(); ++k) {
    points.row(static_cast<Eigen::Index>(k)) = shape.points.row(region[k]);
    if (shape.normals.rows() > 0) normals.row(static_cast<Eigen::Index>(k)) = shape.normals.row(region[k]);
  }
  return {points, normals};
}

}  // namespace

int coverCommand(const std::vector<std::string>& args, std::ostream& out, std::ostream& err) {
  std::string shapePath, outPath, regionPath, name, units = "mm";
  std::optional<Eigen::Vector3d> centre;
  double radius = 0.0;
  models::strip::RegionCoverOptions options;
  models::composite::CreaseKind crease = models::composite::CreaseKind::None;
  try {
    for (std::size_t i = 0; i < args.size(); ++i) {
      const std::string& a = args[i];
      auto value = [&args, &i]() -> const std::string& { return cli::flagValue(args, i); };
      if (a == "--centre" || a == "--center") centre = parsePoint(a, value());
      else if (a == "--radius") radius = cli::parseLength(a, value());
      else if (a == "--strips") options.strips = static_cast<int>(cli::parseNumber(a, value(), 1, 64));
      else if (a == "--thin") options.thinRadius = cli::parseLength(a, value());
      else if (a == "--seed") options.seed = static_cast<std::uint32_t>(cli::parseNumber(a, value(), 0, 4294967295L));
      else if (a == "--control-points") options.placement.controlPoints = static_cast<int>(cli::parseNumber(a, value(), 4, 200));
      else if (a == "--region-out") regionPath = value();
      else if (a == "--rounds") options.pairing.rounds = static_cast<int>(cli::parseNumber(a, value(), 0, 100));
      else if (a == "--crease") {
        const std::string& c = value();
        if (c == "none") crease = models::composite::CreaseKind::None;
        else if (c == "fold") crease = models::composite::CreaseKind::Fold;
        else throw std::invalid_argument("--crease: expected none or fold, got \"" + c + "\"");
      } else if (a == "--name") name = value();
      else if (a == "--units") units = value();
      else if (a == "--out") outPath = value();
      else if (!a.empty() && a[0] == '-') throw std::invalid_argument("unknown option " + a);
      else if (shapePath.empty()) shapePath = a;
      else throw std::invalid_argument("unexpected argument " + a);
    }
    if (shapePath.empty()) throw std::invalid_argument("missing SHAPE (a point cloud or mesh file)");
    if (centre.has_value() != (radius > 0.0)) throw std::invalid_argument("--centre and --radius go together");
    proto::millimetresPerUnit(units);
  } catch (const std::invalid_argument& e) {
    err << "devsurf cover: " << e.what() << "\n" << kCoverUsage;
    return 2;
  }
  try {
    const reference::ReferenceShape shape = reference::readReferenceShape(shapePath);
    const auto [points, normals] = regionOf(shape, centre, radius);
    if (points.rows() < 6 * options.strips)
      throw std::invalid_argument("--radius: the region holds " + std::to_string(points.rows()) + " points of " +
                                  shapePath + "; " + std::to_string(options.strips) + " strips need at least " +
                                  std::to_string(6 * options.strips));
    const models::strip::RegionCover cover = models::strip::coverRegion(points, normals, options);
    // Fig. 10d → e: the paired strips initialize a composite (one face per strip).
    proto::Scene scene;
    scene.name = name.empty() ? std::to_string(options.strips) + " strips covering " + shapePath : name;
    scene.description = "A composite of " + std::to_string(options.strips) + " developable strips covering " +
                        (centre ? "a region of " : "") + shapePath +
                        ", fitted side by side with paired boundaries (devsurf cover; Tang et al. 2016 Fig. 10).";
    scene.units = units;
    scene.model = models::composite::compositeFromStrips(cover.paired.strips, cover.pairings, crease);
    // No fairness: it pulls the composite off the shape (a sphere cap: RMS 0.25 % → 1 % of the
    // diagonal in 10 iterations at ε_fair = ε_reg = 1e-3); ε_reg = 1e-2 keeps it in place.
    scene.solver.iterations = 20;
    scene.solver.regularization = 1e-2;
    scene.solver.fairness = 0.0;
    nlohmann::json report = {{"region_points", points.rows()}, {"strips", options.strips}, {"steep_fraction", cover.steepFraction}};
    for (const auto& p : cover.pairings)
      report["pairings"].push_back({{"first", p.first},
                                    {"first_curve", models::strip::curveName(p.firstCurve)},
                                    {"second", p.second},
                                    {"second_curve", models::strip::curveName(p.secondCurve)},
                                    {"reversed", p.reversed},
                                    {"distance", p.distance}});
    for (const auto& r : cover.paired.rounds)
      report["rounds"].push_back({{"gap_max", r.gapMax}, {"gap_mean", r.gapMean}, {"warp_angle_max_deg", r.warpMaxDeg}});
    if (!regionPath.empty()) {
      // The covered points (the bands), for `solve --reference` to measure the composite against.
      std::ofstream file(regionPath);
      file << std::setprecision(std::numeric_limits<double>::max_digits10);
      for (const std::vector<int>& band : cover.layout.bands)
        for (const int j : band) file << points(j, 0) << ' ' << points(j, 1) << ' ' << points(j, 2) << '\n';
      if (!file) {
        err << "devsurf cover: cannot write " << regionPath << "\n";
        return 1;
      }
    }
    if (!writeScene(scene, outPath, "cover", out, err)) return 1;
    if (!outPath.empty()) out << report.dump(2) << "\n";
    if (cover.steepFraction > 0.05)
      err << "devsurf cover: warning: " << std::lround(100 * cover.steepFraction)
          << " % of the region's normals are more than 75° from its mean plane's: the region wraps around the shape "
             "and bands across a plane do not describe it (a smaller --radius)\n";
    const double warp = cover.paired.rounds.empty() ? 0.0 : cover.paired.rounds.back().warpMaxDeg;
    if (warp > 1.0)
      err << "devsurf cover: warning: after the last sweep a strip is " << warp
          << "° from developable; the composite may not solve (a smaller region, more strips or more --rounds)\n";
    return 0;
  } catch (const std::invalid_argument& e) {
    err << "devsurf cover: " << e.what() << "\n";
    return 2;
  } catch (const std::exception& e) {
    err << "devsurf cover: " << e.what() << "\n";
    return 1;
  }
}

}  // namespace devsurf::server
