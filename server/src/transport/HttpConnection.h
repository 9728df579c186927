#pragma once
// Private to devsurf_transport: one accepted TCP connection on the HTTP side of
// transport::Server, served asynchronously on a strand of the core's io_context.
//
// Life of a request (every step under a deadline of HttpLimits, none holding a thread):
//   1. the head is read (Beast parser; header size limit, then a field count check),
//   2. the body is read and decoded (Content-Length or chunked, body size limit; an
//      "Expect: 100-continue" is answered first),
//   3. a complete "GET /ws" request goes to a WebSocketSession (startWebSocket); any other
//      complete request is run on a route worker: re-serialized without its framing (a
//      Content-Length for the decoded body) and fed to httplib's process_request through an
//      in-memory httplib::Stream, which collects the whole response,
//   4. the buffered response is written back, then the connection waits for the next request
//      (keep-alive) or closes.
// A limit that answers (431, 413, 408, 415, 400, 503) writes a JSON error and closes gracefully:
// it stops sending, then reads and discards what the client still sends (at most
// TransportLimits::closeTimeout) so that the client sees the answer before the close.

#include <boost/beast/core/flat_buffer.hpp>
#include <boost/beast/http/parser.hpp>

#include <chrono>
#include <memory>
#include <optional>
#include <string>

#include "transport/ServerCore.h"

namespace devsurf::server::transport::detail {

class HttpConnection final : public std::enable_shared_from_this<HttpConnection> {
 public:
  /// `slot` empty: the connection was refused (a connection cap); it is answered 503 with
  /// `refusal` and closed.
  HttpConnection(std::shared_ptr<ServerCore> core, tcp::socket socket, std::uint64_t id,
                 ConnectionSlot slot, std::string refusal);

  std::uint64_t id() const { return id_; }

  /// Any thread: start serving.
  void start();
  /// Any thread: server stopping. A connection waiting for or reading a request is closed; a
  /// request being routed or answered is finished first, then the connection closes.
  void shutdown();
  /// Any thread: drop the TCP connection now.
  void abort();

 private:
  enum class Phase { Idle, Head, Body, Routing, Writing, Closing, Done };

  /// Reading the head or the body must end by `timeout` (a timer that cancels the read, so that
  /// its handler can still answer 408).
  void armDeadline(std::chrono::milliseconds timeout);
  void disarmDeadline();
  void awaitRequest(bool first);
  void onFirstBytes(beast::error_code ec, std::size_t bytes);
  void readHead();
  void onHead(beast::error_code ec, std::size_t);
  void readBody();
  void onBody(beast::error_code ec, std::size_t);
  /// A parse or read error of the head or body: answers or closes. `what` names the part.
  void onReadError(beast::error_code ec, const char* what);
  bool tooManyFields();
  void route();
  void runRoutes(const std::shared_ptr<HttpRequest>& request, bool closeAfter);
  void write(std::shared_ptr<const std::string> response, bool closeAfter);
  void answer(int status, const std::string& code, const std::string& message);
  void closeGracefully();
  void discardInput();
  void finish();

  const std::shared_ptr<ServerCore> core_;
  const beast::tcp_stream::executor_type executor_;  // the connection's strand
  beast::tcp_stream stream_;  // moved to a WebSocketSession for an upgrade
  net::steady_timer deadline_;
  const std::uint64_t id_;
  const bool refused_;
  ConnectionSlot slot_;
  const std::string refusal_;
  std::string remote_;  // "ip:port"
  std::string remoteIp_, localIp_;
  int remotePort_ = 0, localPort_ = 0;

  // strand only
  beast::flat_buffer buffer_;
  std::optional<http::request_parser<http::string_body>> parser_;
  std::size_t served_ = 0;
  Phase phase_ = Phase::Idle;
  bool deadlinePassed_ = false;
  std::uint64_t deadlineGeneration_ = 0;
  std::unique_ptr<char[]> discard_;
};

}  // namespace devsurf::server::transport::detail
