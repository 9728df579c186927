#pragma once
// Private to devsurf_transport: the Boost.Asio side of transport::Server, shared by the listener,
// the HTTP connections (HttpConnection.h) and the WebSocket sessions (WebSocketSession.h).
//
// Ownership: the Server, every connection and every WebSocket session hold a shared_ptr to the
// core, so a Connection the protocol layer keeps after the Server is gone never points at a
// destroyed io_context. The core holds its live connections and sessions (shared_ptr) until they
// finish, so that stop() can reach every one of them.

#include <httplib.h>

#include <boost/asio/executor_work_guard.hpp>
#include <boost/asio/io_context.hpp>
#include <boost/asio/ip/tcp.hpp>
#include <boost/asio/steady_timer.hpp>
#include <boost/asio/strand.hpp>
#include <boost/asio/thread_pool.hpp>
#include <boost/beast/core/tcp_stream.hpp>
#include <boost/beast/http/message.hpp>
#include <boost/beast/http/string_body.hpp>

#include <atomic>
#include <condition_variable>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <unordered_map>
#include <vector>

#include "devsurf/server/transport/Connection.h"

namespace devsurf::server::transport::detail {

namespace net = boost::asio;
namespace beast = boost::beast;
namespace http = beast::http;
using tcp = net::ip::tcp;

class HttpConnection;
class WebSocketSession;
struct ServerCore;

/// A complete request as read from the peer: head and decoded body.
using HttpRequest = http::request<http::string_body>;

/// IPv4-mapped IPv6 addresses (::ffff:a.b.c.d) as IPv4; others unchanged.
net::ip::address unmappedAddress(const net::ip::address& address);
/// "ip:port" of an endpoint ("[v6]:port" for IPv6; IPv4-mapped IPv6 addresses as IPv4).
std::string formatEndpoint(const tcp::endpoint& endpoint);
/// The peer's IP address as the per-address connection cap counts it.
std::string addressKey(const tcp::endpoint& endpoint);

/// One admitted TCP connection, counted against HttpLimits::maxConnections and
/// maxConnectionsPerAddress until release() or destruction. Move-only; an empty slot counts
/// nothing.
class ConnectionSlot {
 public:
  ConnectionSlot() = default;
  ConnectionSlot(std::shared_ptr<ServerCore> core, std::string address)
      : core_(std::move(core)), address_(std::move(address)) {}
  ConnectionSlot(ConnectionSlot&& other) noexcept = default;
  ConnectionSlot& operator=(ConnectionSlot&& other) noexcept {
    if (this != &other) {
      release();
      core_ = std::move(other.core_);
      address_ = std::move(other.address_);
    }
    return *this;
  }
  ConnectionSlot(const ConnectionSlot&) = delete;
  ConnectionSlot& operator=(const ConnectionSlot&) = delete;
  ~ConnectionSlot() { release(); }

  explicit operator bool() const { return core_ != nullptr; }
  void release();

 private:
  std::shared_ptr<ServerCore> core_;
  std::string address_;
};

struct ServerCore : std::enable_shared_from_this<ServerCore> {
  /// Runs one complete request (read from `in`) through httplib's routing and writes the whole
  /// response to `in` (see RequestStream in HttpConnection.cpp). `closeConnection`: answer with
  /// "Connection: close". Returns whether the connection must be closed afterwards.
  using RouteRunner = std::function<bool(httplib::Stream& in, bool closeConnection)>;

  ServerCore(WebSocketHandlers h, TransportLimits l);

  void startThreads();
  void stopThreads();
  /// After stopThreads(), on the stopping thread: ends every connection still registered and
  /// runs the handlers left in the io_context (for at most `limit`), so none keeps a connection
  /// alive. A connection's handler holds the connection and the connection holds this core, so a
  /// handler left queued would keep both alive for good (LeakSanitizer's report at exit).
  void finishLeftovers(std::chrono::milliseconds limit);

  // ---- listening (the acceptor lives on its own strand) ----
  /// Opens, binds and listens; returns the bound port. Throws std::runtime_error.
  int bind(const std::string& host, int port);
  /// Starts the accept loop (after bind()).
  void startAccepting();
  /// Closes the listening socket; blocks until done. Not from an io thread.
  void closeAcceptor();

  // ---- connection accounting ----
  /// A slot for a new connection from `address`, or an empty slot with the reason in `refusal`.
  ConnectionSlot admit(const std::string& address, std::string& refusal);
  void releaseSlot(const std::string& address);

  // ---- registries (for stop()) ----
  std::uint64_t newId() { return nextId++; }
  void removeHttp(std::uint64_t id);
  /// Registers the session; false when stopping (the caller then ends it).
  bool addSession(std::uint64_t id, std::shared_ptr<WebSocketSession> session);
  void removeSession(std::uint64_t id);

  // ---- route workers ----
  /// Runs `task` on a route worker; false (task dropped) once the workers are stopped.
  bool runOnWorker(std::function<void()> task);
  /// Stops taking tasks and joins the workers (queued tasks still run).
  void stopWorkers();
  /// Returns freed heap memory to the OS soon (on a worker; coalesced). After large bodies.
  void trimMemorySoon();

  const WebSocketHandlers handlers;
  const TransportLimits limits;
  RouteRunner runRoutes;  // set by the Server before serving

  net::io_context ioc;
  std::optional<net::executor_work_guard<net::io_context::executor_type>> work;
  std::vector<std::thread> threads;
  net::strand<net::io_context::executor_type> acceptorStrand;
  tcp::acceptor acceptor;

  std::mutex mutex;  // guards everything below except the atomics
  std::condition_variable cv;
  bool stopping = false;
  std::atomic<bool> stoppingFlag{false};  // lock-free copy of `stopping` for the io threads
  std::unordered_map<std::uint64_t, std::shared_ptr<WebSocketSession>> sessions;
  std::unordered_map<std::uint64_t, std::shared_ptr<HttpConnection>> httpConnections;
  /// Every WebSocket session ever registered, for finishLeftovers (pruned of expired entries).
  std::vector<std::weak_ptr<WebSocketSession>> everySession;
  std::size_t openSlots = 0;   // admitted TCP connections (HTTP + WebSocket)
  std::size_t refusing = 0;    // connections being answered 503 (not admitted)
  std::unordered_map<std::string, std::size_t> slotsByAddress;
  std::size_t threadsExited = 0;
  std::atomic<std::uint64_t> nextId{1};
  std::atomic<std::size_t> openCount{0};  // open WebSockets (onOpen called, onClose not yet)

 private:
  void acceptNext();
  void onAccept(beast::error_code ec, tcp::socket socket);

  std::optional<net::thread_pool> workers_;
  bool workersStopped_ = false;  // under mutex
  std::atomic<bool> trimPending_{false};
  net::steady_timer acceptRetry_;
};

/// Starts serving a freshly accepted socket: as an HTTP connection, or, when `slot` is empty,
/// by answering 503 with `refusal` and closing.
void startHttpConnection(const std::shared_ptr<ServerCore>& core, tcp::socket socket,
                         ConnectionSlot slot, const std::string& refusal);

/// Hands an upgrade request read by an HTTP connection to a new WebSocket session (which answers
/// 101, or 400/426 for a malformed upgrade, or 503 when stopping).
void startWebSocket(const std::shared_ptr<ServerCore>& core, beast::tcp_stream stream,
                    ConnectionSlot slot, HttpRequest request, std::string remote);

/// The body of every error answer of the transport: {"error":{"code":…,"message":…}}.
std::string errorJson(const std::string& code, const std::string& message);
/// A complete HTTP/1.1 error response with a JSON body and "Connection: close".
std::string errorResponse(int status, const std::string& code, const std::string& message);

}  // namespace devsurf::server::transport::detail
