// `devsurf approximate`: a segmented reference mesh → glued developable patches (issue 15,
// 004_… §5, Fig. 20–21).
#include <cmath>
#include <cstdint>
#include <fstream>
#include <ostream>
#include <map>
#include <set>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "CliArguments.h"
#include "devsurf/models/quad_mesh/SegmentedApproximation.h"
#include "devsurf/proto/Scene.h"
#include "devsurf/reference/ReferenceShape.h"
#include "devsurf/reference/SurfaceSegmentation.h"
#include "devsurf/server/Cli.h"
#include "devsurf/server/ShapeApproximation.h"

namespace devsurf::server {
namespace {

constexpr const char* kApproximateUsage =
    "usage: devsurf approximate MESH [--patches IDS.txt | --segments K [--seed N]]\n"
    "                   [--faces N | --spacing H] [--iterations N]\n"
    "                   [--isometry W] [--proximity W] [--fairness W] [--name NAME]\n"
    "                   [--units mm|cm|m|in] [--out SCENE.json]\n";

/// Patch ids, one integer per triangle of the mesh as read (polygons split as fans), separated by
/// white space; '#' starts a comment.
std::vector<int> readPatchIds(const std::string& path, Eigen::Index triangles) {
  std::ifstream file(path);
  if (!file) throw std::invalid_argument("--patches: cannot read " + path);
  std::vector<int> ids;
  std::string line;
  long lineNumber = 0;
  while (std::getline(file, line)) {
    ++lineNumber;
    line = line.substr(0, line.find('#'));
    std::istringstream words(line);
    std::string word;
    while (words >> word) {
      std::size_t used = 0;
      long value = -1;
      try {
        value = std::stol(word, &used);
      } catch (const std::exception&) {
        used = 0;
      }
      if (used != word.size() || value < 0 || value > 1'000'000)
        throw std::invalid_argument("--patches: " + path + " line " + std::to_string(lineNumber) +
                                    ": expected a patch id 0 … 1000000, got \"" + word + "\"");
      ids.push_back(static_cast<int>(value));
      if (static_cast<Eigen::Index>(ids.size()) > triangles) break;
    }
  }
  if (static_cast<Eigen::Index>(ids.size()) != triangles)
    throw std::invalid_argument("--patches: " + path + " holds " +
                                (static_cast<Eigen::Index>(ids.size()) > triangles ? std::string("more than ")
                                                                                   : std::string()) +
                                std::to_string(ids.size()) + " ids; the mesh has " + std::to_string(triangles) +
                                " triangles (one id per triangle)");
  return ids;
}

}  // namespace

int approximateCommand(const std::vector<std::string>& args, std::ostream& out, std::ostream& err) {
  std::string meshPath, patchPath, outPath;
  // Every option but --patches and --out is a parameter of POST /api/approximations: one parser,
  // one set of ranges and messages (approximationRequestFromQuery).
  const std::set<std::string> requestOptions = {"segments", "seed", "faces", "spacing", "iterations",
                                                "isometry", "proximity", "fairness", "name", "units"};
  std::multimap<std::string, std::string> params;
  ApproximationRequest request;
  try {
    for (std::size_t i = 0; i < args.size(); ++i) {
      const std::string& a = args[i];
      auto value = [&args, &i]() -> const std::string& { return cli::flagValue(args, i); };
      if (a == "--patches") patchPath = value();
      else if (a == "--out") outPath = value();
      else if (a.rfind("--", 0) == 0 && requestOptions.count(a.substr(2))) params.emplace(a.substr(2), value());
      else if (!a.empty() && a[0] == '-') throw std::invalid_argument("unknown option " + a);
      else if (meshPath.empty()) meshPath = a;
      else throw std::invalid_argument("unexpected argument " + a);
    }
    if (meshPath.empty()) throw std::invalid_argument("missing MESH (a triangle mesh: .obj, .off, .ply, .stl)");
    if (!patchPath.empty() && params.count("segments")) throw std::invalid_argument("--patches and --segments exclude each other");
    try {
      request = approximationRequestFromQuery(params);
    } catch (const ApproximationInputError& e) {
      throw std::invalid_argument(std::string("--") + e.what());
    }
  } catch (const std::invalid_argument& e) {
    err << "devsurf approximate: " << e.what() << "\n" << kApproximateUsage;
    return 2;
  }
  try {
    const reference::ReferenceShape shape = reference::readReferenceShape(meshPath);
    if (!patchPath.empty()) request.patchIds = readPatchIds(patchPath, shape.triangles.rows());
    const ApproximationResult result = approximateShape(shape, meshPath, request);
    const nlohmann::json document = proto::sceneToJson(result.scene);
    proto::sceneFromJson(document);  // read back through the checks of devsurf solve
    if (outPath.empty()) {
      out << document.dump(1) << "\n";
    } else {
      std::ofstream file(outPath);
      if (!(file << document.dump(1) << "\n")) throw std::runtime_error("cannot write " + outPath);
    }
    err << "devsurf approximate: " << result.summaryText() << "\n";
    return 0;
  } catch (const std::invalid_argument& e) {
    err << "devsurf approximate: " << e.what() << "\n";
    return 2;
  } catch (const std::exception& e) {
    err << "devsurf approximate: " << e.what() << "\n";
    return 1;
  }
}

}  // namespace devsurf::server
