// The asio side of transport::Server: threads, the listener, connection accounting, route
// workers. See ServerCore.h.
#include "transport/ServerCore.h"

#include <boost/asio/post.hpp>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <cassert>
#include <cstdio>
#include <future>
#include <stdexcept>
#include <utility>

#if defined(__GLIBC__)
#include <malloc.h>
#endif

#include "transport/HttpConnection.h"
#include "transport/WebSocketSession.h"

namespace devsurf::server::transport::detail {

namespace {

const char* statusText(int status) {
  switch (status) {
    case 400: return "Bad Request";
    case 408: return "Request Timeout";
    case 413: return "Payload Too Large";
    case 415: return "Unsupported Media Type";
    case 431: return "Request Header Fields Too Large";
    case 500: return "Internal Server Error";
    case 503: return "Service Unavailable";
    default: return "Error";
  }
}

/// JSON string literal of `text` (our own messages; control characters escaped).
std::string jsonString(const std::string& text) {
  std::string out = "\"";
  for (const char c : text) {
    switch (c) {
      case '"': out += "\\\""; break;
      case '\\': out += "\\\\"; break;
      case '\n': out += "\\n"; break;
      case '\r': out += "\\r"; break;
      case '\t': out += "\\t"; break;
      default:
        if (static_cast<unsigned char>(c) < 0x20) {
          char buf[8];
          std::snprintf(buf, sizeof(buf), "\\u%04x", static_cast<unsigned>(c));
          out += buf;
        } else {
          out += c;
        }
    }
  }
  return out + "\"";
}

}  // namespace

net::ip::address unmappedAddress(const net::ip::address& address) {
  if (address.is_v6() && address.to_v6().is_v4_mapped()) {
    return net::ip::make_address_v4(net::ip::v4_mapped, address.to_v6());
  }
  return address;
}

std::string formatEndpoint(const tcp::endpoint& endpoint) {
  const auto address = unmappedAddress(endpoint.address());
  if (address.is_v6()) return "[" + address.to_string() + "]:" + std::to_string(endpoint.port());
  return address.to_string() + ":" + std::to_string(endpoint.port());
}

std::string addressKey(const tcp::endpoint& endpoint) {
  return unmappedAddress(endpoint.address()).to_string();
}

std::string errorJson(const std::string& code, const std::string& message) {
  return "{\"error\":{\"code\":" + jsonString(code) + ",\"message\":" + jsonString(message) + "}}";
}

std::string errorResponse(int status, const std::string& code, const std::string& message) {
  const std::string body = errorJson(code, message);
  return "HTTP/1.1 " + std::to_string(status) + " " + statusText(status) +
         "\r\nServer: devsurf\r\nContent-Type: application/json\r\nContent-Length: " +
         std::to_string(body.size()) + "\r\nConnection: close\r\n\r\n" + body;
}

// ---- ConnectionSlot ------------------------------------------------------------------------

void ConnectionSlot::release() {
  if (!core_) return;
  core_->releaseSlot(address_);
  core_.reset();
}

// ---- ServerCore --------------------------------------------------------------------------

ServerCore::ServerCore(WebSocketHandlers h, TransportLimits l)
    : handlers(std::move(h)),
      limits(l),
      work(net::make_work_guard(ioc)),
      acceptorStrand(net::make_strand(ioc)),
      acceptor(acceptorStrand),
      acceptRetry_(acceptorStrand) {
  workers_.emplace(static_cast<std::size_t>(std::max(1, limits.http.workers)));
}

void ServerCore::startThreads() {
  const int n = std::max(1, limits.ioThreads);
  for (int i = 0; i < n; ++i) {
    threads.emplace_back([this] {
      for (;;) {
        try {
          ioc.run();
          break;
        } catch (const std::exception& e) {
          spdlog::error("transport: exception on io thread: {}", e.what());
        }
      }
      std::lock_guard<std::mutex> lk(mutex);
      ++threadsExited;
      cv.notify_all();
    });
  }
}

void ServerCore::stopThreads() {
  work.reset();
  {
    std::unique_lock<std::mutex> lk(mutex);
    const bool done = cv.wait_for(lk, std::chrono::seconds(2),
                                  [&] { return threadsExited == threads.size(); });
    if (!done) {
      spdlog::debug("transport: io_context still has work after shutdown; stopping it");
      ioc.stop();
    }
  }
  for (auto& t : threads) {
    if (t.joinable()) t.join();
  }
  threads.clear();
}

void ServerCore::finishLeftovers(std::chrono::milliseconds limit) {
  assert(threads.empty() && "finishLeftovers runs after stopThreads");
  std::vector<std::shared_ptr<WebSocketSession>> leftSessions;
  std::vector<std::shared_ptr<HttpConnection>> leftHttp;
  {
    std::lock_guard<std::mutex> lk(mutex);
    for (const auto& entry : sessions) leftSessions.push_back(entry.second);
    for (const auto& entry : httpConnections) leftHttp.push_back(entry.second);
  }
  // Posted, then run below with everything that was still queued when the threads stopped: a
  // finished connection cancels its timers and closes its socket, so its pending operations
  // complete (aborted) and the io_context runs out of work.
  for (auto& session : leftSessions) session->abort();
  for (auto& connection : leftHttp) connection->abort();
  if (!leftSessions.empty() || !leftHttp.empty()) {
    spdlog::warn("transport: finishing {} WebSocket(s) and {} HTTP connection(s) after the io "
                 "threads stopped",
                 leftSessions.size(), leftHttp.size());
  }
  leftSessions.clear();
  leftHttp.clear();
  auto runLeftovers = [this, limit] {
    ioc.restart();
    try {
      ioc.run_for(limit);
    } catch (const std::exception& e) {
      spdlog::error("transport: exception while finishing connections: {}", e.what());
    }
  };
  runLeftovers();
  // Sessions still alive (held by the protocol layer, or by a handler Beast parked in their own
  // stream) lose their streams; the operations that ends complete (aborted) in a second run.
  std::vector<std::shared_ptr<WebSocketSession>> alive;
  {
    std::lock_guard<std::mutex> lk(mutex);
    for (const auto& weak : everySession)
      if (auto session = weak.lock()) alive.push_back(std::move(session));
    everySession.clear();
  }
  if (!alive.empty()) {
    for (auto& session : alive) session->dropStream();
    alive.clear();
    runLeftovers();
  }
  std::lock_guard<std::mutex> lk(mutex);
  sessions.clear();
  httpConnections.clear();
}

int ServerCore::bind(const std::string& host, int port) {
  beast::error_code ec;
  tcp::resolver resolver(ioc);
  const auto results = resolver.resolve(host, std::to_string(port),
                                        tcp::resolver::passive | tcp::resolver::numeric_service,
                                        ec);
  if (!ec) ec = net::error::host_not_found;
  for (const auto& entry : results) {
    acceptor.open(entry.endpoint().protocol(), ec);
    if (!ec) acceptor.set_option(tcp::acceptor::reuse_address(true), ec);
    if (!ec) acceptor.bind(entry.endpoint(), ec);
    if (!ec) acceptor.listen(net::socket_base::max_listen_connections, ec);
    if (!ec) return acceptor.local_endpoint().port();
    beast::error_code ignored;
    acceptor.close(ignored);
  }
  throw std::runtime_error("transport: cannot bind " + host + ":" + std::to_string(port) + ": " +
                           ec.message());
}

void ServerCore::startAccepting() {
  net::post(acceptorStrand, [self = shared_from_this()] { self->acceptNext(); });
}

void ServerCore::acceptNext() {
  if (stoppingFlag || !acceptor.is_open()) return;
  acceptor.async_accept(net::make_strand(ioc),
                        [self = shared_from_this()](beast::error_code ec, tcp::socket socket) {
                          self->onAccept(ec, std::move(socket));
                        });
}

void ServerCore::onAccept(beast::error_code ec, tcp::socket socket) {
  if (stoppingFlag || ec == net::error::operation_aborted) return;
  if (ec) {
    // Out of file descriptors (EMFILE/ENFILE) or a connection reset before accept: the pending
    // connections wait in the backlog; try again shortly.
    spdlog::warn("transport: accept failed: {}; retrying in 100 ms", ec.message());
    acceptRetry_.expires_after(std::chrono::milliseconds(100));
    acceptRetry_.async_wait([self = shared_from_this()](beast::error_code waitEc) {
      if (!waitEc) self->acceptNext();
    });
    return;
  }
  beast::error_code endpointEc;
  const auto remote = socket.remote_endpoint(endpointEc);
  if (!endpointEc) {
    beast::error_code ignored;
    socket.set_option(tcp::no_delay(true), ignored);
    std::string refusal;
    ConnectionSlot slot = admit(addressKey(remote), refusal);
    startHttpConnection(shared_from_this(), std::move(socket), std::move(slot), refusal);
  }
  acceptNext();
}

void ServerCore::closeAcceptor() {
  std::promise<void> closed;
  auto done = closed.get_future();
  net::post(acceptorStrand, [this, &closed] {
    beast::error_code ignored;
    acceptor.close(ignored);
    acceptRetry_.cancel();
    closed.set_value();
  });
  if (done.wait_for(std::chrono::seconds(5)) != std::future_status::ready) {
    spdlog::warn("transport: closing the listening socket timed out");
  }
}

ConnectionSlot ServerCore::admit(const std::string& address, std::string& refusal) {
  std::lock_guard<std::mutex> lk(mutex);
  const auto& http = limits.http;
  if (openSlots >= http.maxConnections) {
    refusal = "too many connections (limit " + std::to_string(http.maxConnections) + ")";
    return {};
  }
  auto it = slotsByAddress.find(address);
  const std::size_t fromAddress = it == slotsByAddress.end() ? 0 : it->second;
  if (fromAddress >= http.maxConnectionsPerAddress) {
    refusal = "too many connections from " + address + " (limit " +
              std::to_string(http.maxConnectionsPerAddress) + ")";
    return {};
  }
  ++openSlots;
  ++slotsByAddress[address];
  return ConnectionSlot(shared_from_this(), address);
}

void ServerCore::releaseSlot(const std::string& address) {
  std::lock_guard<std::mutex> lk(mutex);
  if (openSlots > 0) --openSlots;
  auto it = slotsByAddress.find(address);
  if (it != slotsByAddress.end() && --it->second == 0) slotsByAddress.erase(it);
  cv.notify_all();
}

void ServerCore::removeHttp(std::uint64_t id) {
  std::lock_guard<std::mutex> lk(mutex);
  httpConnections.erase(id);
  cv.notify_all();
}

bool ServerCore::addSession(std::uint64_t id, std::shared_ptr<WebSocketSession> session) {
  std::lock_guard<std::mutex> lk(mutex);
  if (stopping) return false;
  if (everySession.size() >= 64 && everySession.size() >= 2 * sessions.size()) {
    everySession.erase(std::remove_if(everySession.begin(), everySession.end(),
                                      [](const std::weak_ptr<WebSocketSession>& w) { return w.expired(); }),
                       everySession.end());
  }
  everySession.push_back(session);
  sessions.emplace(id, std::move(session));
  return true;
}

void ServerCore::removeSession(std::uint64_t id) {
  std::lock_guard<std::mutex> lk(mutex);
  sessions.erase(id);
  cv.notify_all();
}

bool ServerCore::runOnWorker(std::function<void()> task) {
  std::lock_guard<std::mutex> lk(mutex);
  if (workersStopped_) return false;
  net::post(*workers_, std::move(task));
  return true;
}

void ServerCore::stopWorkers() {
  {
    std::lock_guard<std::mutex> lk(mutex);
    if (workersStopped_) return;
    workersStopped_ = true;
  }
  workers_->join();
}

void ServerCore::trimMemorySoon() {
#if defined(__GLIBC__)
  if (trimPending_.exchange(true)) return;
  auto self = shared_from_this();
  if (!runOnWorker([self] {
        self->trimPending_ = false;
        ::malloc_trim(0);
      })) {
    trimPending_ = false;
  }
#endif
}

// ---- connections -------------------------------------------------------------------------

void startHttpConnection(const std::shared_ptr<ServerCore>& core, tcp::socket socket,
                         ConnectionSlot slot, const std::string& refusal) {
  const bool refused = !slot;
  const auto id = core->newId();
  auto connection = std::make_shared<HttpConnection>(core, std::move(socket), id, std::move(slot),
                                                     refusal);
  {
    std::lock_guard<std::mutex> lk(core->mutex);
    if (core->stopping) return;  // the socket closes with the connection
    if (refused) {
      // Answering a refusal takes a moment; beyond this many at once, refuse by closing.
      if (core->refusing >= core->limits.http.maxConnections) return;
      ++core->refusing;
    }
    core->httpConnections.emplace(id, connection);
  }
  if (refused) spdlog::debug("transport: refusing a connection: {}", refusal);
  connection->start();
}

void startWebSocket(const std::shared_ptr<ServerCore>& core, beast::tcp_stream stream,
                    ConnectionSlot slot, HttpRequest request, std::string remote) {
  const auto id = core->newId();
  auto session = std::make_shared<WebSocketSession>(core, std::move(stream), id, std::move(remote),
                                                    std::move(slot), std::move(request));
  if (!core->addSession(id, session)) return;  // stopping: the stream closes with the session
  session->start();
}

}  // namespace devsurf::server::transport::detail
