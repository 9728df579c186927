#include "devsurf/server/Cli.h"

#include <chrono>
#include <fstream>
#include <iostream>
#include <sstream>
#include <stdexcept>

#include "devsurf/proto/Scene.h"
#include "devsurf/server/SceneSolver.h"

namespace devsurf::server {
namespace {

constexpr const char* kUsage =
    "usage: devsurf <command> [options]\n"
    "\n"
    "commands:\n"
    "  solve SCENE [--iterations N] [--out REPORT.json] [--export FORMAT:FILE]...\n"
    "        Solve a scene file (\"-\" reads standard input) and write the report as JSON.\n"
    "        FORMAT is obj, off, ply or stl (the sampled surface as quads).\n"
    "  version   Print the version.\n"
    "  help      Print this text.\n";

constexpr std::size_t kMaxSceneBytes = 64u << 20;  // 64 MiB

std::string readAll(std::istream& in) {
  std::ostringstream buffer;
  buffer << in.rdbuf();
  return buffer.str();
}

int parseIterations(const std::string& value) {
  std::size_t used = 0;
  int n = -1;
  try {
    n = std::stoi(value, &used);
  } catch (const std::exception&) {
    used = 0;
  }
  if (used != value.size() || n < 0 || n > 10000)
    throw std::invalid_argument("--iterations: expected an integer from 0 to 10000, got \"" + value + "\"");
  return n;
}

}  // namespace

int solveCommand(const std::vector<std::string>& args, std::istream& in, std::ostream& out,
                 std::ostream& err) {
  std::string scenePath, outPath;
  int iterations = -1;
  std::vector<std::string> exports;
  try {
    for (std::size_t i = 0; i < args.size(); ++i) {
      const std::string& a = args[i];
      auto value = [&args, &i, &a]() -> const std::string& {
        if (i + 1 >= args.size()) throw std::invalid_argument(a + ": missing value");
        return args[++i];
      };
      if (a == "--iterations") iterations = parseIterations(value());
      else if (a == "--out") outPath = value();
      else if (a == "--export") exports.push_back(value());
      else if (!a.empty() && a[0] == '-' && a != "-") throw std::invalid_argument("unknown option " + a);
      else if (scenePath.empty()) scenePath = a;
      else throw std::invalid_argument("unexpected argument " + a);
    }
    if (scenePath.empty()) throw std::invalid_argument("missing SCENE (a scene file, or - for standard input)");
  } catch (const std::invalid_argument& e) {
    err << "devsurf solve: " << e.what() << "\n" << kUsage;
    return 2;
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
    SceneSolver solver(proto::sceneFromText(text));
    const engine::SolveSummary summary = solver.solve(iterations);
    const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
    const nlohmann::json report = solver.report(summary, ms);
    for (const std::string& spec : exports) solver.exportTo(spec);
    if (outPath.empty()) {
      out << report.dump(2) << "\n";
    } else {
      std::ofstream file(outPath);
      if (!(file << report.dump(2) << "\n")) {
        err << "devsurf solve: cannot write " << outPath << "\n";
        return 1;
      }
    }
    return summary.reason == engine::TerminationReason::Diverged ? 1 : 0;
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

int runCli(const std::vector<std::string>& args, std::istream& in, std::ostream& out,
           std::ostream& err) {
  if (args.empty()) {
    err << kUsage;
    return 2;
  }
  const std::string& command = args[0];
  const std::vector<std::string> rest(args.begin() + 1, args.end());
  if (command == "solve") return solveCommand(rest, in, out, err);
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
