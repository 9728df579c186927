#pragma once
// WebSocket connection interface of the transport layer (no Beast or httplib types here).
//
// Conventions
//  * Only text frames carry messages (UTF-8 JSON by convention of the protocol layer). A binary
//    frame from a client closes the connection with 1003, a message larger than
//    TransportLimits::maxMessageBytes with 1009; both closes carry a human-readable reason.
//  * Handlers run on the transport's io threads. Different connections may be served
//    concurrently, but for ONE connection all handler calls are sequential and ordered:
//    onOpen, then onMessage in arrival order, then onClose exactly once. A handler must return
//    quickly (post real work elsewhere): while it runs, no other frame of that connection is read
//    and it occupies one of the few io threads. Never call Server::stop() from a handler.
//  * Connection methods are thread-safe and never block; the Connection object stays valid for
//    as long as someone holds the shared_ptr (after close, send() is simply ignored).

#include <chrono>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>

#include "devsurf/server/transport/Limits.h"

namespace devsurf::server::transport {

/// WebSocket close status codes used by the transport (RFC 6455 §7.4.1).
struct CloseCode {
  static constexpr std::uint16_t Normal = 1000;
  static constexpr std::uint16_t GoingAway = 1001;        // server shutting down
  static constexpr std::uint16_t ProtocolError = 1002;
  static constexpr std::uint16_t UnsupportedData = 1003;  // binary frame received
  static constexpr std::uint16_t PolicyViolation = 1008;  // client too slow (backlog overflow)
  static constexpr std::uint16_t MessageTooBig = 1009;
  static constexpr std::uint16_t InternalError = 1011;
  static constexpr std::uint16_t ServiceRestart = 1012;   // the session moved to another daemon
  static constexpr std::uint16_t TryAgainLater = 1013;    // the session is held by another daemon
};

enum class Delivery {
  /// Always delivered (unless the connection closes), in send() order.
  Reliable,
  /// May be replaced by a newer message with the same non-empty key while it is still queued
  /// (not yet being written). With an empty key it behaves like Reliable.
  Latest,
};

/// One open WebSocket connection. Thread-safe; shared_ptr-owned by the transport and by whoever
/// keeps a copy.
class Connection {
 public:
  virtual ~Connection() = default;

  /// Unique per Server instance, starting at 1.
  virtual std::uint64_t id() const = 0;
  /// "ip:port" of the peer ("[v6]:port" for IPv6).
  virtual std::string remoteAddress() const = 0;
  /// Request target of the upgrade request, e.g. "/ws" or "/ws?session=3".
  virtual std::string target() const = 0;

  /// Queues a text frame; never blocks. Delivered messages are always a subsequence of the
  /// send() order. A Latest message with a non-empty key removes a queued, not-yet-written
  /// message with the same key and is appended at the end (a slow client gets the newest
  /// iterate, never an unbounded backlog). If the backlog of queued messages then exceeds
  /// maxQueuedBytes (only counted when more than one message is queued) or maxQueuedMessages,
  /// the queue is dropped and the connection is closed with 1008 "client too slow".
  /// Ignored once the connection is closing or closed.
  virtual void send(std::string text, Delivery delivery = Delivery::Reliable,
                    std::string key = {}) = 0;

  /// Starts the closing handshake after the queued messages have been written. If that
  /// (flush + handshake) takes longer than TransportLimits::closeTimeout, the TCP connection is
  /// dropped. Idempotent; the reason is truncated to 123 bytes.
  virtual void close(std::uint16_t code = CloseCode::Normal, std::string reason = {}) = 0;

  /// True from onOpen until a close was requested (by either side) or the connection failed.
  virtual bool isOpen() const = 0;

  /// Bytes of queued, not-yet-written messages (the message being written is not counted).
  virtual std::size_t queuedBytes() const = 0;
  virtual std::size_t queuedMessages() const = 0;
};

struct WebSocketHandlers {
  /// After the handshake; send() may be called from here.
  std::function<void(const std::shared_ptr<Connection>&)> onOpen;
  /// One complete text message; sequential and in order for one connection. Messages that
  /// arrive after a close was requested (isOpen() == false) are discarded.
  std::function<void(const std::shared_ptr<Connection>&, std::string message)> onMessage;
  /// Exactly once per opened connection, whatever ended it (close frame from either side,
  /// TCP drop, protocol error, Server::stop()).
  std::function<void(const std::shared_ptr<Connection>&)> onClose;
  /// The transport answered a request itself with an error (431, 413, 408, 415, 400, 503, 500),
  /// before any route saw it: its code ("too_large", "timeout", "limit", …), for the metrics.
  std::function<void(const std::string& code)> onRefused;
};

}  // namespace devsurf::server::transport
