#include "devsurf/server/Cli.h"

#include "CliArguments.h"

#include <algorithm>
#include <cctype>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <sstream>
#include <stdexcept>
#include <variant>

#include "devsurf/io/QuadMesh.h"
#include "devsurf/proto/BoundedJson.h"
#include "devsurf/proto/Scene.h"
#include "devsurf/reference/ReferenceShape.h"
#include "devsurf/server/CreasePatternImport.h"
#include "devsurf/server/Daemon.h"
#include "devsurf/server/ShapeUpload.h"
#include "devsurf/server/StaticAssets.h"
#include "devsurf/server/SceneSolver.h"

#include <csignal>
#include <mutex>
#include <thread>

#include <httplib.h>
#include <pthread.h>
#include <sys/resource.h>
#include <spdlog/sinks/stdout_color_sinks.h>
#include <spdlog/spdlog.h>
#include <unistd.h>

#if defined(__GLIBC__)
#include <malloc.h>
#endif

namespace devsurf::server {
namespace {

using cli::flagValue;
using cli::parseLength;
using cli::parseNumber;

constexpr const char* kUsage =
    "usage: devsurf <command> [options]\n"
    "\n"
    "commands:\n"
    "  solve SCENE [--iterations N] [--out REPORT.json] [--export FORMAT:FILE]...\n"
    "        [--reference SHAPE [--coverage-tolerance T]]\n"
    "        [--memory-budget-mb MB] [--max-control-points N] [--require-quality]\n"
    "        [--fold-amount A]\n"
    "        Solve a scene file (\"-\" reads standard input) and write the report as JSON.\n"
    "        --fold-amount folds a composite with fold angles (an imported crease pattern,\n"
    "        a drawn sheet) to A of its designed angles, 0..1 or 0%..100% (the slider's\n"
    "        amount; an import starts flat, at 0), with at least 200 iterations unless\n"
    "        --iterations says otherwise (a session's release runs as many).\n"
    "        The report's quality says whether the result meets its kind's thresholds\n"
    "        (a warning on standard error if not; exit status 3 with --require-quality).\n"
    "        Scenes are held to the server's default limits (512 MiB estimated memory,\n"
    "        20 000 control points or mesh vertices); --memory-budget-mb and\n"
    "        --max-control-points raise them. Every --export is checked before the solve;\n"
    "        the report is written before the exports.\n"
    "        FORMAT is obj, off, ply or stl (the sampled surface as quads; stl: two\n"
    "        triangles per quad, zero-area ones left out, in mm), iges and step (B-spline\n"
    "        surfaces), svg and dxf (flat patterns at true size in mm: a composite's\n"
    "        crease pattern, or the pieces cut along its seams; a strip's unfolding);\n"
    "        png (a 320 x 240 picture of the surface); fold (FOLD 1.2) for\n"
    "        composites with a development; for quad_mesh scenes\n"
    "        obj (M), unfolding_obj (M′), stl, svg and dxf (cutting pattern) and fold\n"
    "        (both frames).\n"
    "  serve [--port 8080] [--bind 127.0.0.1] [--data DIR] [--store postgresql://...]\n"
    "        [--node-id ID] [--lease-ms MS] [--api-key KEY] [--web DIR]\n"
    "        [--demo SCENE]... [--workers N] [--max-sessions N] [--max-clients N]\n"
    "        [--max-body BYTES] [--max-message BYTES] [--message-rate PER_S]\n"
    "        [--max-control-points N] [--max-iterations N] [--job-workers N]\n"
    "        [--max-jobs N] [--job-timeout-ms MS] [--job-retention-hours H]\n"
    "        [--drag-iterations N] [--release-iterations N]\n"
    "        [--log-level trace|debug|info|warn|error|off]\n"
    "        [--max-connections N] [--max-connections-per-address N] [--max-header-bytes BYTES]\n"
    "        [--max-header-fields N] [--header-timeout-ms MS] [--body-timeout-ms MS]\n"
    "        [--keep-alive-timeout-ms MS] [--keep-alive-requests N] [--write-timeout-ms MS]\n"
    "        [--http-workers N]\n"
    "        [--memory-budget-mb MB] [--session-time-budget-ms MS]\n"
    "        Run the daemon: REST under /api, the web app at /, the WebSocket at /ws.\n"
    "        The web app is the built one (npm --prefix web run build) in --web DIR, by\n"
    "        default web/dist under the current directory, else ../../web/dist from the\n"
    "        executable (a build tree) or ../share/devsurf/web/dist (an installation);\n"
    "        --web \"\" serves none. Its files are read and compressed once, at start-up.\n"
    "        Sessions and jobs are stored in DIR/devsurf.db (SQLite; --data, default ./var),\n"
    "        or with --store postgresql://USER@HOST/DB in PostgreSQL, shared by several\n"
    "        daemons (docs/scaling.md): jobs are claimed from one queue and sessions held\n"
    "        by one daemon at a time, under leases of --lease-ms (default 10000) that a\n"
    "        daemon that dies stops renewing; --node-id names this daemon (default\n"
    "        HOST-PID) in leases, /api/health and /api/metrics. Finished jobs and their\n"
    "        reports are deleted --job-retention-hours after they end (default 168; 0 keeps\n"
    "        them).\n"
    "        serve --help prints this text.\n"
    "  reference SHAPE [--thin RADIUS] [--seed N] [--out CLOUD.xyz]\n"
    "        Read a point cloud (.xyz, .pwn, .ply) or mesh (.obj, .off, .ply, .stl) and print\n"
    "        what it holds as JSON; --thin keeps points at least RADIUS apart, each with a\n"
    "        normal fitted to its ball (written with --out as x y z nx ny nz lines).\n"
    "        With solve, --reference reports the distances from SHAPE's points to the solved\n"
    "        surface (reference_* metrics; coverage within T, default 1% of SHAPE's size).\n"
    "  fit SHAPE [--centre X,Y,Z --radius R] [--thin RADIUS] [--seed N]\n"
    "        [--control-points N] [--rulings auto|across|along] [--flat] [--iterations N]\n"
    "        [--overhang W] [--name NAME] [--units mm|cm|m|in] [--out SCENE.json]\n"
    "        Make a strip scene that approximates SHAPE within the ball (default: all of it):\n"
    "        the region thinned (default radius 3% of its size) with a fitted normal per\n"
    "        point, a strip placed by PCA over it (lifted onto its quadratic height field\n"
    "        unless --flat), eq. (9)-(11) of Tang et al. 2016 as its approximation target,\n"
    "        and with --overhang W > 0 (e.g. 0.001; default 0, the paper's equations alone)\n"
    "        parts of the strip beyond the region pulled back, so it does not spread there.\n"
    "        Solve it with solve; the report's approximation_* metrics measure the fit.\n"
    "  merge FIRST.json SECOND.json [--name NAME] [--unchecked] [--out SCENE.json]\n"
    "        Merge two strip scenes into one strip by joining their control-point sequences\n"
    "        (lined up end to end, the meeting points averaged; approximation targets joined).\n"
    "        Strips that do not continue one another are refused, and so is a merged strip\n"
    "        that, solved, warps beyond a strip's limit and twice its parts' warp\n"
    "        (--unchecked: written without that solve).\n"
    "  cover SHAPE [--centre X,Y,Z --radius R] [--strips K] [--regions R] [--thin RADIUS]\n"
    "        [--seed N] [--control-points N] [--rounds N] [--crease none|fold] [--overhang W]\n"
    "        [--name NAME]\n"
    "        [--units mm|cm|m|in] [--region-out POINTS.xyz] [--out SCENE.json]\n"
    "        Cover a region of SHAPE (a ball, default all of it) by K strips side by side\n"
    "        (default 4) and make them one composite (Tang et al. 2016 Fig. 10): the region\n"
    "        cut into bands across its flattest direction, a strip fitted to each, neighbouring\n"
    "        boundaries paired and pulled together (--rounds sweeps, default 8), then a\n"
    "        composite with one face per strip and a shared edge per pair (a seam, or a curved\n"
    "        fold with --crease fold). --regions R > 1 first cuts the region into R parts by\n"
    "        normal and position and covers each by K strips: a whole closed shape as one\n"
    "        composite of R parts (Fig. 10e). Prints the fit and the gaps as JSON; --region-out\n"
    "        writes the covered points, to measure the solved composite against with\n"
    "        solve --reference POINTS.xyz.\n"
    "  approximate MESH [--patches IDS.txt | --segments K [--seed N]] [--faces N | --spacing H]\n"
    "        [--iterations N] [--isometry W] [--proximity W] [--fairness W] [--name NAME]\n"
    "        [--units mm|cm|m|in] [--out SCENE.json]\n"
    "        Make a quad_mesh scene that approximates a triangle mesh (a disk: one boundary loop)\n"
    "        by developable patches glued along their borders (Jiang et al. 2020, Sec. 5): the\n"
    "        mesh mapped to the plane, a grid of about N quads (default 1500) or spacing H laid\n"
    "        over it, each quad in the patch under its centre. Patches: one id per triangle in\n"
    "        IDS.txt, K clusters of normals and positions (--segments), or one patch. Solve it\n"
    "        with solve: length_error, area_error and approximation_* measure the result.\n"
    "        Weights (Fig. 21's trade-off): isometry and gluing (default 10), proximity to\n"
    "        MESH (0.01), fairness at the first round (0.01); default 40 iterations.\n"
    "  import PATTERN.fold|PATTERN.svg [--name NAME] [--units mm|cm|m|in] [--out SCENE.json]\n"
    "        Make a composite scene from a FOLD crease pattern (or folded form): planar faces\n"
    "        between straight creases that fold freely, the largest face fixed, faces found\n"
    "        from the edges when the file has none. What could not be carried over is noted\n"
    "        on stderr, by element (\"edges_vertices[4]: …\").\n"
    "  import MESH [--unfolding MESH] [--variables mesh|unfolding|both] [--proximity]\n"
    "        [--name NAME] [--units mm|cm|m|in] [--out SCENE.json]\n"
    "        Make a quad_mesh scene from an OBJ, OFF or PLY mesh of triangles and quads (M),\n"
    "        optionally with its unfolding M′ (same vertices and faces; planar when every z is\n"
    "        0). Without one, M′ is computed (both meshes move); --proximity keeps M near the\n"
    "        input (Fig. 8: make a mesh developable close to its original).\n"
    "  worker --store postgresql://... [--node-id ID] [--job-workers N] [--lease-ms MS]\n"
    "        [--job-timeout-ms MS] [--job-retention-hours H] [--max-iterations N] [--max-control-points N]\n"
    "        [--memory-budget-mb MB]\n"
    "        Solve batch jobs from the shared PostgreSQL queue of several daemons, serving no\n"
    "        HTTP (docs/scaling.md); SIGTERM hands its running jobs back to the queue.\n"
    "  job submit SCENE --server URL [--wait [--require-quality]] [--api-key KEY] [--idempotency-key KEY]\n"
    "        [--out FILE]\n"
    "        Submit a batch job (SCENE \"-\" reads standard input) to the daemon at URL, as\n"
    "        `devsurf serve` prints it (http://HOST:PORT/, with a path when a proxy serves it\n"
    "        under one); with --wait, show progress and write the report, warning when it\n"
    "        misses its quality thresholds (exit status 3 with --require-quality).\n"
    "  version   Print the version.\n"
    "  help      Print this text.\n";

constexpr std::size_t kMaxSceneBytes = 64u << 20;  // 64 MiB
constexpr int kFoldIterations = 200;  ///< devsurf solve --fold-amount without --iterations: at least these

/// The part of kUsage about one command (every entry of it: import has two), as
/// "usage: devsurf COMMAND …"; all of kUsage for a command it does not list.
std::string commandUsage(const std::string& command) {
  std::istringstream lines(kUsage);
  std::string line, entries;
  bool inEntry = false;
  while (std::getline(lines, line)) {
    const bool starts = line.rfind("  " + command + " ", 0) == 0 || line == "  " + command;
    if (starts) {
      entries += "usage: devsurf " + line.substr(2) + "\n";
      inEntry = true;
    } else if (inEntry && line.rfind("        ", 0) == 0) {
      entries += line + "\n";
    } else {
      inEntry = false;
    }
  }
  return entries.empty() ? std::string(kUsage) : entries;
}

/// Writes a command's document to --out, or to standard output without one.
void writeOutput(const std::string& text, const std::string& outPath, std::ostream& out) {
  if (outPath.empty()) {
    out << text;
    return;
  }
  std::ofstream file(outPath, std::ios::binary);
  if (!(file << text)) throw std::runtime_error("cannot write " + outPath);
}

std::string readAll(std::istream& in) {
  std::ostringstream buffer;
  buffer << in.rdbuf();
  return buffer.str();
}

/// Warns on `err` when a report misses its quality thresholds, naming each failed check (the
/// report's `quality`); returns whether it missed them. `kind`: the scene's model kind.
bool warnQualityMissed(const nlohmann::json& report, const std::string& command, const std::string& kind, std::ostream& err) {
  const auto quality = report.find("quality");
  if (quality == report.end() || quality->at("met").get<bool>()) return false;
  err << "devsurf " << command << ": warning: the result misses its quality thresholds:";
  for (const nlohmann::json& check : quality->at("checks"))
    if (!check.at("ok").get<bool>())
      err << " " << check.at("metric").get<std::string>() << " " << check.at("value").get<double>()
          << " (limit " << check.at("limit").get<double>() << ");";
  if (kind == "conical_strip")
    err << " the greedy strip folds back on itself: a smaller h3 (shorter fans of triangles) or h4 may"
           " help, Chu et al. §5.4 (the report's quality)\n";
  else
    err << " more --iterations may help; targets the sheet cannot reach stretch it (the report's quality)\n";
  return true;
}

/// A daemon's address as `devsurf serve` prints it: http://HOST[:PORT][/PREFIX][/]. `origin` is
/// what httplib connects to, `prefix` the path before /api (a daemon behind a proxy's path).
struct ServerAddress {
  std::string origin, prefix;
};

/// @throws std::invalid_argument naming --server for another scheme or no host
ServerAddress parseServerAddress(const std::string& url) {
  const std::size_t schemeEnd = url.find("://");
  std::string scheme = schemeEnd == std::string::npos ? std::string("http") : url.substr(0, schemeEnd);
  std::transform(scheme.begin(), scheme.end(), scheme.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  if (scheme != "http")
    throw std::invalid_argument("--server: \"" + scheme + "\" is not a scheme devsurf job speaks (http://HOST:PORT)");
  const std::string rest = schemeEnd == std::string::npos ? url : url.substr(schemeEnd + 3);
  const std::size_t slash = rest.find('/');
  ServerAddress address;
  address.origin = "http://" + rest.substr(0, slash);
  if (slash == 0 || rest.empty()) throw std::invalid_argument("--server: no host in \"" + url + "\" (http://HOST:PORT)");
  if (slash != std::string::npos) address.prefix = rest.substr(slash);
  while (!address.prefix.empty() && address.prefix.back() == '/') address.prefix.pop_back();
  return address;
}

/// Process settings of the daemon. glibc keeps freed memory in its per-thread arenas and raises
/// its mmap threshold after every large free, so a few large request bodies left the daemon at
/// gigabytes of RSS: a fixed 1 MiB threshold makes large buffers (bodies, responses) mmapped and
/// returned on free (the transport also calls malloc_trim after large requests). The soft limit
/// on open files is raised to the hard one so that --max-connections can be reached.
void tuneProcessForServing() {
#if defined(__GLIBC__)
  mallopt(M_MMAP_THRESHOLD, 1 << 20);
#endif
  rlimit files{};
  if (getrlimit(RLIMIT_NOFILE, &files) == 0 && files.rlim_cur < files.rlim_max) {
    files.rlim_cur = files.rlim_max;
    setrlimit(RLIMIT_NOFILE, &files);
  }
}

}  // namespace

int solveCommand(const std::vector<std::string>& args, std::istream& in, std::ostream& out,
                 std::ostream& err) {
  std::string scenePath, outPath, referencePath;
  double coverageTolerance = 0.0;
  int iterations = -1;
  double foldAmount = -1.0;  // < 0: the scene's own
  bool requireQuality = false;
  std::vector<std::string> exports;
  proto::ResourceLimits limits;
  try {
    for (std::size_t i = 0; i < args.size(); ++i) {
      const std::string& a = args[i];
      auto value = [&args, &i]() -> const std::string& { return flagValue(args, i); };
      if (a == "--iterations") iterations = static_cast<int>(parseNumber(a, value(), 0, 10000));
      else if (a == "--memory-budget-mb")
        limits.memoryBudgetBytes = static_cast<double>(parseNumber(a, value(), 16, 1L << 30)) * 1024.0 * 1024.0;
      else if (a == "--max-control-points")
        limits.maxControlPoints = static_cast<int>(parseNumber(a, value(), 4, 10000000));
      else if (a == "--out") outPath = value();
      else if (a == "--export") exports.push_back(value());
      else if (a == "--reference") referencePath = value();
      else if (a == "--coverage-tolerance") coverageTolerance = parseLength(a, value());
      else if (a == "--require-quality") requireQuality = true;
      else if (a == "--fold-amount") foldAmount = cli::parseFraction(a, value());
      else if (!a.empty() && a[0] == '-' && a != "-") throw std::invalid_argument("unknown option " + a);
      else if (scenePath.empty()) scenePath = a;
      else throw std::invalid_argument("unexpected argument " + a);
    }
    if (scenePath.empty()) throw std::invalid_argument("missing SCENE (a scene file, or - for standard input)");
    if (coverageTolerance > 0.0 && referencePath.empty())
      throw std::invalid_argument("--coverage-tolerance: needs --reference");
  } catch (const std::invalid_argument& e) {
    err << "devsurf solve: " << e.what() << "\n" << commandUsage("solve");
    return 2;
  }
  reference::ReferenceShape referenceShape;
  if (!referencePath.empty()) {
    try {
      referenceShape = reference::readReferenceShape(referencePath);
    } catch (const std::invalid_argument& e) {
      err << "devsurf solve: --reference: " << e.what() << "\n";
      return 2;
    } catch (const std::exception& e) {
      err << "devsurf solve: --reference: " << referencePath << ": " << e.what() << "\n";
      return 1;
    }
  }

  std::string text;
  if (scenePath == "-") {
    text = readAll(in);
  } else {
    std::ifstream file(scenePath, std::ios::binary);
    if (!file) {
      err << "devsurf solve: cannot open " << scenePath << "\n";
      return 2;
    }
    text = readAll(file);
  }
  if (text.size() > kMaxSceneBytes) {
    err << "devsurf solve: " << scenePath << ": scene larger than " << (kMaxSceneBytes >> 20) << " MiB\n";
    return 2;
  }

  try {
    const auto start = std::chrono::steady_clock::now();
    proto::Scene scene = proto::sceneFromText(text, limits);
    if (foldAmount >= 0.0) {
      auto* design = std::get_if<models::composite::CompositeDesign>(&scene.model);
      if (!design)
        throw std::invalid_argument("--fold-amount: only a composite (a crease pattern, a drawn sheet) folds by an "
                                    "amount; this scene's model is of another kind");
      if (design->foldAngles.empty())
        throw std::invalid_argument("--fold-amount: the composite has no fold angles (model.fold_angles) to fold to");
      design->foldAmount = foldAmount;
      // A fold from flat takes as many iterations as the slider's release in a session: an import's
      // own 20 left a 53° crease at 21° (a new user's tryout).
      if (iterations < 0) iterations = std::max(scene.solver.iterations, kFoldIterations);
    }
    SceneSolver solver(std::move(scene));
    // Every export checked before the solve (a format that does not apply, a folder that does not
    // exist), and the report's folder: a mistake in the last --export costs no solve.
    if (const std::filesystem::path folder = std::filesystem::path(outPath).parent_path();
        !outPath.empty() && !folder.empty() && !std::filesystem::is_directory(folder))
      throw std::invalid_argument("--out " + outPath + ": the folder " + folder.string() + " does not exist");
    for (const std::string& spec : exports) {
      const std::size_t colon = spec.find(':');
      if (colon == std::string::npos || colon == 0 || colon + 1 == spec.size())
        throw std::invalid_argument("--export: expected FORMAT:FILE, e.g. obj:strip.obj, got \"" + spec + "\"");
      try {
        solver.checkExportFormat(spec.substr(0, colon));
      } catch (const ExportUnavailable& e) {
        throw std::invalid_argument("--export " + std::string(e.what()).substr(8));
      }
      const std::filesystem::path folder = std::filesystem::path(spec.substr(colon + 1)).parent_path();
      if (!folder.empty() && !std::filesystem::is_directory(folder))
        throw std::invalid_argument("--export " + spec + ": the folder " + folder.string() + " does not exist");
    }
    const engine::SolveSummary summary = solver.solve(iterations);
    const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
    nlohmann::json report = solver.report(summary, ms);
    if (const std::string bad = proto::nonFinitePath(report); !bad.empty()) {
      err << "devsurf solve: the solve produced a non-finite value (" << bad << "); no report written\n";
      return 1;
    }
    if (!referencePath.empty()) {
      try {
        for (const auto& [name, value] : solver.referenceMetrics(referenceShape.points, coverageTolerance))
          report["metrics"][name] = value;
      } catch (const std::exception& e) {
        err << "devsurf solve: --reference: no distances measured: " << e.what() << "\n";
        return 1;
      }
    }
    // The report first: an export that fails on the solved state leaves it written.
    if (outPath.empty()) {
      out << report.dump(2) << "\n";
    } else {
      std::ofstream file(outPath);
      if (!(file << report.dump(2) << "\n")) {
        err << "devsurf solve: cannot write " << outPath << "\n";
        return 1;
      }
    }
    for (const std::string& spec : exports) {
      try {
        solver.exportTo(spec);
      } catch (const std::invalid_argument& e) {
        err << "devsurf solve: " << e.what() << (outPath.empty() ? "" : " (the report is written)") << "\n";
        return 2;
      } catch (const std::bad_alloc&) {
        throw;
      } catch (const std::exception& e) {
        err << "devsurf solve: " << e.what() << (outPath.empty() ? "" : " (the report is written)") << "\n";
        return 1;
      }
    }
    if (summary.reason == engine::TerminationReason::Diverged) {
      err << "devsurf solve: the solver diverged after " << summary.stepsTaken()
          << " iterations; the report holds the last good state"
          << (summary.stepsTaken() == 0 ? " (at its first step: the scene's geometry is likely degenerate — control "
                                          "points on top of each other, an edge or a face of no length or area)"
                                        : "")
          << "\n";
      return 1;
    }
    if (requireQuality && !report.contains("quality"))
      err << "devsurf solve: note: --require-quality: a " << solver.kindName()
          << " report has no quality thresholds to require (see its metrics)\n";
    if (warnQualityMissed(report, "solve", solver.kindName(), err) && requireQuality) return 3;
    return 0;
  } catch (const proto::SceneError& e) {
    err << "devsurf solve: " << (scenePath == "-" ? "<stdin>" : scenePath) << ": " << e.what() << "\n";
    return 2;
  } catch (const std::invalid_argument& e) {
    err << "devsurf solve: " << e.what() << "\n";
    return 2;
  } catch (const std::exception& e) {
    err << "devsurf solve: " << e.what() << "\n";
    return 1;
  }
}

/// Writes an imported scene to --out or stdout: 0, or 2 when --out cannot be written (as `solve`
/// refuses an --out or --export it cannot open: a bad argument).
int writeImportedScene(const std::string& scene, const std::string& outPath, std::ostream& out, std::ostream& err) {
  try {
    writeOutput(scene, outPath, out);
    return 0;
  } catch (const std::exception& e) {
    err << "devsurf import: --out: " << e.what() << "\n";
    return 2;
  }
}

/// `devsurf import PATTERN.fold|.svg`: a composite scene from a crease pattern; notes on stderr.
/// Exit status 2 for what the file holds, a file that cannot be read or written (as `solve`), 1
/// for a failure of the machine.
int importCreasePatternFile(const std::string& path, const std::string& name, const std::string& units,
                            const std::string& outPath, std::ostream& out, std::ostream& err) {
  std::string scene;
  try {
    std::ifstream in(path, std::ios::binary);
    if (!in) throw ApproximationInputError("FILE", "cannot read " + path);
    CreasePatternImportRequest request;
    request.format = std::filesystem::path(path).extension() == ".svg" || std::filesystem::path(path).extension() == ".SVG" ? "svg" : "fold";
    request.name = name;
    request.units = units;
    const CreasePatternImportResult result = importCreasePattern(readAll(in), request);
    for (const io::ImportNote& note : result.notes) err << "devsurf import: note: " << note.element << ": " << note.message << "\n";
    scene = proto::sceneToJson(result.scene).dump(1) + "\n";
  } catch (const ApproximationInputError& e) {
    err << "devsurf import: " << (e.field() == "FILE" ? std::string() : path + ": ") << e.what() << "\n";
    return 2;
  } catch (const std::exception& e) {
    err << "devsurf import: " << e.what() << "\n";
    return 1;
  }
  return writeImportedScene(scene, outPath, out, err);
}

int importCommand(const std::vector<std::string>& args, std::ostream& out, std::ostream& err) {
  std::string meshPath, unfoldingPath, outPath, variables, name, units = "mm";
  bool proximity = false, unitsGiven = false;
  try {
    for (std::size_t i = 0; i < args.size(); ++i) {
      const std::string& a = args[i];
      auto value = [&args, &i]() -> const std::string& { return flagValue(args, i); };
      if (a == "--unfolding") unfoldingPath = value();
      else if (a == "--variables") variables = value();
      else if (a == "--proximity") proximity = true;
      else if (a == "--name") name = value();
      else if (a == "--units") {
        units = value();
        unitsGiven = true;
      }
      else if (a == "--out") outPath = value();
      else if (!a.empty() && a[0] == '-') throw std::invalid_argument("unknown option " + a);
      else if (meshPath.empty()) meshPath = a;
      else throw std::invalid_argument("unexpected argument " + a);
    }
    if (meshPath.empty()) throw std::invalid_argument("missing FILE (a .fold or .svg crease pattern, or an .obj, .off or .ply mesh)");
    if (isCreasePatternFile(meshPath) && (!unfoldingPath.empty() || !variables.empty() || proximity))
      throw std::invalid_argument("--unfolding, --variables and --proximity apply to meshes, not to crease patterns");
    if (!variables.empty() && variables != "mesh" && variables != "unfolding" && variables != "both")
      throw std::invalid_argument("--variables: expected mesh, unfolding or both, got \"" + variables + "\"");
    proto::millimetresPerUnit(units);
  } catch (const std::invalid_argument& e) {
    err << "devsurf import: " << e.what() << "\n" << commandUsage("import");
    return 2;
  }
  if (isCreasePatternFile(meshPath)) return importCreasePatternFile(meshPath, name, unitsGiven ? units : "", outPath, out, err);
  std::string scene;
  try {
    int skipped = 0;
    const io::PolygonMeshFile mesh = io::readPolygonMesh(meshPath, &skipped);
    if (skipped > 0)
      throw std::runtime_error(meshPath + ": " + std::to_string(skipped) +
                               " faces could not be added (non-manifold or turned against their neighbours)");
    nlohmann::json model = {{"kind", "quad_mesh"}};
    nlohmann::json vertices = nlohmann::json::array(), faces = nlohmann::json::array();
    for (Eigen::Index i = 0; i < mesh.vertices.rows(); ++i)
      vertices.push_back({mesh.vertices(i, 0), mesh.vertices(i, 1), mesh.vertices(i, 2)});
    for (const auto& f : mesh.faces) {
      nlohmann::json face = {f[0], f[1], f[2]};
      if (f[3] >= 0) face.push_back(f[3]);
      faces.push_back(std::move(face));
    }
    model["mesh"] = {{"vertices", vertices}, {"faces", faces}};
    if (!unfoldingPath.empty()) {
      const io::PolygonMeshFile flat = io::readPolygonMesh(unfoldingPath);
      if (flat.vertices.rows() != mesh.vertices.rows() || flat.faces != mesh.faces)
        throw std::runtime_error(unfoldingPath + ": the unfolding must have the mesh's vertices and faces (" +
                                 std::to_string(flat.vertices.rows()) + " vertices, " + std::to_string(flat.faces.size()) +
                                 " faces; the mesh has " + std::to_string(mesh.vertices.rows()) + ", " +
                                 std::to_string(mesh.faces.size()) + ")");
      const bool planar = flat.vertices.col(2).cwiseAbs().maxCoeff() == 0.0;
      nlohmann::json u = nlohmann::json::array();
      for (Eigen::Index i = 0; i < flat.vertices.rows(); ++i)
        u.push_back(planar ? nlohmann::json{flat.vertices(i, 0), flat.vertices(i, 1)}
                           : nlohmann::json{flat.vertices(i, 0), flat.vertices(i, 1), flat.vertices(i, 2)});
      model["unfolding"] = {{"vertices", u}};
      if (!planar) model["unfolding"]["planar"] = false;
    }
    model["variables"] = !variables.empty() ? variables : unfoldingPath.empty() ? "both" : "mesh";
    if (proximity) {
      model["reference"] = {{"vertices", vertices}, {"faces", nlohmann::json::array()}};
      for (const auto& f : mesh.faces) {
        model["reference"]["faces"].push_back({f[0], f[1], f[2]});
        if (f[3] >= 0) model["reference"]["faces"].push_back({f[0], f[2], f[3]});
      }
      model["weights"] = {{"proximity_point", 0.001}, {"proximity_plane", 0.001}};  // Fig. 22, rows 10 and 20
    }
    nlohmann::json document = {{"format", "devsurf-scene"}, {"version", 1}, {"model", model}};
    document["name"] = name.empty() ? std::filesystem::path(meshPath).stem().string() : name;
    if (units != "mm") document["units"] = units;
    // Read back as any scene is: the schema, indices, the model's checks and the limits.
    scene = proto::sceneToJson(proto::sceneFromJson(document)).dump(1) + "\n";
  } catch (const std::bad_alloc&) {
    err << "devsurf import: out of memory reading " << meshPath << "\n";
    return 1;
  } catch (const proto::SceneError& e) {
    err << "devsurf import: " << meshPath << ": " << e.what() << "\n";
    return 2;
  } catch (const std::exception& e) {  // an unreadable file, faces OpenMesh refuses, an unfolding that does not match
    err << "devsurf import: " << e.what() << "\n";
    return 2;
  }
  return writeImportedScene(scene, outPath, out, err);
}

int serveCommand(const std::vector<std::string>& args, std::ostream& out, std::ostream& err) {
  DaemonOptions o;
  spdlog::level::level_enum logLevel = spdlog::level::info;
  bool webGiven = false;
  try {
    for (std::size_t i = 0; i < args.size(); ++i) {
      const std::string& a = args[i];
      auto value = [&args, &i]() -> const std::string& { return flagValue(args, i); };
      if (a == "--help" || a == "-h") {
        out << commandUsage("serve");
        return 0;
      }
      if (a == "--port") o.port = static_cast<int>(parseNumber(a, value(), 0, 65535));
      else if (a == "--bind") o.bind = value();
      else if (a == "--data") o.dataDir = value();
      else if (a == "--store") o.store = value();
      else if (a == "--node-id") {
        o.nodeId = value();
        if (o.nodeId.empty() || o.nodeId.size() > 64)
          throw std::invalid_argument("--node-id: expected 1 to 64 characters");
      }
      else if (a == "--lease-ms") o.leaseMs = static_cast<double>(parseNumber(a, value(), 100, 3600000));
      else if (a == "--api-key") o.apiKey = value();
      else if (a == "--web") {
        o.webRoot = value();
        webGiven = true;
      }
      else if (a == "--demo") o.demoScenes.push_back(value());
      else if (a == "--workers") o.workerThreads = static_cast<int>(parseNumber(a, value(), 0, 256));
      else if (a == "--max-sessions") o.maxSessions = static_cast<int>(parseNumber(a, value(), 1, 100000));
      else if (a == "--max-clients") o.maxClientsPerSession = static_cast<int>(parseNumber(a, value(), 1, 10000));
      else if (a == "--max-body") o.http.maxBodyBytes = static_cast<std::size_t>(parseNumber(a, value(), 1024, 1L << 30));
      else if (a == "--max-message") o.maxMessageBytes = static_cast<std::size_t>(parseNumber(a, value(), 1024, 1L << 28));
      else if (a == "--message-rate") o.messageRate = static_cast<double>(parseNumber(a, value(), 1, 100000));
      else if (a == "--max-control-points") o.maxControlPoints = static_cast<int>(parseNumber(a, value(), 4, 10000000));
      else if (a == "--max-iterations") o.maxIterationsPerRequest = static_cast<int>(parseNumber(a, value(), 1, 1000000));
      else if (a == "--job-workers") o.jobs.workers = static_cast<int>(parseNumber(a, value(), 1, 256));
      else if (a == "--max-jobs") o.jobs.maxQueued = static_cast<std::size_t>(parseNumber(a, value(), 1, 1000000));
      else if (a == "--job-timeout-ms") o.jobs.maxRunMs = static_cast<double>(parseNumber(a, value(), 1, 86400000));
      else if (a == "--job-retention-hours")
        o.jobs.retentionMs = static_cast<double>(parseNumber(a, value(), 0, 87600)) * 3600.0 * 1000.0;
      else if (a == "--memory-budget-mb") o.memoryBudgetMb = static_cast<double>(parseNumber(a, value(), 16, 1L << 30));
      else if (a == "--session-time-budget-ms")
        o.session.rebuildTimeBudgetMs = static_cast<double>(parseNumber(a, value(), 100, 86400000));
      else if (a == "--drag-iterations") o.session.dragIterations = static_cast<int>(parseNumber(a, value(), 1, 100));
      else if (a == "--release-iterations") o.session.releaseIterations = static_cast<int>(parseNumber(a, value(), 0, 1000));
      else if (a == "--log-level") logLevel = cli::parseLogLevel(a, value());
      else if (a == "--max-connections") o.http.maxConnections = static_cast<std::size_t>(parseNumber(a, value(), 1, 1000000));
      else if (a == "--max-connections-per-address") o.http.maxConnectionsPerAddress = static_cast<std::size_t>(parseNumber(a, value(), 1, 1000000));
      else if (a == "--max-header-bytes") o.http.maxHeaderBytes = static_cast<std::size_t>(parseNumber(a, value(), 1024, 1L << 20));
      else if (a == "--max-header-fields") o.http.maxHeaderFields = static_cast<std::size_t>(parseNumber(a, value(), 8, 10000));
      else if (a == "--header-timeout-ms") o.http.headerTimeout = std::chrono::milliseconds(parseNumber(a, value(), 100, 3600000));
      else if (a == "--body-timeout-ms") o.http.bodyTimeout = std::chrono::milliseconds(parseNumber(a, value(), 100, 3600000));
      else if (a == "--keep-alive-timeout-ms") o.http.keepAliveTimeout = std::chrono::milliseconds(parseNumber(a, value(), 100, 3600000));
      else if (a == "--keep-alive-requests") o.http.maxRequestsPerConnection = static_cast<std::size_t>(parseNumber(a, value(), 1, 1000000));
      else if (a == "--write-timeout-ms") o.http.writeTimeout = std::chrono::milliseconds(parseNumber(a, value(), 100, 3600000));
      else if (a == "--http-workers") o.http.workers = static_cast<int>(parseNumber(a, value(), 1, 256));
      else throw std::invalid_argument("unknown option " + a);
    }
  } catch (const std::invalid_argument& e) {
    err << "devsurf serve: " << e.what() << "\n" << commandUsage("serve");
    return 2;
  }
  tuneProcessForServing();
  // Logs go to stderr; stdout carries only the line with the URL (scripts read it).
  if (!spdlog::get("devsurf")) spdlog::set_default_logger(spdlog::stderr_color_mt("devsurf"));
  spdlog::set_level(logLevel);
  if (!webGiven) {  // the built app of this source tree or installation (StaticAssets.h)
    std::error_code ec;
    const std::filesystem::path exe = std::filesystem::read_symlink("/proc/self/exe", ec);
    const std::filesystem::path cwd = std::filesystem::current_path(ec);
    o.webRoot = defaultWebRoot(cwd, exe.parent_path()).string();
    if (o.webRoot.empty()) spdlog::warn("no built web app found (web/dist): serving none; build it or pass --web DIR");
  }
  // SIGINT/SIGTERM are taken by a thread of their own (blocked everywhere else).
  sigset_t signals;
  sigemptyset(&signals);
  sigaddset(&signals, SIGINT);
  sigaddset(&signals, SIGTERM);
  pthread_sigmask(SIG_BLOCK, &signals, nullptr);
  try {
    Daemon daemon(o);
    // The signal thread runs from the start: a SIGTERM while sessions are being restored ends
    // the start-up there (everything restored so far is stored) instead of waiting for it.
    std::mutex phase;
    bool serving = false, signalled = false;
    std::thread waiter([&signals, &daemon, &phase, &serving, &signalled]() {
      int sig = 0;
      sigwait(&signals, &sig);
      spdlog::info("signal {}: shutting down", sig);
      std::lock_guard<std::mutex> lock(phase);
      signalled = true;
      if (serving)
        daemon.stop();
      else
        daemon.abandonStart();
    });
    const int port = daemon.start();
    {
      std::lock_guard<std::mutex> lock(phase);
      serving = port > 0 && !signalled;
    }
    if (serving) {
      out << "devsurf serving on http://" << (o.bind == "0.0.0.0" ? "localhost" : o.bind) << ":" << port << "/" << std::endl;
      daemon.run();
    }
    {
      std::lock_guard<std::mutex> lock(phase);
      if (!signalled) pthread_kill(waiter.native_handle(), SIGTERM);  // wake it: the server stopped by itself
    }
    waiter.join();
    spdlog::info("stopped");
    return 0;
  } catch (const std::exception& e) {
    err << "devsurf serve: " << e.what() << "\n";
    return 1;
  }
}

int jobCommand(const std::vector<std::string>& args, std::istream& in, std::ostream& out, std::ostream& err) {
  std::string scenePath, server, apiKey, idemKey, outPath;
  bool wait = false, requireQuality = false;
  ServerAddress address;
  try {
    if (args.empty() || args[0] != "submit") throw std::invalid_argument("expected: job submit SCENE --server URL");
    for (std::size_t i = 1; i < args.size(); ++i) {
      const std::string& a = args[i];
      auto value = [&args, &i]() -> const std::string& { return flagValue(args, i); };
      if (a == "--server") server = value();
      else if (a == "--api-key") apiKey = value();
      else if (a == "--idempotency-key") idemKey = value();
      else if (a == "--out") outPath = value();
      else if (a == "--wait") wait = true;
      else if (a == "--require-quality") requireQuality = true;
      else if (a != "-" && !a.empty() && a[0] == '-') throw std::invalid_argument("unknown option " + a);
      else if (scenePath.empty()) scenePath = a;
      else throw std::invalid_argument("unexpected argument " + a);
    }
    if (scenePath.empty() || server.empty()) throw std::invalid_argument("need SCENE and --server URL");
    if (requireQuality && !wait) throw std::invalid_argument("--require-quality needs --wait (the report comes at the end)");
    address = parseServerAddress(server);
  } catch (const std::invalid_argument& e) {
    err << "devsurf job: " << e.what() << "\n" << commandUsage("job");
    return 2;
  }
  std::string body;
  if (scenePath == "-") {
    body = readAll(in);
  } else {
    std::ifstream file(scenePath, std::ios::binary);
    if (!file) {
      err << "devsurf job: cannot open " << scenePath << "\n";
      return 2;
    }
    body = readAll(file);
  }
  httplib::Client client(address.origin);
  client.set_connection_timeout(5);
  client.set_read_timeout(60);
  httplib::Headers headers;
  if (!apiKey.empty()) headers.emplace("Authorization", "Bearer " + apiKey);
  if (!idemKey.empty()) headers.emplace("Idempotency-Key", idemKey);
  auto res = client.Post(address.prefix + "/api/jobs", headers, body, "application/json");
  if (!res) {
    err << "devsurf job: cannot reach " << server << ": " << httplib::to_string(res.error())
        << " (is `devsurf serve` running there? --server takes the address it prints, http://HOST:PORT/)\n";
    return 1;
  }
  if (res->status != 202 && res->status != 200) {
    err << "devsurf job: server answered " << res->status << ": " << res->body << "\n";
    return res->status >= 400 && res->status < 500 ? 2 : 1;
  }
  const nlohmann::json submitted = nlohmann::json::parse(res->body, nullptr, false);
  if (!submitted.is_object() || !submitted.contains("id") || !submitted["id"].is_string()) {
    err << "devsurf job: " << server << " answered " << res->status << " without a job id (is it a devsurf daemon?)\n";
    return 1;
  }
  const std::string id = submitted["id"];
  if (!wait) {
    out << nlohmann::json{{"id", id}, {"location", address.prefix + "/api/jobs/" + id}}.dump() << "\n";
    return 0;
  }
  const bool terminal = isatty(STDERR_FILENO);
  for (;;) {
    auto r = client.Get(address.prefix + "/api/jobs/" + id, headers);
    if (!r || r->status != 200) {
      err << "devsurf job: lost the job " << id << "\n";
      return 1;
    }
    const nlohmann::json job = nlohmann::json::parse(r->body, nullptr, false);
    if (!job.is_object() || !job.contains("state") || !job["state"].is_string()) {
      err << "devsurf job: the job " << id << " came back unreadable\n";
      return 1;
    }
    const std::string state = job["state"];
    const int it = job["progress"]["iteration"], of = std::max(1, job["progress"]["of"].get<int>());
    if (terminal) {
      const int width = 30, filled = std::min(width, it * width / of);
      err << "\r" << id << " [" << std::string(filled, '#') << std::string(width - filled, ' ') << "] "
          << it << "/" << of << " " << state << "   " << std::flush;
    }
    if (state == "succeeded" || state == "failed" || state == "cancelled") {
      if (terminal) err << "\n";
      if (state != "succeeded") {
        err << "devsurf job: " << state << (job.contains("error") ? ": " + job["error"].get<std::string>() : "") << "\n";
        return 1;
      }
      const nlohmann::json& report = job["report"];
      const std::string text = report.dump(2);
      if (outPath.empty()) out << text << "\n";
      else std::ofstream(outPath) << text << "\n";
      // As `devsurf solve`: a missed quality is a warning, and exit status 3 with --require-quality.
      std::string kind;
      if (report.contains("scene") && report["scene"].contains("model")) kind = report["scene"]["model"].value("kind", "");
      if (requireQuality && !report.contains("quality"))
        err << "devsurf job: note: --require-quality: a " << kind << " report has no quality thresholds to require (see its metrics)\n";
      if (warnQualityMissed(report, "job", kind, err) && requireQuality) return 3;
      return 0;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(200));
  }
}

int runCli(const std::vector<std::string>& args, std::istream& in, std::ostream& out,
           std::ostream& err) {
  if (args.empty()) {
    err << kUsage;
    return 2;
  }
  const std::string& command = args[0];
  const std::vector<std::string> rest(args.begin() + 1, args.end());
  // `devsurf COMMAND --help` (or -h anywhere among its arguments) prints the usage, for every
  // command, rather than "unknown option" or a start.
  if (command != "help" && std::any_of(rest.begin(), rest.end(), [](const std::string& a) { return a == "--help" || a == "-h"; })) {
    out << commandUsage(command);
    return 0;
  }
  if (command == "solve") return solveCommand(rest, in, out, err);
  if (command == "serve") return serveCommand(rest, out, err);
  if (command == "job") return jobCommand(rest, in, out, err);
  if (command == "worker") return workerCommand(rest, out, err);
  if (command == "import") return importCommand(rest, out, err);
  if (command == "reference") return referenceCommand(rest, out, err);
  if (command == "fit") return fitCommand(rest, out, err);
  if (command == "merge") return mergeCommand(rest, out, err);
  if (command == "cover") return coverCommand(rest, out, err);
  if (command == "approximate") return approximateCommand(rest, out, err);
  if (command == "version" || command == "--version") {
    out << "devsurf 0.1.0\n";
    return 0;
  }
  if (command == "help" || command == "--help" || command == "-h") {
    out << kUsage;
    return 0;
  }
  err << "devsurf: unknown command \"" << command << "\"\n" << kUsage;
  return 2;
}

}  // namespace devsurf::server
