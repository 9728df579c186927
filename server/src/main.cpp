#include <iostream>
#include <string>
#include <vector>

#include "devsurf/engine/LinearSolver.h"
#include "devsurf/server/Cli.h"

int main(int argc, char** argv) {
  devsurf::engine::prepareBlasForThreads();  // before any thread of ours, and before signals are blocked
  std::ios::sync_with_stdio(false);
  const std::vector<std::string> args(argv + 1, argv + argc);
  return devsurf::server::runCli(args, std::cin, std::cout, std::cerr);
}
