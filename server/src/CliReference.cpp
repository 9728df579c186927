// `devsurf reference`: what a user's shape holds, thinned when asked (issue 15).
#include <algorithm>
#include <map>
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
#include "devsurf/server/SceneSolver.h"
#include "devsurf/server/ShapeFitting.h"

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
    "                   [--iterations N] [--overhang W] [--name NAME] [--units mm|cm|m|in]\n"
    "                   [--out SCENE.json]\n";

}  // namespace

namespace {

/// Options of `fit` and `cover` that are parameters of POST /api/fits and /api/covers (one
/// parser, one set of ranges and messages: regionFitRequestFromQuery), by flag.
const std::map<std::string, std::string>& regionFlags() {
  static const std::map<std::string, std::string> flags = {
      {"--centre", "centre"},   {"--center", "centre"},   {"--radius", "radius"}, {"--thin", "thin"},
      {"--seed", "seed"},       {"--control-points", "control_points"},           {"--iterations", "iterations"},
      {"--rulings", "rulings"}, {"--strips", "strips"},   {"--rounds", "rounds"}, {"--crease", "crease"},
      {"--regions", "regions"}, {"--overhang", "overhang"}, {"--name", "name"},       {"--units", "units"}};
  return flags;
}

/// The flag a request parameter came from ("control_points" → "--control-points").
std::string flagOf(const std::string& field) {
  std::string flag = "--" + field;
  std::replace(flag.begin(), flag.end(), '_', '-');
  return flag;
}

/// A service's error as the CLI says it: the parameter named by its flag.
std::string flagMessage(const ApproximationInputError& e) {
  const std::string message = e.what(), prefix = e.field() + ": ";
  return message.rfind(prefix, 0) == 0 ? flagOf(e.field()) + ": " + message.substr(prefix.size()) : message;
}

/// Parses `fit`/`cover` arguments: SHAPE, --out, --region-out (cover), --flat (fit) and the
/// request's flags. @throws std::invalid_argument with the flag's name
RegionFitRequest parseRegionArguments(const std::vector<std::string>& args, bool cover, std::string& shapePath,
                                      std::string& outPath, std::string& regionPath) {
  std::multimap<std::string, std::string> params;
  for (std::size_t i = 0; i < args.size(); ++i) {
    const std::string& a = args[i];
    const auto flag = regionFlags().find(a);
    if (a == "--out") outPath = cli::flagValue(args, i);
    else if (a == "--region-out" && cover) regionPath = cli::flagValue(args, i);
    else if (a == "--flat" && !cover) params.emplace("flat", "true");
    else if (flag != regionFlags().end()) params.emplace(flag->second, cli::flagValue(args, i));
    else if (!a.empty() && a[0] == '-') throw std::invalid_argument("unknown option " + a);
    else if (shapePath.empty()) shapePath = a;
    else throw std::invalid_argument("unexpected argument " + a);
  }
  if (shapePath.empty()) throw std::invalid_argument("missing SHAPE (a point cloud or mesh file)");
  try {
    return regionFitRequestFromQuery(params, cover);
  } catch (const ApproximationInputError& e) {
    const std::string message = e.what();
    if (message == "centre and radius go together") throw std::invalid_argument("--centre and --radius go together");
    throw std::invalid_argument(flagMessage(e));
  }
}

}  // namespace

int fitCommand(const std::vector<std::string>& args, std::ostream& out, std::ostream& err) {
  std::string shapePath, outPath, unusedRegion;
  RegionFitRequest request;
  try {
    request = parseRegionArguments(args, false, shapePath, outPath, unusedRegion);
  } catch (const std::invalid_argument& e) {
    err << "devsurf fit: " << e.what() << "\n" << kFitUsage;
    return 2;
  }
  try {
    const reference::ReferenceShape shape = reference::readReferenceShape(shapePath);
    const RegionFitResult result = fitStripToShape(shape, shapePath, request);
    if (!writeScene(result.scene, outPath, "fit", out, err)) return 1;
    if (!outPath.empty())
      err << "devsurf fit: " << outPath << ": a strip over " << result.summary["thinned_points"] << " of "
          << result.summary["region_points"] << " region points (thinned at " << result.summary["thin_radius"] << ")\n";
    return 0;
  } catch (const ApproximationInputError& e) {
    err << "devsurf fit: " << flagMessage(e) << "\n";
    return 2;
  } catch (const std::invalid_argument& e) {
    err << "devsurf fit: " << e.what() << "\n";
    return 2;
  } catch (const std::exception& e) {
    err << "devsurf fit: " << e.what() << "\n";
    return 1;
  }
}

namespace {

/// The warp check of a strip scene's quality verdict after a solve with its own settings; what
/// is solved is named in an error (std::invalid_argument: a refusal, exit 2).
QualityCheck solvedWarpCheck(const proto::Scene& scene, const std::string& what) {
  try {
    SceneSolver solver(scene);
    solver.solve();
    for (const QualityCheck& check : solver.quality().checks)
      if (check.metric == "warp_angle_max_deg") return check;
  } catch (const std::exception& e) {
    throw std::invalid_argument(what + " could not be solved to check it: " + e.what());
  }
  throw std::logic_error("a strip's quality verdict has no warp_angle_max_deg check");
}

constexpr const char* kMergeUsage =
    "usage: devsurf merge FIRST.json SECOND.json [--name NAME] [--unchecked] [--out SCENE.json]\n";

}  // namespace

int mergeCommand(const std::vector<std::string>& args, std::ostream& out, std::ostream& err) {
  std::vector<std::string> paths;
  std::string outPath, name;
  bool checked = true;
  try {
    for (std::size_t i = 0; i < args.size(); ++i) {
      const std::string& a = args[i];
      if (a == "--out") outPath = cli::flagValue(args, i);
      else if (a == "--name") name = cli::flagValue(args, i);
      else if (a == "--unchecked") checked = false;
      else if (!a.empty() && a[0] == '-') throw std::invalid_argument("unknown option " + a);
      else paths.push_back(a);
    }
    if (paths.size() != 2) throw std::invalid_argument("expected two strip scenes, got " + std::to_string(paths.size()));
  } catch (const std::invalid_argument& e) {
    err << "devsurf merge: " << e.what() << "\n" << kMergeUsage;
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
    // Strips apart (no control point of one within a strip's width of the other's) are not one
    // strip: the join would bridge the gap with a span no solve makes developable.
    const auto& first = std::get<models::strip::StripDesign>(scenes[0].model);
    const auto& second = std::get<models::strip::StripDesign>(scenes[1].model);
    const auto width = [](const models::strip::StripDesign& d) { return (d.a.points - d.b.points).rowwise().norm().mean(); };
    const double widest = std::max(width(first), width(second));
    double nearest = std::numeric_limits<double>::infinity();
    for (const Eigen::MatrixXd* p : {&first.a.points, &first.b.points})
      for (const Eigen::MatrixXd* q : {&second.a.points, &second.b.points})
        for (Eigen::Index i = 0; i < p->rows(); ++i)
          nearest = std::min(nearest, (q->rowwise() - p->row(i)).rowwise().norm().minCoeff());
    if (nearest > widest) {
      err << "devsurf merge: the strips do not meet: their nearest control points are " << nearest
          << " apart, more than a strip is wide (" << widest
          << "); nothing written (fit one strip over both regions, or cover them with several)\n";
      return 2;
    }
    // Fig. 10c: the control-point sequences joined, end points averaged; solved again by `solve`.
    const models::strip::StripMerge merge = models::strip::mergeStrips(
        std::get<models::strip::StripDesign>(scenes[0].model), std::get<models::strip::StripDesign>(scenes[1].model));
    proto::Scene scene = scenes[0];
    scene.name = name.empty() ? scenes[0].name + " + " + scenes[1].name : name;
    scene.summary.clear();  // the first strip's sentence is not the merged strip's
    scene.description = "Strips of " + paths[0] + " and " + paths[1] + " merged (devsurf merge; Tang et al. 2016 Fig. 10c).";
    scene.model = merge.merged;
    // The layout checks of mergeStrips cannot tell whether the joined strip can be developable (two
    // overlapping kitten fits running crosswise passed them and solved to a warp of 65°): solve it
    // as `solve` would and refuse a strip that misses the warp limit where its parts did better.
    // Each part is solved with its own settings, the merged strip with the first's (its scene's).
    if (checked) {
      const QualityCheck merged = solvedWarpCheck(scene, "the merged strip");
      if (!merged.ok) {  // within the limit: nothing to compare (the parts' solves are skipped)
        const double first = solvedWarpCheck(scenes[0], paths[0]).value;
        const double second = solvedWarpCheck(scenes[1], paths[1]).value;
        const double parts = std::isfinite(first) && std::isfinite(second) ? std::max(first, second)
                                                                           : std::numeric_limits<double>::infinity();
        // A warp that is not a number is no strip at all (NaN compares false: tested first).
        if (!std::isfinite(merged.value) || merged.value > 2.0 * parts) {
          err << "devsurf merge: the strips do not make one developable strip: merged and solved, it warps by "
              << merged.value << "° (a strip's limit " << merged.limit << "°), its parts solved by at most " << parts
              << "°; nothing written (--unchecked writes it anyway)\n";
          return 2;
        }
      }
    }
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
    "usage: devsurf cover SHAPE [--centre X,Y,Z --radius R] [--strips K] [--regions R] [--thin RADIUS]\n"
    "                     [--seed N] [--control-points N] [--rounds N] [--crease none|fold] [--overhang W]\n"
    "                     [--name NAME]"
    "\n"
    "                     [--units mm|cm|m|in] [--region-out POINTS.xyz] [--out SCENE.json]\n";

}  // namespace

int coverCommand(const std::vector<std::string>& args, std::ostream& out, std::ostream& err) {
  std::string shapePath, outPath, regionPath;
  RegionFitRequest request;
  try {
    request = parseRegionArguments(args, true, shapePath, outPath, regionPath);
  } catch (const std::invalid_argument& e) {
    err << "devsurf cover: " << e.what() << "\n" << kCoverUsage;
    return 2;
  }
  try {
    const reference::ReferenceShape shape = reference::readReferenceShape(shapePath);
    const RegionFitResult result = coverShapeWithStrips(shape, shapePath, request);
    if (!regionPath.empty()) {
      // The covered points (the bands), for `solve --reference` to measure the composite against.
      std::ofstream file(regionPath);
      file << std::setprecision(std::numeric_limits<double>::max_digits10);
      for (Eigen::Index j = 0; j < result.covered.rows(); ++j)
        file << result.covered(j, 0) << ' ' << result.covered(j, 1) << ' ' << result.covered(j, 2) << '\n';
      if (!file) {
        err << "devsurf cover: cannot write " << regionPath << "\n";
        return 1;
      }
    }
    if (!writeScene(result.scene, outPath, "cover", out, err)) return 1;
    if (!outPath.empty()) out << result.summary.dump(2) << "\n";
    for (const std::string& warning : result.warnings) err << "devsurf cover: warning: " << warning << "\n";
    return 0;
  } catch (const ApproximationInputError& e) {
    err << "devsurf cover: " << flagMessage(e) << "\n";
    return 2;
  } catch (const std::invalid_argument& e) {
    err << "devsurf cover: " << e.what() << "\n";
    return 2;
  } catch (const std::exception& e) {
    err << "devsurf cover: " << e.what() << "\n";
    return 1;
  }
}

}  // namespace devsurf::server
