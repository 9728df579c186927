#pragma once
// One TCP port for REST (cpp-httplib routes), static files (set_mount_point) and a WebSocket
// endpoint at /ws (Boost.Beast, hidden in the .cpp).
//
// Usage:
//   transport::Server server(handlers, limits);
//   server.Get("/api/health", ...);                    // plain httplib::Server API for REST
//   server.set_mount_point("/", webRoot);              // static files; httplib rejects "../"
//   int port = server.bind("127.0.0.1", 0);            // 0 = ephemeral
//   std::thread t([&] { server.serve(); });            // blocks until stop()
//   ...
//   server.stop();  t.join();                           // or just destroy the server
//
// Routing: a request whose request line starts with "GET /ws " or "GET /ws?" is a WebSocket
// upgrade (the path /ws, with any query, is reserved); everything else, including "GET /wsx",
// "GET /ws/…" and any other method on /ws, is served by httplib as usual. This also holds for a
// later request on a kept-alive HTTP connection.
//
// How it works: httplib's accept loop hands each accepted socket to a worker thread which calls
// the private virtual process_and_close_socket(); this class overrides it. The override keeps
// httplib's keep-alive loop (re-created around the protected process_request(), because the base
// implementation is private and not callable), and before each request peeks (recv MSG_PEEK) at
// the request line. For /ws it gives the fd to a Beast stream on the transport's own io_context
// and returns at once, without closing it; the worker is free again. Beast then reads the
// upgrade request itself.
//
// Threads: REST and static files run on httplib's worker pool (as with a plain httplib::Server);
// WebSocket I/O and the WebSocketHandlers run on TransportLimits::ioThreads threads of the
// transport's own io_context, each connection on its own strand (see Connection.h).
//
// Use bind()/serve()/stop() rather than httplib's listen()/stop(). A Server serves once: after
// stop() it cannot serve again.

#include <httplib.h>

#include <condition_variable>
#include <cstddef>
#include <memory>
#include <mutex>
#include <string>

#include "devsurf/server/transport/Connection.h"

namespace devsurf::server::transport {

namespace detail {
struct ServerCore;  // Beast/io_context side; defined in Server.cpp
}

class Server : public httplib::Server {
 public:
  explicit Server(WebSocketHandlers handlers, TransportLimits limits = {});
  /// Calls stop().
  ~Server() override;

  Server(const Server&) = delete;
  Server& operator=(const Server&) = delete;

  /// Binds the listening socket; port 0 = ephemeral. Returns the bound port or throws
  /// std::runtime_error.
  int bind(const std::string& host, int port);

  /// Serves until stop() (blocking). Throws std::runtime_error if bind() was not called. Returns
  /// immediately if stop() was already called.
  void serve();

  /// Stops accepting, closes every WebSocket with 1001 "server shutting down" (waiting at most
  /// TransportLimits::closeTimeout for the closing handshakes, then dropping the TCP
  /// connections), stops httplib (waits for serve() to return) and joins the io threads.
  /// After it returns, no WebSocket handler runs any more. Idempotent and thread-safe; must not
  /// be called from a handler.
  void stop();

  /// Open WebSocket connections (onOpen called, onClose not yet).
  std::size_t connectionCount() const;

  /// The port from bind(), or 0.
  int port() const { return port_; }

 private:
  // httplib 0.11.4 declares this private virtual; overriding it is allowed.
  bool process_and_close_socket(socket_t sock) override;

  std::shared_ptr<detail::ServerCore> core_;
  int port_ = 0;

  std::mutex serveMutex_;
  std::condition_variable serveCv_;
  bool serving_ = false;
  bool stopRequested_ = false;
  std::once_flag stopOnce_;
};

}  // namespace devsurf::server::transport
