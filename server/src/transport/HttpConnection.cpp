// The HTTP side of transport::Server, one connection at a time. See HttpConnection.h.
#include "transport/HttpConnection.h"

#include <boost/asio/dispatch.hpp>
#include <boost/asio/post.hpp>
#include <boost/asio/write.hpp>
#include <boost/beast/core/bind_handler.hpp>
#include <boost/beast/core/error.hpp>
#include <boost/beast/core/string.hpp>
#include <boost/beast/http/error.hpp>
#include <boost/beast/http/read.hpp>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <cstring>
#include <iterator>
#include <utility>

#if defined(__GLIBC__)
#include <malloc.h>
#endif

namespace devsurf::server::transport::detail {

namespace {

constexpr std::size_t kReadChunk = 16 * 1024;     // first read of a kept-alive request
constexpr std::size_t kDiscardChunk = 64 * 1024;  // reads of a graceful close
/// After a request with a body at least this large, freed heap memory is returned to the OS.
constexpr std::size_t kTrimAfterBodyBytes = 1u << 20;

/// One complete request for httplib's process_request: the re-serialized head, then the body;
/// everything httplib writes is appended to `out`. Reads never block, writes never fail.
class RequestStream final : public httplib::Stream {
 public:
  RequestStream(std::string head, const std::string& body, std::string& out,
                const std::string& remoteIp, int remotePort, const std::string& localIp,
                int localPort)
      : head_(std::move(head)),
        body_(body),
        out_(out),
        remoteIp_(remoteIp),
        localIp_(localIp),
        remotePort_(remotePort),
        localPort_(localPort) {}

  bool is_readable() const override {
    return headRead_ < head_.size() || bodyRead_ < body_.size();
  }
  bool is_writable() const override { return true; }

  ssize_t read(char* ptr, size_t size) override {
    size_t n = 0;
    if (headRead_ < head_.size()) {
      n = std::min(size, head_.size() - headRead_);
      std::memcpy(ptr, head_.data() + headRead_, n);
      headRead_ += n;
    } else if (bodyRead_ < body_.size()) {
      n = std::min(size, body_.size() - bodyRead_);
      std::memcpy(ptr, body_.data() + bodyRead_, n);
      bodyRead_ += n;
    }
    return static_cast<ssize_t>(n);
  }

  ssize_t write(const char* ptr, size_t size) override {
    out_.append(ptr, size);
    return static_cast<ssize_t>(size);
  }

  void get_remote_ip_and_port(std::string& ip, int& port) const override {
    ip = remoteIp_;
    port = remotePort_;
  }
  void get_local_ip_and_port(std::string& ip, int& port) const override {
    ip = localIp_;
    port = localPort_;
  }
  socket_t socket() const override { return INVALID_SOCKET; }

 private:
  const std::string head_;
  const std::string& body_;
  std::string& out_;
  const std::string& remoteIp_;
  const std::string& localIp_;
  const int remotePort_;
  const int localPort_;
  size_t headRead_ = 0;
  size_t bodyRead_ = 0;
};

/// The request line and fields for httplib: framing fields (Content-Length, Transfer-Encoding)
/// and Expect dropped, a Content-Length for the decoded body added.
std::string serializeHead(const HttpRequest& request) {
  std::string head;
  head.reserve(256);
  head.append(request.method_string().data(), request.method_string().size());
  head += ' ';
  head.append(request.target().data(), request.target().size());
  head += " HTTP/";
  head += std::to_string(request.version() / 10);
  head += '.';
  head += std::to_string(request.version() % 10);
  head += "\r\n";
  for (const auto& field : request) {
    const auto name = field.name();
    if (name == http::field::content_length || name == http::field::transfer_encoding ||
        name == http::field::expect) {
      continue;
    }
    if (name == http::field::content_type &&
        beast::iequals(field.value().substr(0, 33), "application/x-www-form-urlencoded")) {
      // Every body of the API is JSON; `curl -d` labels it form-urlencoded, which Debian's httplib
      // reads only up to a compiled-in 8 KiB (a 413 without a body). Passed on as bytes, so
      // --max-body is the only limit.
      head += "Content-Type: application/octet-stream\r\n";
      continue;
    }
    head.append(field.name_string().data(), field.name_string().size());
    head += ": ";
    head.append(field.value().data(), field.value().size());
    head += "\r\n";
  }
  if (request.has_content_length() || request.chunked() || !request.body().empty()) {
    head += "Content-Length: " + std::to_string(request.body().size()) + "\r\n";
  }
  head += "\r\n";
  return head;
}

bool isWebSocketRoute(const HttpRequest& request) {
  const auto target = request.target();
  return request.method() == http::verb::get &&
         (target == "/ws" || (target.size() > 3 && target.substr(0, 4) == "/ws?"));
}

bool isParseError(const beast::error_code& ec) {
  return ec.category() == http::make_error_code(http::error::bad_method).category();
}

std::string fieldText(const HttpRequest& request, http::field field) {
  const auto value = request[field];
  return std::string(value.data(), value.size());
}

void ipAndPort(const tcp::endpoint& endpoint, std::string& ip, int& port) {
  ip = unmappedAddress(endpoint.address()).to_string();
  port = endpoint.port();
}

}  // namespace

HttpConnection::HttpConnection(std::shared_ptr<ServerCore> core, tcp::socket socket,
                               std::uint64_t id, ConnectionSlot slot, std::string refusal)
    : core_(std::move(core)),
      executor_(socket.get_executor()),
      stream_(std::move(socket)),
      deadline_(executor_),
      id_(id),
      refused_(!slot),
      slot_(std::move(slot)),
      refusal_(std::move(refusal)) {
  beast::error_code ec;
  const auto remote = stream_.socket().remote_endpoint(ec);
  if (!ec) {
    remote_ = formatEndpoint(remote);
    ipAndPort(remote, remoteIp_, remotePort_);
  }
  const auto local = stream_.socket().local_endpoint(ec);
  if (!ec) ipAndPort(local, localIp_, localPort_);
}

void HttpConnection::start() {
  net::dispatch(executor_, [self = shared_from_this()] {
    if (self->refused_) {
      self->answer(503, "limit", self->refusal_);
      return;
    }
    self->awaitRequest(/*first=*/true);
  });
}

void HttpConnection::shutdown() {
  net::post(executor_, [self = shared_from_this()] {
    switch (self->phase_) {
      case Phase::Idle:
      case Phase::Head:
      case Phase::Body:
      case Phase::Closing:
        self->finish();
        break;
      case Phase::Routing:  // answered, then closed (see write())
      case Phase::Writing:
      case Phase::Done:
        break;
    }
  });
}

void HttpConnection::abort() {
  net::post(executor_, [self = shared_from_this()] { self->finish(); });
}

// ---- reading a request -------------------------------------------------------------------

void HttpConnection::armDeadline(std::chrono::milliseconds timeout) {
  deadlinePassed_ = false;
  const auto generation = ++deadlineGeneration_;
  deadline_.expires_after(timeout);
  deadline_.async_wait([self = shared_from_this(), generation](beast::error_code ec) {
    if (ec || self->phase_ == Phase::Done || generation != self->deadlineGeneration_) return;
    // Cancel the read; its handler answers 408. (tcp_stream's own timeout would close the
    // socket, leaving no way to answer.)
    self->deadlinePassed_ = true;
    self->stream_.cancel();
  });
}

void HttpConnection::disarmDeadline() {
  ++deadlineGeneration_;
  deadline_.cancel();
}

void HttpConnection::awaitRequest(bool first) {
  const auto& limits = core_->limits.http;
  parser_.emplace();
  parser_->header_limit(static_cast<std::uint32_t>(std::min<std::size_t>(limits.maxHeaderBytes, UINT32_MAX)));
  parser_->body_limit(limits.maxBodyBytes);
  if (buffer_.capacity() > 4 * kDiscardChunk) buffer_.shrink_to_fit();
  if (first || buffer_.size() > 0) {
    // The first request's deadline runs from the accept; a pipelined request has begun already.
    stream_.expires_never();
    armDeadline(limits.headerTimeout);
    readHead();
    return;
  }
  phase_ = Phase::Idle;
  stream_.expires_after(limits.keepAliveTimeout);
  stream_.async_read_some(
      buffer_.prepare(kReadChunk),
      beast::bind_front_handler(&HttpConnection::onFirstBytes, shared_from_this()));
}

void HttpConnection::onFirstBytes(beast::error_code ec, std::size_t bytes) {
  if (phase_ == Phase::Done) return;
  if (ec) {  // idle too long, or the client closed its kept-alive connection
    finish();
    return;
  }
  buffer_.commit(bytes);
  stream_.expires_never();
  armDeadline(core_->limits.http.headerTimeout);
  readHead();
}

void HttpConnection::readHead() {
  phase_ = Phase::Head;
  http::async_read_header(stream_, buffer_, *parser_,
                          beast::bind_front_handler(&HttpConnection::onHead, shared_from_this()));
}

void HttpConnection::onHead(beast::error_code ec, std::size_t) {
  if (phase_ == Phase::Done) return;
  if (ec) {
    onReadError(ec, "head");
    return;
  }
  if (tooManyFields()) return;
  const HttpRequest& request = parser_->get();
  if (!parser_->is_done()) {
    const std::string encoding = fieldText(request, http::field::content_encoding);
    if (!encoding.empty() && !beast::iequals(encoding, "identity")) {
      answer(415, "unsupported", "Content-Encoding " + encoding.substr(0, 32) +
                                     " is not accepted on request bodies");
      return;
    }
    if (beast::iequals(fieldText(request, http::field::expect), "100-continue")) {
      static const std::string kContinue = "HTTP/1.1 100 Continue\r\n\r\n";
      phase_ = Phase::Body;
      disarmDeadline();
      stream_.expires_after(core_->limits.http.writeTimeout);
      net::async_write(stream_, net::buffer(kContinue),
                       [self = shared_from_this()](beast::error_code writeEc, std::size_t) {
                         if (self->phase_ == Phase::Done) return;
                         if (writeEc) {
                           self->finish();
                           return;
                         }
                         self->readBody();
                       });
      return;
    }
  }
  readBody();
}

void HttpConnection::readBody() {
  phase_ = Phase::Body;
  if (parser_->is_done()) {
    onBody({}, 0);
    return;
  }
  stream_.expires_never();
  armDeadline(core_->limits.http.bodyTimeout);
  http::async_read(stream_, buffer_, *parser_,
                   beast::bind_front_handler(&HttpConnection::onBody, shared_from_this()));
}

void HttpConnection::onBody(beast::error_code ec, std::size_t) {
  if (phase_ == Phase::Done) return;
  if (ec) {
    onReadError(ec, "body");
    return;
  }
  disarmDeadline();
  if (tooManyFields()) return;  // trailer fields of a chunked body count too
  ++served_;
  if (isWebSocketRoute(parser_->get())) {
    if (core_->stoppingFlag) {
      answer(503, "limit", "server shutting down");
      return;
    }
    if (buffer_.size() > 0) {
      // A client must wait for the 101 before it sends frames (RFC 6455 §4.1).
      spdlog::debug("transport: {} sent {} bytes after its upgrade request; dropped", remote_,
                    buffer_.size());
    }
    phase_ = Phase::Done;
    auto request = parser_->release();
    parser_.reset();
    startWebSocket(core_, std::move(stream_), std::move(slot_), std::move(request), remote_);
    core_->removeHttp(id_);
    return;
  }
  route();
}

void HttpConnection::onReadError(beast::error_code ec, const char* what) {
  const auto& limits = core_->limits.http;
  const bool bodyPart = std::strcmp(what, "body") == 0;
  if (deadlinePassed_ && ec == net::error::operation_aborted) {
    if (!bodyPart && !parser_->got_some() && buffer_.size() == 0) {
      finish();  // nothing of a request arrived: just close
      return;
    }
    const auto ms = (bodyPart ? limits.bodyTimeout : limits.headerTimeout).count();
    answer(408, "timeout", std::string("the request ") + what + " did not arrive within " +
                               std::to_string(ms) + " ms");
    return;
  }
  if (ec == http::error::header_limit) {
    answer(431, "too_large", "request head larger than " + std::to_string(limits.maxHeaderBytes) +
                                 " bytes");
    return;
  }
  if (ec == http::error::body_limit) {
    parser_.reset();  // frees what was read of the body
    core_->trimMemorySoon();
    answer(413, "too_large",
           "request body larger than " + std::to_string(limits.maxBodyBytes) + " bytes");
    return;
  }
  if (ec != http::error::end_of_stream && ec != http::error::partial_message &&
      isParseError(ec)) {
    answer(400, "invalid", std::string("malformed HTTP request ") + what + ": " + ec.message());
    return;
  }
  finish();  // the client closed or reset the connection
}

bool HttpConnection::tooManyFields() {
  const auto& request = parser_->get();
  const auto count = static_cast<std::size_t>(std::distance(request.begin(), request.end()));
  const auto limit = core_->limits.http.maxHeaderFields;
  if (count <= limit) return false;
  answer(431, "too_large", "request has " + std::to_string(count) + " header fields (limit " +
                               std::to_string(limit) + ")");
  return true;
}

// ---- routing -----------------------------------------------------------------------------

void HttpConnection::route() {
  auto request = std::make_shared<HttpRequest>(parser_->release());
  parser_.reset();
  const bool closeAfter = !request->keep_alive() || core_->stoppingFlag ||
                          served_ >= core_->limits.http.maxRequestsPerConnection;
  phase_ = Phase::Routing;
  auto self = shared_from_this();
  if (!core_->runOnWorker([self, request, closeAfter] { self->runRoutes(request, closeAfter); })) {
    finish();  // stopping
  }
}

void HttpConnection::runRoutes(const std::shared_ptr<HttpRequest>& request, bool closeAfter) {
  // On a route worker: nothing of the strand's state is touched here.
  auto response = std::make_shared<std::string>();
  bool close = closeAfter;
  const std::size_t bodyBytes = request->body().size();
  try {
    RequestStream in(serializeHead(*request), request->body(), *response, remoteIp_, remotePort_,
                     localIp_, localPort_);
    close = core_->runRoutes(in, closeAfter);
  } catch (const std::exception& e) {
    spdlog::error("transport: request from {} failed: {}", remote_, e.what());
    response->clear();
  }
  if (response->empty()) {
    *response = errorResponse(500, "internal", "the request could not be processed");
    if (core_->handlers.onRefused) core_->handlers.onRefused("internal");
    close = true;
  }
  HttpRequest().swap(*request);  // free the body here, not on an io thread
#if defined(__GLIBC__)
  if (bodyBytes >= kTrimAfterBodyBytes) ::malloc_trim(0);
#endif
  net::post(executor_, [self = shared_from_this(), response, close] {
    if (self->phase_ == Phase::Done) return;
    self->write(response, close);
  });
}

// ---- writing -----------------------------------------------------------------------------

void HttpConnection::write(std::shared_ptr<const std::string> response, bool closeAfter) {
  phase_ = Phase::Writing;
  stream_.expires_after(core_->limits.http.writeTimeout);
  net::async_write(stream_, net::buffer(*response),
                   [self = shared_from_this(), response, closeAfter](beast::error_code ec,
                                                                     std::size_t) {
                     if (self->phase_ == Phase::Done) return;
                     if (ec) {  // write deadline passed, or the client went away
                       self->finish();
                       return;
                     }
                     if (self->core_->stoppingFlag) {
                       self->finish();
                       return;
                     }
                     if (closeAfter) {
                       self->closeGracefully();
                       return;
                     }
                     self->awaitRequest(/*first=*/false);
                   });
}

void HttpConnection::answer(int status, const std::string& code, const std::string& message) {
  spdlog::debug("transport: {} answered {} ({})", remote_.empty() ? "?" : remote_, status,
                message);
  disarmDeadline();
  parser_.reset();
  if (core_->handlers.onRefused) core_->handlers.onRefused(code);
  write(std::make_shared<const std::string>(errorResponse(status, code, message)),
        /*closeAfter=*/true);
}

void HttpConnection::closeGracefully() {
  phase_ = Phase::Closing;
  beast::error_code ignored;
  stream_.socket().shutdown(tcp::socket::shutdown_send, ignored);
  stream_.expires_after(core_->limits.closeTimeout);
  buffer_.clear();
  buffer_.shrink_to_fit();
  discard_ = std::make_unique<char[]>(kDiscardChunk);
  discardInput();
}

void HttpConnection::discardInput() {
  stream_.async_read_some(net::buffer(discard_.get(), kDiscardChunk),
                          [self = shared_from_this()](beast::error_code ec, std::size_t) {
                            if (self->phase_ == Phase::Done) return;
                            if (ec) {  // end of stream, or closeTimeout
                              self->finish();
                              return;
                            }
                            self->discardInput();
                          });
}

void HttpConnection::finish() {
  if (phase_ == Phase::Done) return;
  phase_ = Phase::Done;
  disarmDeadline();
  beast::error_code ignored;
  stream_.socket().shutdown(tcp::socket::shutdown_both, ignored);
  stream_.close();
  parser_.reset();
  discard_.reset();
  slot_.release();
  if (refused_) {
    std::lock_guard<std::mutex> lk(core_->mutex);
    if (core_->refusing > 0) --core_->refusing;
  }
  core_->removeHttp(id_);
}

}  // namespace devsurf::server::transport::detail
