// Synchronous WebSocket client on Boost.Beast: async operations driven by a private io_context
// that runs only inside the calls, which is how receive() and send() get their timeouts.
#include "devsurf/server/transport/Client.h"

#include <boost/asio/connect.hpp>
#include <boost/asio/io_context.hpp>
#include <boost/asio/ip/tcp.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/http.hpp>
#include <boost/beast/websocket.hpp>

#include <deque>
#include <stdexcept>

namespace devsurf::server::transport {

namespace beast = boost::beast;
namespace http = beast::http;
namespace websocket = beast::websocket;
namespace net = boost::asio;
using tcp = net::ip::tcp;
using Clock = std::chrono::steady_clock;

struct Client::Impl {
  net::io_context ioc;
  websocket::stream<beast::tcp_stream> ws{ioc};
  beast::flat_buffer readBuffer;
  std::deque<std::string> inbox;
  bool connected = false;
  bool closed = false;  // no further frames can arrive
  bool reading = false;
  std::optional<CloseInfo> closeInfo;
  int httpStatus = 0;

  struct OpState {
    bool done = false;
    beast::error_code ec;
    std::string data;
  };

  /// Runs handlers until done() or the deadline. Returns done().
  template <class Pred>
  bool runUntil(Pred done, Clock::time_point deadline) {
    while (!done()) {
      if (ioc.stopped()) ioc.restart();
      if (ioc.run_one_until(deadline) == 0) return done();
    }
    return true;
  }

  void startRead() {
    if (reading || closed) return;
    reading = true;
    ws.async_read(readBuffer, [this](beast::error_code ec, std::size_t) { onRead(ec); });
  }

  void onRead(beast::error_code ec) {
    reading = false;
    if (ec) {
      closed = true;
      if (ec == websocket::error::closed) {
        const auto& r = ws.reason();
        closeInfo = CloseInfo{static_cast<std::uint16_t>(r.code),
                              std::string(r.reason.data(), r.reason.size())};
      }
      return;
    }
    inbox.push_back(beast::buffers_to_string(readBuffer.data()));
    readBuffer.consume(readBuffer.size());
    startRead();
  }

  void dropSocket(bool reset) {
    beast::error_code ignored;
    auto& socket = beast::get_lowest_layer(ws).socket();
    if (!socket.is_open()) return;
    if (reset) socket.set_option(net::socket_base::linger(true, 0), ignored);
    socket.close(ignored);
  }

  void write(const std::string& data, bool binary, std::chrono::milliseconds timeout) {
    if (!connected || closed) throw std::runtime_error("WebSocket client: not connected");
    auto state = std::make_shared<OpState>();
    state->data = data;
    ws.binary(binary);
    ws.async_write(net::buffer(state->data), [state](beast::error_code ec, std::size_t) {
      state->done = true;
      state->ec = ec;
    });
    if (!runUntil([&] { return state->done; }, Clock::now() + timeout)) {
      closed = true;
      dropSocket(true);
      throw std::runtime_error("WebSocket client: send timed out");
    }
    if (state->ec) {
      closed = true;
      throw std::runtime_error("WebSocket client: send failed: " + state->ec.message());
    }
  }
};

Client::Client() : impl_(std::make_unique<Impl>()) {}

Client::~Client() {
  if (impl_) impl_->dropSocket(false);
}

void Client::connect(const std::string& host, int port, const std::string& target,
                     std::chrono::milliseconds timeout) {
  auto& d = *impl_;
  if (d.connected) throw std::runtime_error("WebSocket client: already connected");
  const auto deadline = Clock::now() + timeout;
  const std::string where = host + ":" + std::to_string(port) + target;

  tcp::resolver resolver(d.ioc);
  struct Resolved : Impl::OpState {
    tcp::resolver::results_type endpoints;
  };
  auto resolved = std::make_shared<Resolved>();
  resolver.async_resolve(host, std::to_string(port),
                         [resolved](beast::error_code ec, tcp::resolver::results_type results) {
                           resolved->done = true;
                           resolved->ec = ec;
                           resolved->endpoints = std::move(results);
                         });
  if (!d.runUntil([&] { return resolved->done; }, deadline) || resolved->ec) {
    resolver.cancel();
    throw std::runtime_error("WebSocket client: cannot resolve " + host + ": " +
                             (resolved->ec ? resolved->ec.message() : "timeout"));
  }

  auto& stream = beast::get_lowest_layer(d.ws);
  stream.expires_at(deadline);
  auto connected = std::make_shared<Impl::OpState>();
  stream.async_connect(resolved->endpoints, [connected](beast::error_code ec, const tcp::endpoint&) {
    connected->done = true;
    connected->ec = ec;
  });
  if (!d.runUntil([&] { return connected->done; }, deadline + std::chrono::seconds(1)) ||
      connected->ec) {
    d.dropSocket(false);
    throw std::runtime_error("WebSocket client: cannot connect to " + where + ": " +
                             (connected->ec ? connected->ec.message() : "timeout"));
  }

  d.ws.set_option(websocket::stream_base::decorator([](websocket::request_type& req) {
    req.set(http::field::user_agent, "devsurf-client");
  }));
  auto response = std::make_shared<websocket::response_type>();
  auto handshake = std::make_shared<Impl::OpState>();
  d.ws.async_handshake(*response, host + ":" + std::to_string(port), target,
                       [handshake, response](beast::error_code ec) {
                         handshake->done = true;
                         handshake->ec = ec;
                       });
  const bool finished =
      d.runUntil([&] { return handshake->done; }, deadline + std::chrono::seconds(1));
  d.httpStatus = response->result_int();
  if (!finished || handshake->ec) {
    d.dropSocket(false);
    std::string message = "WebSocket client: handshake with " + where + " failed: ";
    if (d.httpStatus != 0 && d.httpStatus != 101) {
      message += "HTTP " + std::to_string(d.httpStatus) + " " + std::string(response->reason());
    } else {
      message += finished ? handshake->ec.message() : "timeout";
    }
    throw std::runtime_error(message);
  }
  stream.expires_never();
  d.ws.read_message_max(std::size_t(256) << 20);
  d.ws.auto_fragment(false);
  d.connected = true;
}

void Client::send(const std::string& text, std::chrono::milliseconds timeout) {
  impl_->write(text, false, timeout);
}

void Client::sendBinary(const std::string& data, std::chrono::milliseconds timeout) {
  impl_->write(data, true, timeout);
}

std::optional<std::string> Client::receive(std::chrono::milliseconds timeout) {
  auto& d = *impl_;
  if (d.inbox.empty() && d.connected && !d.closed) {
    d.startRead();
    d.runUntil([&] { return !d.inbox.empty() || d.closed; }, Clock::now() + timeout);
  }
  if (d.inbox.empty()) return std::nullopt;
  std::string message = std::move(d.inbox.front());
  d.inbox.pop_front();
  return message;
}

void Client::close(std::uint16_t code, const std::string& reason,
                   std::chrono::milliseconds timeout) {
  auto& d = *impl_;
  if (d.connected && !d.closed) {
    auto state = std::make_shared<Impl::OpState>();
    websocket::close_reason cr(static_cast<websocket::close_code>(code),
                               reason.substr(0, 123));
    d.ws.async_close(cr, [state](beast::error_code ec) {
      state->done = true;
      state->ec = ec;
    });
    d.runUntil([&] { return state->done && !d.reading; }, Clock::now() + timeout);
    d.closed = true;
  }
  d.dropSocket(false);
}

void Client::abort() {
  impl_->closed = true;
  impl_->dropSocket(true);
}

bool Client::isOpen() const { return impl_->connected && !impl_->closed; }

std::optional<CloseInfo> Client::closeInfo() const { return impl_->closeInfo; }

int Client::httpStatus() const { return impl_->httpStatus; }

}  // namespace devsurf::server::transport
