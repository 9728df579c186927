#pragma once

// Shared by the CLI tests: one `devsurf` command run in-process, its exit code and output.

#include <sstream>
#include <string>
#include <vector>

#include "devsurf/server/Cli.h"

namespace devsurf::server::testing {

struct CliRun {
  int code;
  std::string out, err;
};

/// runCli with `input` as standard input.
inline CliRun runCommand(const std::vector<std::string>& args, const std::string& input = "") {
  std::istringstream in(input);
  std::ostringstream out, err;
  const int code = runCli(args, in, out, err);
  return {code, out.str(), err.str()};
}

/// Path of a shipped example scene.
inline std::string examplePath(const std::string& name) {
  return std::string(DEVSURF_SOURCE_DIR) + "/examples/" + name;
}

}  // namespace devsurf::server::testing
