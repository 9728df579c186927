#pragma once
// Small synchronous WebSocket client (tests, CLI). Not thread-safe: use one Client from one
// thread. Network I/O happens only inside its calls: once receive() has been called, frames
// that arrive while send()/receive() run are read and kept in an inbox; before the first
// receive() nothing is read (so a test can play a client that never reads). Pings are answered
// only while a call runs: a long-lived client should call receive() at least every
// TransportLimits::idleTimeout / 2, or the server drops it as idle.

#include <chrono>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>

namespace devsurf::server::transport {

struct CloseInfo {
  std::uint16_t code = 0;
  std::string reason;
};

class Client {
 public:
  Client();
  ~Client();  // closes the TCP connection (no closing handshake)
  Client(const Client&) = delete;
  Client& operator=(const Client&) = delete;

  /// Connects and performs the WebSocket handshake. Throws std::runtime_error on failure; if the
  /// server answered with an HTTP status other than 101 the message contains "HTTP <status>"
  /// and httpStatus() returns it.
  void connect(const std::string& host, int port, const std::string& target = "/ws",
               std::chrono::milliseconds timeout = std::chrono::seconds(5));

  /// Sends one text message (one frame). Throws std::runtime_error if the connection is
  /// closed or the write does not finish within `timeout`.
  void send(const std::string& text,
            std::chrono::milliseconds timeout = std::chrono::seconds(10));
  /// Sends one binary frame (the server rejects these; for tests).
  void sendBinary(const std::string& data,
                  std::chrono::milliseconds timeout = std::chrono::seconds(10));

  /// Next text message, or nullopt on timeout or when the connection is closed (see
  /// isOpen()/closeInfo()).
  std::optional<std::string> receive(std::chrono::milliseconds timeout);

  /// Closing handshake (waits at most `timeout`, discarding unread messages), then closes TCP.
  void close(std::uint16_t code = 1000, const std::string& reason = {},
             std::chrono::milliseconds timeout = std::chrono::seconds(5));

  /// Drops the TCP connection without a closing handshake (RST).
  void abort();

  bool isOpen() const;
  /// The close frame received from the server, if any.
  std::optional<CloseInfo> closeInfo() const;
  /// HTTP status of the handshake response (101 on success), 0 if none was received.
  int httpStatus() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace devsurf::server::transport
