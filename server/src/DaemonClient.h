#pragma once
// Private to server/src: one WebSocket connection of the daemon (Daemon.cpp routes its messages,
// DaemonSessions.cpp closes it when its session moves to another daemon).

#include <chrono>
#include <memory>
#include <mutex>

#include "devsurf/server/Daemon.h"

namespace devsurf::server {

/// Per WebSocket connection: which session it joined, and its message budget.
struct Daemon::Client {
  std::weak_ptr<transport::Connection> connection;
  std::weak_ptr<Session> session;
  int participant = -1;
  double tokens = 0.0;
  std::chrono::steady_clock::time_point refilled = std::chrono::steady_clock::now();
  std::mutex mutex;
};

}  // namespace devsurf::server
