// `devsurf reference`: what a user's shape holds, thinned when asked (issue 15).
#include <algorithm>
#include <cstdint>
#include <fstream>
#include <iomanip>
#include <limits>
#include <ostream>
#include <stdexcept>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "CliArguments.h"
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

}  // namespace devsurf::server
