// HTTP (cpp-httplib routes) + WebSocket (Boost.Beast) on one port. See Server.h for the design;
// the connections are in HttpConnection.cpp and WebSocketSession.cpp.
#include "devsurf/server/transport/Server.h"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <chrono>
#include <stdexcept>
#include <utility>
#include <vector>

#include "transport/HttpConnection.h"
#include "transport/ServerCore.h"
#include "transport/WebSocketSession.h"

namespace devsurf::server::transport {

Server::Server(WebSocketHandlers handlers, TransportLimits limits)
    : core_(std::make_shared<detail::ServerCore>(std::move(handlers), limits)) {
  const auto& http = core_->limits.http;
  // What httplib itself still checks or announces (the transport enforces the limits first).
  payload_max_length_ = http.maxBodyBytes;
  keep_alive_max_count_ = http.maxRequestsPerConnection;
  keep_alive_timeout_sec_ =
      static_cast<time_t>(std::max<std::int64_t>(1, (http.keepAliveTimeout.count() + 999) / 1000));
  // A worker runs this on a complete request; the stream holds the request and takes the
  // response. stop() joins the workers before the Server can be destroyed.
  core_->runRoutes = [this](httplib::Stream& stream, bool closeConnection) {
    bool connectionClosed = false;
    const bool ok = process_request(stream, closeConnection, connectionClosed, nullptr);
    return !ok || connectionClosed || closeConnection;
  };
  core_->startThreads();
}

Server::~Server() { stop(); }

int Server::bind(const std::string& host, int port) {
  {
    std::lock_guard<std::mutex> lk(serveMutex_);
    if (stopRequested_) throw std::runtime_error("transport: bind() after stop()");
    if (port_ != 0) throw std::runtime_error("transport: bind() called twice");
  }
  port_ = core_->bind(host, port);
  spdlog::info("transport: listening on {}:{}", host, port_);
  return port_;
}

void Server::serve() {
  {
    std::lock_guard<std::mutex> lk(serveMutex_);
    if (stopRequested_) return;
    if (port_ == 0) throw std::runtime_error("transport: serve() before bind()");
    if (serving_) throw std::runtime_error("transport: serve() called twice");
    serving_ = true;
  }
  core_->startAccepting();
  std::unique_lock<std::mutex> lk(serveMutex_);
  serveCv_.wait(lk, [this] { return stopped_; });
  serving_ = false;
}

void Server::stop() {
  std::call_once(stopOnce_, [this] {
    auto& core = *core_;
    {
      std::lock_guard<std::mutex> lk(core.mutex);
      core.stopping = true;
      core.stoppingFlag = true;
    }
    {
      std::lock_guard<std::mutex> lk(serveMutex_);
      stopRequested_ = true;
    }

    // 1. Stop accepting.
    core.closeAcceptor();

    // 2. WebSockets get 1001, idle HTTP connections are closed, requests in progress are
    //    answered; wait for all of them, then drop what is left.
    auto snapshot = [&core](std::vector<std::shared_ptr<detail::WebSocketSession>>& sessions,
                            std::vector<std::shared_ptr<detail::HttpConnection>>& http) {
      std::lock_guard<std::mutex> lk(core.mutex);
      for (const auto& entry : core.sessions) sessions.push_back(entry.second);
      for (const auto& entry : core.httpConnections) http.push_back(entry.second);
    };
    std::vector<std::shared_ptr<detail::WebSocketSession>> sessions;
    std::vector<std::shared_ptr<detail::HttpConnection>> http;
    snapshot(sessions, http);
    for (auto& session : sessions) session->shutdown();
    for (auto& connection : http) connection->shutdown();
    sessions.clear();
    http.clear();
    bool allClosed;
    {
      std::unique_lock<std::mutex> lk(core.mutex);
      const auto grace = core.limits.closeTimeout + std::chrono::milliseconds(500);
      allClosed = core.cv.wait_for(lk, grace, [&core] {
        return core.sessions.empty() && core.httpConnections.empty();
      });
    }
    if (!allClosed) {
      snapshot(sessions, http);
      spdlog::warn("transport: {} WebSocket(s) and {} HTTP connection(s) did not close in time; "
                   "dropping them",
                   sessions.size(), http.size());
      for (auto& session : sessions) session->abort();
      for (auto& connection : http) connection->abort();
      sessions.clear();
      http.clear();
      std::unique_lock<std::mutex> lk(core.mutex);
      core.cv.wait_for(lk, std::chrono::seconds(2), [&core] {
        return core.sessions.empty() && core.httpConnections.empty();
      });
    }

    // 3. Routes still running finish (their answers go nowhere now); then the io threads.
    core.stopWorkers();
    core.stopThreads();
    core.finishLeftovers(core.limits.closeTimeout + std::chrono::milliseconds(500));
    {
      std::lock_guard<std::mutex> lk(serveMutex_);
      stopped_ = true;
    }
    serveCv_.notify_all();
    spdlog::debug("transport: stopped");
  });
}

std::size_t Server::connectionCount() const { return core_->openCount.load(); }

}  // namespace devsurf::server::transport
