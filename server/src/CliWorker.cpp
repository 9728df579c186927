// `devsurf worker`: a process that only solves batch jobs from a shared store (issue 18): it
// claims jobs from the queue under leases like a daemon's job workers, and serves no HTTP.

#include <pthread.h>
#include <signal.h>
#include <unistd.h>

#include <cstdio>
#include <iostream>

#include <spdlog/sinks/stdout_color_sinks.h>
#include <spdlog/spdlog.h>

#include "CliArguments.h"
#include "devsurf/server/Cli.h"
#include "devsurf/server/JobQueue.h"
#include "devsurf/server/store/Store.h"

namespace devsurf::server {

using cli::flagValue;
using cli::parseNumber;

int workerCommand(const std::vector<std::string>& args, std::ostream& out, std::ostream& err) {
  const char* usage =
      "usage: devsurf worker --store postgresql://... [--node-id ID] [--job-workers N] [--lease-ms MS]\n"
      "                      [--job-timeout-ms MS] [--job-retention-hours H] [--max-iterations N]\n"
      "                      [--max-control-points N]\n"
      "                      [--memory-budget-mb MB] [--log-level LEVEL]\n";
  std::string location, nodeId;
  JobLimits limits;
  double memoryBudgetMb = 512.0;
  int maxControlPoints = 20000;
  spdlog::level::level_enum logLevel = spdlog::level::info;
  try {
    for (std::size_t i = 0; i < args.size(); ++i) {
      const std::string& a = args[i];
      auto value = [&args, &i]() -> const std::string& { return flagValue(args, i); };
      if (a == "--help" || a == "-h") {
        out << usage;
        return 0;
      }
      if (a == "--store") location = value();
      else if (a == "--node-id") nodeId = value();
      else if (a == "--job-workers") limits.workers = static_cast<int>(parseNumber(a, value(), 1, 256));
      else if (a == "--lease-ms") limits.leaseMs = static_cast<double>(parseNumber(a, value(), 100, 3600000));
      else if (a == "--job-timeout-ms") limits.maxRunMs = static_cast<double>(parseNumber(a, value(), 1, 86400000));
      else if (a == "--job-retention-hours")
        limits.retentionMs = static_cast<double>(parseNumber(a, value(), 0, 87600)) * 3600.0 * 1000.0;
      else if (a == "--max-iterations") limits.maxIterations = static_cast<int>(parseNumber(a, value(), 1, 1000000));
      else if (a == "--max-control-points") maxControlPoints = static_cast<int>(parseNumber(a, value(), 4, 10000000));
      else if (a == "--memory-budget-mb") memoryBudgetMb = static_cast<double>(parseNumber(a, value(), 16, 1L << 30));
      else if (a == "--log-level") logLevel = cli::parseLogLevel(a, value());
      else throw std::invalid_argument("unknown option " + a);
    }
    if (!store::isPostgresLocation(location))
      throw std::invalid_argument("--store: a worker needs the shared store, postgresql://... (got \"" + location + "\")");
    if (nodeId.size() > 64) throw std::invalid_argument("--node-id: expected 1 to 64 characters");
  } catch (const std::invalid_argument& e) {
    err << "devsurf worker: " << e.what() << "\n" << usage;
    return 2;
  }
  if (!spdlog::get("devsurf")) spdlog::set_default_logger(spdlog::stderr_color_mt("devsurf"));
  spdlog::set_level(logLevel);
  if (nodeId.empty()) {
    char host[256] = {0};
    if (::gethostname(host, sizeof host - 1) != 0) std::snprintf(host, sizeof host, "worker");
    nodeId = std::string(host) + "-" + std::to_string(::getpid());
  }
  limits.heartbeatMs = std::min(limits.heartbeatMs, limits.leaseMs / 10.0);
  limits.resources.maxControlPoints = maxControlPoints;
  limits.resources.maxIterations = limits.maxIterations;
  limits.resources.memoryBudgetBytes = memoryBudgetMb * 1024.0 * 1024.0;
  try {
    const std::unique_ptr<store::Store> shared = store::openStore(location);
    // SIGINT/SIGTERM from here on are waited for (blocked, then taken by sigwait below).
    sigset_t signals;
    sigemptyset(&signals);
    sigaddset(&signals, SIGINT);
    sigaddset(&signals, SIGTERM);
    pthread_sigmask(SIG_BLOCK, &signals, nullptr);
    {
      JobQueue queue(*shared, limits, nodeId);
      out << "devsurf worker " << nodeId << " claiming jobs from " << shared->info().path << std::endl;
      int sig = 0;
      sigwait(&signals, &sig);
      spdlog::info("signal {}: handing running jobs back and stopping", sig);
    }  // the queue's destructor stops the solves and re-queues them
    spdlog::info("stopped");
    return 0;
  } catch (const std::exception& e) {
    err << "devsurf worker: " << e.what() << "\n";
    return 1;
  }
}

}  // namespace devsurf::server
