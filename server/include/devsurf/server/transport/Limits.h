#pragma once
// Limits of the transport layer (transport::Server): HTTP requests and connections, WebSockets.
// Every limit has a documented default; `devsurf serve` exposes them as flags (docs/protocol.md,
// "Limits"). Where a limit answers, it answers with a status and a JSON body
// {"error":{"code","message"}} (see HttpLimits).

#include <chrono>
#include <cstddef>

namespace devsurf::server::transport {

/// HTTP side: every request, including the WebSocket upgrade request.
///
/// Answers (the connection is closed after each of them):
///   503 `limit`      more than maxConnections open, or maxConnectionsPerAddress from one address
///   431 `too_large`  request head over maxHeaderBytes, or more than maxHeaderFields fields
///   413 `too_large`  body over maxBodyBytes, by Content-Length (at once) or while a chunked body
///                    is read (as soon as it crosses the limit; the rest is never buffered)
///   408 `timeout`    the head (headerTimeout) or the body (bodyTimeout) did not arrive in time;
///                    a connection that sent nothing of its request is closed without an answer
///   415 `unsupported` a Content-Encoding on the request body (it would bypass maxBodyBytes)
///   400 `invalid`    a request head that is not HTTP/1.x
struct HttpLimits {
  /// Open TCP connections of any kind (HTTP and WebSocket). More: 503 and close.
  std::size_t maxConnections = 1024;
  /// Open TCP connections from one peer IP address. More: 503 and close. A classroom behind one
  /// NAT address (a browser tab holds one WebSocket and a few HTTP connections) fits in 256; raise
  /// it for larger ones behind a single address.
  std::size_t maxConnectionsPerAddress = 256;
  /// Request line and header fields together, in bytes.
  std::size_t maxHeaderBytes = 16 * 1024;
  /// Header fields of one request (trailer fields of a chunked body count too).
  std::size_t maxHeaderFields = 100;
  /// Request body after chunked decoding, in bytes.
  std::size_t maxBodyBytes = 16u << 20;
  /// The whole request head must arrive within this, counted from the connection's accept (first
  /// request) or from the first byte of the request (later requests on a kept-alive connection).
  std::chrono::milliseconds headerTimeout{10000};
  /// The whole body must arrive within this, counted from the end of the head.
  std::chrono::milliseconds bodyTimeout{60000};
  /// A kept-alive connection waiting for its next request is closed after this.
  std::chrono::milliseconds keepAliveTimeout{5000};
  /// Writing one whole response must finish within this, or the connection is dropped (a client
  /// that does not read holds no worker, only its buffered response).
  std::chrono::milliseconds writeTimeout{30000};
  /// Requests served on one kept-alive connection; the last one is answered with
  /// "Connection: close".
  std::size_t maxRequestsPerConnection = 100;
  /// Threads that run the routes (httplib handlers) on complete, buffered requests.
  int workers = 8;
};

struct TransportLimits {
  std::size_t maxMessageBytes = 1 << 20;  // larger incoming messages: close 1009 with a reason
  std::size_t maxQueuedBytes = 8 << 20;   // outgoing backlog per connection (see send())
  std::size_t maxQueuedMessages = 4096;
  int ioThreads = 2;                      // threads of the io_context (all socket I/O; at least 1)
  /// Writing the 101 response of a WebSocket upgrade (the upgrade request itself is read under
  /// HttpLimits::headerTimeout).
  std::chrono::milliseconds handshakeTimeout{10000};
  /// Flush + closing handshake of close(), and the grace period of Server::stop(); after it the
  /// TCP connection is dropped. Also how long an HTTP connection closed after an error answer
  /// keeps reading (and discarding) what the client still sends, so that it sees the answer.
  std::chrono::milliseconds closeTimeout{5000};
  /// No data from the client for half of this: ping; for all of it: drop. 0 = never.
  std::chrono::milliseconds idleTimeout{60000};
  HttpLimits http;
};

}  // namespace devsurf::server::transport
