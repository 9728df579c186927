// One WebSocket connection of transport::Server. See WebSocketSession.h.
#include "transport/WebSocketSession.h"

#include <boost/asio/dispatch.hpp>
#include <boost/asio/post.hpp>
#include <boost/beast/core/bind_handler.hpp>
#include <boost/beast/core/buffers_to_string.hpp>
#include <boost/beast/http/write.hpp>
#include <spdlog/spdlog.h>

#include <utility>

namespace devsurf::server::transport::detail {

WebSocketSession::WebSocketSession(std::shared_ptr<ServerCore> core, beast::tcp_stream stream,
                                   std::uint64_t id, std::string remote, ConnectionSlot slot,
                                   HttpRequest request)
    : core_(std::move(core)),
      ws_(std::in_place, std::move(stream)),
      timer_(ws_->get_executor()),
      id_(id),
      remote_(std::move(remote)),
      target_(request.target()),
      slot_(std::move(slot)),
      request_(std::move(request)) {}

void WebSocketSession::send(std::string text, Delivery delivery, std::string key) {
  bool kick = false;
  std::optional<bool> overflowKick;  // set when this message overflowed the backlog
  std::size_t count = 0;
  std::size_t bytes = 0;
  {
    std::lock_guard<std::mutex> lk(mutex_);
    if (state_ != State::Open) return;
    const bool coalesce = delivery == Delivery::Latest && !key.empty();
    if (coalesce) {
      auto it = byKey_.find(key);
      if (it != byKey_.end()) {
        queuedBytes_ -= it->second->text.size();
        queue_.erase(it->second);
        byKey_.erase(it);
      }
    }
    queuedBytes_ += text.size();
    queue_.push_back(Outgoing{std::move(text), coalesce ? std::move(key) : std::string()});
    if (coalesce) byKey_.emplace(queue_.back().key, std::prev(queue_.end()));
    const auto& limits = core_->limits;
    if (queue_.size() > limits.maxQueuedMessages ||
        (queue_.size() > 1 && queuedBytes_ > limits.maxQueuedBytes)) {
      // Decide and drop under the same lock, or the writer could drain the queue in between.
      count = queue_.size();
      bytes = queuedBytes_;
      overflowKick = closeLocked(CloseCode::PolicyViolation, "client too slow", true);
    } else if (!writing_) {
      writing_ = true;
      kick = true;
    }
  }
  if (overflowKick) {
    spdlog::warn("transport: WebSocket #{} ({}) too slow ({} messages, {} bytes queued); closing",
                 id_, remote_, count, bytes);
    postClose(*overflowKick);
    return;
  }
  if (kick) net::post(timer_.get_executor(), [self = shared_from_this()] { self->writeNext(); });
}

void WebSocketSession::close(std::uint16_t code, std::string reason) {
  requestClose(code, std::move(reason), /*dropQueue=*/false);
}

bool WebSocketSession::isOpen() const {
  std::lock_guard<std::mutex> lk(mutex_);
  return state_ == State::Open;
}

std::size_t WebSocketSession::queuedBytes() const {
  std::lock_guard<std::mutex> lk(mutex_);
  return queuedBytes_;
}

std::size_t WebSocketSession::queuedMessages() const {
  std::lock_guard<std::mutex> lk(mutex_);
  return queue_.size();
}

void WebSocketSession::start() {
  net::dispatch(timer_.get_executor(), [self = shared_from_this()] { self->accept(); });
}

void WebSocketSession::shutdown() {
  net::post(timer_.get_executor(), [self = shared_from_this()] {
    if (self->finished_) return;
    if (!self->opened_) {
      self->finish(net::error::operation_aborted);
      return;
    }
    self->requestClose(CloseCode::GoingAway, "server shutting down", /*dropQueue=*/true);
  });
}

void WebSocketSession::abort() {
  net::post(timer_.get_executor(),
            [self = shared_from_this()] { self->finish(net::error::operation_aborted); });
}

// ---- handshake ---------------------------------------------------------------------------

void WebSocketSession::accept() {
  if (finished_) return;
  if (core_->stoppingFlag) {
    reject(503, "limit", "server shutting down");
    return;
  }
  const auto& limits = core_->limits;
  websocket::stream_base::timeout opt{};
  opt.handshake_timeout = limits.handshakeTimeout;
  opt.idle_timeout = limits.idleTimeout.count() > 0
                         ? websocket::stream_base::duration(limits.idleTimeout)
                         : websocket::stream_base::none();
  opt.keep_alive_pings = true;
  beast::get_lowest_layer(*ws_).expires_never();  // Beast's websocket timeouts take over
  ws_->set_option(opt);
  ws_->set_option(websocket::stream_base::decorator(
      [](websocket::response_type& res) { res.set(http::field::server, "devsurf"); }));
  ws_->read_message_max(0);  // enforced by onRead, so the close carries a reason
  ws_->auto_fragment(false);
  ws_->async_accept(request_,
                   beast::bind_front_handler(&WebSocketSession::onAccept, shared_from_this()));
}

void WebSocketSession::reject(int status, const std::string& code, const std::string& message) {
  if (core_->handlers.onRefused) core_->handlers.onRefused(code);
  auto response = std::make_shared<std::string>(errorResponse(status, code, message));
  auto& stream = beast::get_lowest_layer(*ws_);
  stream.expires_after(core_->limits.http.writeTimeout);
  net::async_write(stream, net::buffer(*response),
                   [self = shared_from_this(), response](beast::error_code ec, std::size_t) {
                     self->finish(ec);
                   });
}

void WebSocketSession::onAccept(beast::error_code ec) {
  if (finished_) return;
  HttpRequest().swap(request_);
  if (ec) {  // Beast has answered with 400/426 already
    spdlog::debug("transport: WebSocket handshake from {} failed: {}", remote_, ec.message());
    finish(ec);
    return;
  }
  if (core_->stoppingFlag) {
    finish(net::error::operation_aborted);
    return;
  }
  {
    std::lock_guard<std::mutex> lk(mutex_);
    state_ = State::Open;
  }
  opened_ = true;
  ++core_->openCount;
  spdlog::debug("transport: WebSocket #{} open ({}, {})", id_, remote_, target_);
  if (core_->handlers.onOpen) {
    try {
      core_->handlers.onOpen(shared_from_this());
    } catch (const std::exception& e) {
      spdlog::error("transport: onOpen handler threw: {}", e.what());
    }
  }
  readNext();
}

// ---- reading -----------------------------------------------------------------------------

void WebSocketSession::readNext() {
  ws_->async_read_some(buffer_, kReadChunk,
                      beast::bind_front_handler(&WebSocketSession::onRead, shared_from_this()));
}

void WebSocketSession::onRead(beast::error_code ec, std::size_t) {
  if (finished_) return;
  if (ec) {
    finish(ec);
    return;
  }
  if (ws_->got_binary()) {
    buffer_.clear();
    requestClose(CloseCode::UnsupportedData, "binary frames are not supported", true);
    return;  // Beast's close operation reads (and discards) until the peer's close frame
  }
  const auto maxBytes = core_->limits.maxMessageBytes;
  if (buffer_.size() > maxBytes) {
    buffer_.clear();
    requestClose(CloseCode::MessageTooBig,
                 "message too big (limit " + std::to_string(maxBytes) + " bytes)", true);
    return;
  }
  if (ws_->is_message_done()) {
    std::string message = beast::buffers_to_string(buffer_.data());
    buffer_.consume(buffer_.size());
    if (isOpen() && core_->handlers.onMessage) {
      try {
        core_->handlers.onMessage(shared_from_this(), std::move(message));
      } catch (const std::exception& e) {
        spdlog::error("transport: onMessage handler threw: {}", e.what());
      }
    }
  }
  readNext();
}

// ---- writing -----------------------------------------------------------------------------

void WebSocketSession::writeNext() {
  std::unique_lock<std::mutex> lk(mutex_);
  if (finished_) {
    writing_ = false;
    return;
  }
  if (!queue_.empty()) {
    Outgoing& next = queue_.front();
    if (!next.key.empty()) byKey_.erase(next.key);
    queuedBytes_ -= next.text.size();
    inFlight_ = std::move(next.text);
    queue_.pop_front();
    lk.unlock();
    ws_->text(true);
    ws_->async_write(net::buffer(inFlight_),
                    beast::bind_front_handler(&WebSocketSession::onWrite, shared_from_this()));
    return;
  }
  if (closeRequest_ && !closeStarted_) {
    closeStarted_ = true;
    const websocket::close_reason reason = *closeRequest_;
    lk.unlock();
    ws_->async_close(reason, beast::bind_front_handler(&WebSocketSession::finish,
                                                      shared_from_this()));
    return;
  }
  writing_ = false;
}

void WebSocketSession::onWrite(beast::error_code ec, std::size_t) {
  std::string().swap(inFlight_);
  if (ec) {
    finish(ec);
    return;
  }
  writeNext();
}

// ---- closing -----------------------------------------------------------------------------

void WebSocketSession::requestClose(std::uint16_t code, std::string reason, bool dropQueue) {
  std::optional<bool> kick;
  {
    std::lock_guard<std::mutex> lk(mutex_);
    kick = closeLocked(code, std::move(reason), dropQueue);
  }
  if (kick) postClose(*kick);
}

std::optional<bool> WebSocketSession::closeLocked(std::uint16_t code, std::string reason,
                                                  bool dropQueue) {
  if (state_ != State::Open) return std::nullopt;
  state_ = State::Closing;
  if (reason.size() > 123) reason.resize(123);
  closeRequest_.emplace(static_cast<websocket::close_code>(code), reason);
  if (dropQueue) dropQueueLocked();
  if (writing_) return false;
  writing_ = true;
  return true;
}

void WebSocketSession::postClose(bool kick) {
  net::post(timer_.get_executor(), [self = shared_from_this(), kick] {
    self->armCloseTimer();
    if (kick) self->writeNext();
  });
}

void WebSocketSession::armCloseTimer() {
  if (timerArmed_ || finished_) return;
  timerArmed_ = true;
  timer_.expires_after(core_->limits.closeTimeout);
  timer_.async_wait([self = shared_from_this()](beast::error_code ec) {
    if (ec || self->finished_) return;
    spdlog::debug("transport: WebSocket #{} close timed out; dropping TCP", self->id_);
    self->finish(net::error::timed_out);
  });
}

void WebSocketSession::finish(beast::error_code ec) {
  if (finished_) return;
  finished_ = true;
  {
    std::lock_guard<std::mutex> lk(mutex_);
    state_ = State::Finished;
    dropQueueLocked();
  }
  timer_.cancel();
  // Beast leaves its idle/handshake timer pending after a failed read; turning the timeouts off
  // cancels it, so the io_context can run out of work even while someone still holds this
  // Connection.
  ws_->set_option(websocket::stream_base::timeout{websocket::stream_base::none(),
                                                 websocket::stream_base::none(), false});
  beast::error_code ignored;
  auto& stream = beast::get_lowest_layer(*ws_);
  stream.socket().shutdown(tcp::socket::shutdown_both, ignored);
  stream.close();
  slot_.release();  // before onClose: a client that saw the close may connect again at once
  if (opened_) {
    spdlog::debug("transport: WebSocket #{} closed ({})", id_, ec.message());
    --core_->openCount;
    if (core_->handlers.onClose) {
      try {
        core_->handlers.onClose(shared_from_this());
      } catch (const std::exception& e) {
        spdlog::error("transport: onClose handler threw: {}", e.what());
      }
    }
  }
  core_->removeSession(id_);
}

void WebSocketSession::dropStream() {
  const auto self = shared_from_this();  // a handler parked in the stream may hold the last one
  if (!finished_) finish(net::error::operation_aborted);
  timer_.cancel();
  ws_.reset();
}

void WebSocketSession::dropQueueLocked() {
  queue_.clear();
  byKey_.clear();
  queuedBytes_ = 0;
}

}  // namespace devsurf::server::transport::detail
