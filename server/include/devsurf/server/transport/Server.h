#pragma once
// One TCP port for REST (cpp-httplib routes), static files (set_mount_point) and a WebSocket
// endpoint at /ws (Boost.Beast, hidden in the .cpp).
//
// Usage:
//   transport::Server server(handlers, limits);
//   server.Get("/api/health", ...);                    // plain httplib::Server API for routes
//   server.set_mount_point("/", webRoot);              // static files; httplib rejects "../"
//   int port = server.bind("127.0.0.1", 0);            // 0 = ephemeral
//   std::thread t([&] { server.serve(); });            // blocks until stop()
//   ...
//   server.stop();  t.join();                           // or just destroy the server
//
// Routing: a complete request "GET /ws" or "GET /ws?…" is a WebSocket upgrade (the path /ws,
// with any query, is reserved); everything else, including "GET /wsx", "GET /ws/…" and any other
// method on /ws, goes to the httplib routes. This also holds for a later request on a kept-alive
// HTTP connection.
//
// How it works: httplib's own accept loop and blocking socket I/O are not used (httplib's read
// timeout applies per read, so a client sending its request a byte at a time held a worker
// indefinitely). Instead every connection is read asynchronously on the transport's io_context
// (Boost.Asio/Beast): the request head and body arrive under deadlines and size limits
// (HttpLimits), and only a complete request reaches a route worker, which runs httplib's
// protected process_request on an in-memory copy of the request (head re-serialized without its
// chunked framing, decoded body) and buffers the whole response; the io_context writes it back
// under a write deadline. So a slow, idle or non-reading client holds a socket and a few
// buffers, never a thread. A "GET /ws" request is handed, already parsed, to a Beast WebSocket
// stream (async_accept(request)). The httplib::Server base class provides the routes, the
// regex matches, the static-file mount and the response formatting, unchanged.
//
// Threads: all socket I/O (HTTP and WebSocket) and the WebSocketHandlers run on
// TransportLimits::ioThreads threads, each connection on its own strand (see Connection.h);
// routes run on HttpLimits::workers threads.
//
// httplib settings that belong to its own socket loop (listen(), set_read_timeout,
// set_keep_alive_*, set_payload_max_length, new_task_queue) have no effect here: TransportLimits
// holds them. Use bind()/serve()/stop(). A Server serves once: after stop() it cannot serve again.

#include <httplib.h>

#include <condition_variable>
#include <cstddef>
#include <memory>
#include <mutex>
#include <string>

#include "devsurf/server/transport/Connection.h"
#include "devsurf/server/transport/Limits.h"

namespace devsurf::server::transport {

namespace detail {
struct ServerCore;  // asio side; server/src/transport/ServerCore.h
}

class Server : public httplib::Server {
 public:
  explicit Server(WebSocketHandlers handlers, TransportLimits limits = {});
  /// Calls stop().
  ~Server() override;

  Server(const Server&) = delete;
  Server& operator=(const Server&) = delete;

  /// Binds the listening socket; port 0 = ephemeral. Returns the bound port or throws
  /// std::runtime_error. Connections wait in the backlog until serve().
  int bind(const std::string& host, int port);

  /// Serves until stop() (blocking). Throws std::runtime_error if bind() was not called. Returns
  /// immediately if stop() was already called.
  void serve();

  /// Stops accepting; closes every WebSocket with 1001 "server shutting down" and every idle
  /// HTTP connection; lets requests in progress be answered (then closes their connections);
  /// waits at most TransportLimits::closeTimeout for all that, then drops the remaining TCP
  /// connections; waits for the route workers and joins the io threads; then serve() returns.
  /// After it returns, no WebSocket handler and no route runs any more. Idempotent and
  /// thread-safe; must not be called from a handler or a route.
  void stop();

  /// Open WebSocket connections (onOpen called, onClose not yet).
  std::size_t connectionCount() const;

  /// The port from bind(), or 0.
  int port() const { return port_; }

 private:
  std::shared_ptr<detail::ServerCore> core_;
  int port_ = 0;

  std::mutex serveMutex_;
  std::condition_variable serveCv_;
  bool serving_ = false;
  bool stopRequested_ = false;
  bool stopped_ = false;
  std::once_flag stopOnce_;
};

}  // namespace devsurf::server::transport
