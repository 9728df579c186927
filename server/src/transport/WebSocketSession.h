#pragma once
// Private to devsurf_transport: one WebSocket connection (Boost.Beast stream on a strand of the
// core's io_context). Created by an HTTP connection that has read a complete "GET /ws" request
// (startWebSocket in ServerCore.h); answers the upgrade with async_accept(request).
//
// Threading: everything except the Connection interface and start/shutdown/abort runs on the
// strand. The outgoing queue and the state are guarded by mutex_ (send() is called from any
// thread).

#include <boost/beast/websocket.hpp>

#include <atomic>
#include <list>
#include <mutex>
#include <optional>
#include <string>
#include <unordered_map>

#include "transport/ServerCore.h"

namespace devsurf::server::transport::detail {

namespace websocket = beast::websocket;

class WebSocketSession final : public Connection,
                               public std::enable_shared_from_this<WebSocketSession> {
 public:
  WebSocketSession(std::shared_ptr<ServerCore> core, beast::tcp_stream stream, std::uint64_t id,
                   std::string remote, ConnectionSlot slot, HttpRequest request);

  std::uint64_t id() const override { return id_; }
  std::string remoteAddress() const override { return remote_; }
  std::string target() const override { return target_; }
  void send(std::string text, Delivery delivery, std::string key) override;
  void close(std::uint16_t code, std::string reason) override;
  bool isOpen() const override;
  std::size_t queuedBytes() const override;
  std::size_t queuedMessages() const override;

  /// Any thread: answer the upgrade request.
  void start();
  /// Any thread: server stopping. Open connections get 1001 (queue dropped); a connection still
  /// in its handshake is dropped.
  void shutdown();
  /// Any thread: drop the TCP connection now.
  void abort();
  /// Only after the io threads stopped, on the stopping thread: finishes the session if it is
  /// not finished and destroys the Beast stream, and with it every handler Beast parked inside it
  /// (a read waiting for a close or write that will never complete holds this session, which
  /// holds the core, which owns the io_context: a cycle LeakSanitizer reported at exit). Every
  /// strand handler returns on `finished_` before touching the stream, so none runs after this.
  void dropStream();

 private:
  enum class State { Handshake, Open, Closing, Finished };
  struct Outgoing {
    std::string text;
    std::string key;  // non-empty: coalescable (Latest)
  };
  static constexpr std::size_t kReadChunk = 64 * 1024;

  void accept();
  void reject(int status, const std::string& code, const std::string& message);
  void onAccept(beast::error_code ec);
  void readNext();
  void onRead(beast::error_code ec, std::size_t);
  void writeNext();
  void onWrite(beast::error_code ec, std::size_t);
  void requestClose(std::uint16_t code, std::string reason, bool dropQueue);
  std::optional<bool> closeLocked(std::uint16_t code, std::string reason, bool dropQueue);
  void postClose(bool kick);
  void armCloseTimer();
  void finish(beast::error_code ec);
  void dropQueueLocked();

  const std::shared_ptr<ServerCore> core_;
  std::optional<websocket::stream<beast::tcp_stream>> ws_;  // empty after dropStream()
  net::steady_timer timer_;
  const std::uint64_t id_;
  const std::string remote_;
  const std::string target_;
  ConnectionSlot slot_;
  HttpRequest request_;  // the upgrade request, until async_accept completes

  // strand only
  beast::flat_buffer buffer_;
  std::string inFlight_;
  bool opened_ = false;
  bool timerArmed_ = false;
  std::atomic<bool> finished_{false};  // written on the strand; read under mutex_ in writeNext

  mutable std::mutex mutex_;
  State state_ = State::Handshake;
  std::list<Outgoing> queue_;
  std::unordered_map<std::string, std::list<Outgoing>::iterator> byKey_;
  std::size_t queuedBytes_ = 0;
  bool writing_ = false;  // a writeNext/async_write/async_close chain is active
  std::optional<websocket::close_reason> closeRequest_;
  bool closeStarted_ = false;
};

}  // namespace devsurf::server::transport::detail
