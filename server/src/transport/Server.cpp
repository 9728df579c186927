// HTTP (cpp-httplib) + WebSocket (Boost.Beast) on one port. See Server.h for the design.
#include "devsurf/server/transport/Server.h"

#include <boost/asio/dispatch.hpp>
#include <boost/asio/executor_work_guard.hpp>
#include <boost/asio/io_context.hpp>
#include <boost/asio/ip/tcp.hpp>
#include <boost/asio/post.hpp>
#include <boost/asio/steady_timer.hpp>
#include <boost/asio/strand.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/http.hpp>
#include <boost/beast/websocket.hpp>
#include <spdlog/spdlog.h>

#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <sys/time.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <cerrno>
#include <chrono>
#include <cstring>
#include <list>
#include <optional>
#include <stdexcept>
#include <thread>
#include <unordered_map>
#include <utility>
#include <vector>

namespace devsurf::server::transport {

namespace beast = boost::beast;
namespace http = beast::http;
namespace websocket = beast::websocket;
namespace net = boost::asio;
using tcp = net::ip::tcp;

namespace detail {

class WebSocketSession;

/// Everything on the Beast side. Shared by the Server and its sessions so that a Connection held
/// by the protocol layer after the Server is gone never points at a destroyed io_context.
struct ServerCore : std::enable_shared_from_this<ServerCore> {
  ServerCore(WebSocketHandlers h, TransportLimits l)
      : handlers(std::move(h)), limits(l), work(net::make_work_guard(ioc)) {}

  void startThreads();
  /// Takes ownership of an accepted fd whose first request is "GET /ws…". Returns false (fd not
  /// taken, caller closes it) when stopping.
  bool adopt(int fd);
  void removeSession(std::uint64_t id, bool admittedSlot);
  void stopThreads();

  const WebSocketHandlers handlers;
  const TransportLimits limits;
  net::io_context ioc;
  std::optional<net::executor_work_guard<net::io_context::executor_type>> work;
  std::vector<std::thread> threads;

  std::mutex mutex;  // guards everything below except the atomics
  std::condition_variable cv;
  bool stopping = false;
  std::atomic<bool> stoppingFlag{false};  // lock-free copy of `stopping` for the io threads
  std::unordered_map<std::uint64_t, std::shared_ptr<WebSocketSession>> sessions;
  std::size_t admitted = 0;  // sessions counted against maxConnections
  std::size_t threadsExited = 0;
  std::uint64_t nextId = 1;
  std::atomic<std::size_t> openCount{0};
};

/// One WebSocket connection: Beast stream on a strand of the core's io_context.
/// Threading: everything except the Connection interface and start/shutdown/abort runs on the
/// strand. The outgoing queue and the state are guarded by mutex_ (send() is called from any
/// thread).
class WebSocketSession final : public Connection,
                               public std::enable_shared_from_this<WebSocketSession> {
 public:
  WebSocketSession(std::shared_ptr<ServerCore> core, tcp::socket socket, std::uint64_t id,
                   std::string remote, bool reject)
      : core_(std::move(core)),
        ws_(std::move(socket)),
        timer_(ws_.get_executor()),
        id_(id),
        remote_(std::move(remote)),
        reject_(reject) {}

  std::uint64_t id() const override { return id_; }
  std::string remoteAddress() const override { return remote_; }
  std::string target() const override {
    std::lock_guard<std::mutex> lk(mutex_);
    return target_;
  }

  void send(std::string text, Delivery delivery, std::string key) override {
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
    if (kick) net::post(ws_.get_executor(), [self = shared_from_this()] { self->writeNext(); });
  }

  void close(std::uint16_t code, std::string reason) override {
    requestClose(code, std::move(reason), /*dropQueue=*/false);
  }

  bool isOpen() const override {
    std::lock_guard<std::mutex> lk(mutex_);
    return state_ == State::Open;
  }
  std::size_t queuedBytes() const override {
    std::lock_guard<std::mutex> lk(mutex_);
    return queuedBytes_;
  }
  std::size_t queuedMessages() const override {
    std::lock_guard<std::mutex> lk(mutex_);
    return queue_.size();
  }

  bool admitted() const { return !reject_; }

  /// Any thread: begin reading the upgrade request.
  void start() {
    net::dispatch(ws_.get_executor(), [self = shared_from_this()] { self->readRequest(); });
  }

  /// Any thread: server stopping. Open connections get 1001 (queue dropped); a connection still
  /// in its handshake is dropped.
  void shutdown() {
    net::post(ws_.get_executor(), [self = shared_from_this()] {
      if (self->finished_) return;
      if (!self->opened_) {
        self->finish(net::error::operation_aborted);
        return;
      }
      self->requestClose(CloseCode::GoingAway, "server shutting down", /*dropQueue=*/true);
    });
  }

  /// Any thread: drop the TCP connection now.
  void abort() {
    net::post(ws_.get_executor(),
              [self = shared_from_this()] { self->finish(net::error::operation_aborted); });
  }

 private:
  enum class State { Handshake, Open, Closing, Finished };
  struct Outgoing {
    std::string text;
    std::string key;  // non-empty: coalescable (Latest)
  };
  static constexpr std::size_t kReadChunk = 64 * 1024;

  // ---- handshake -------------------------------------------------------------------------
  void readRequest() {
    beast::get_lowest_layer(ws_).expires_after(core_->limits.handshakeTimeout);
    parser_.emplace();
    parser_->header_limit(16 * 1024);
    http::async_read(ws_.next_layer(), buffer_, *parser_,
                     beast::bind_front_handler(&WebSocketSession::onRequest, shared_from_this()));
  }

  void onRequest(beast::error_code ec, std::size_t) {
    if (finished_) return;
    if (ec) {
      finish(ec);
      return;
    }
    const auto& req = parser_->get();
    {
      std::lock_guard<std::mutex> lk(mutex_);
      target_ = std::string(req.target());
    }
    if (reject_) {
      spdlog::warn("transport: refusing WebSocket from {}: {} connections open", remote_,
                   core_->limits.maxConnections);
      reject(http::status::service_unavailable, "too many WebSocket connections\n");
      return;
    }
    if (core_->stoppingFlag) {
      reject(http::status::service_unavailable, "server shutting down\n");
      return;
    }
    const auto& limits = core_->limits;
    websocket::stream_base::timeout opt{};
    opt.handshake_timeout = limits.handshakeTimeout;
    opt.idle_timeout = limits.idleTimeout.count() > 0
                           ? websocket::stream_base::duration(limits.idleTimeout)
                           : websocket::stream_base::none();
    opt.keep_alive_pings = true;
    beast::get_lowest_layer(ws_).expires_never();  // Beast's websocket timeouts take over
    ws_.set_option(opt);
    ws_.set_option(websocket::stream_base::decorator(
        [](websocket::response_type& res) { res.set(http::field::server, "devsurf"); }));
    ws_.read_message_max(0);  // enforced by onRead, so the close carries a reason
    ws_.auto_fragment(false);
    ws_.async_accept(req,
                     beast::bind_front_handler(&WebSocketSession::onAccept, shared_from_this()));
  }

  void reject(http::status status, std::string body) {
    auto res = std::make_shared<http::response<http::string_body>>(status, 11);
    res->set(http::field::server, "devsurf");
    res->set(http::field::content_type, "text/plain");
    res->keep_alive(false);
    res->body() = std::move(body);
    res->prepare_payload();
    http::async_write(ws_.next_layer(), *res,
                      [self = shared_from_this(), res](beast::error_code ec, std::size_t) {
                        self->finish(ec);
                      });
  }

  void onAccept(beast::error_code ec) {
    if (finished_) return;
    if (ec) {  // Beast has answered with 400/426 already
      spdlog::debug("transport: WebSocket handshake from {} failed: {}", remote_, ec.message());
      finish(ec);
      return;
    }
    if (core_->stoppingFlag) {
      finish(net::error::operation_aborted);
      return;
    }
    buffer_.clear();
    {
      std::lock_guard<std::mutex> lk(mutex_);
      state_ = State::Open;
    }
    opened_ = true;
    ++core_->openCount;
    spdlog::debug("transport: WebSocket #{} open ({}, {})", id_, remote_, target());
    if (core_->handlers.onOpen) {
      try {
        core_->handlers.onOpen(shared_from_this());
      } catch (const std::exception& e) {
        spdlog::error("transport: onOpen handler threw: {}", e.what());
      }
    }
    readNext();
  }

  // ---- reading ---------------------------------------------------------------------------
  void readNext() {
    ws_.async_read_some(buffer_, kReadChunk,
                        beast::bind_front_handler(&WebSocketSession::onRead, shared_from_this()));
  }

  void onRead(beast::error_code ec, std::size_t) {
    if (finished_) return;
    if (ec) {
      finish(ec);
      return;
    }
    if (ws_.got_binary()) {
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
    if (ws_.is_message_done()) {
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

  // ---- writing ---------------------------------------------------------------------------
  void writeNext() {
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
      ws_.text(true);
      ws_.async_write(net::buffer(inFlight_),
                      beast::bind_front_handler(&WebSocketSession::onWrite, shared_from_this()));
      return;
    }
    if (closeRequest_ && !closeStarted_) {
      closeStarted_ = true;
      const websocket::close_reason reason = *closeRequest_;
      lk.unlock();
      ws_.async_close(reason, beast::bind_front_handler(&WebSocketSession::onCloseDone,
                                                        shared_from_this()));
      return;
    }
    writing_ = false;
  }

  void onWrite(beast::error_code ec, std::size_t) {
    std::string().swap(inFlight_);
    if (ec) {
      finish(ec);
      return;
    }
    writeNext();
  }

  void onCloseDone(beast::error_code ec) { finish(ec); }

  // ---- closing ---------------------------------------------------------------------------
  /// Any thread.
  void requestClose(std::uint16_t code, std::string reason, bool dropQueue) {
    std::optional<bool> kick;
    {
      std::lock_guard<std::mutex> lk(mutex_);
      kick = closeLocked(code, std::move(reason), dropQueue);
    }
    if (kick) postClose(*kick);
  }

  /// mutex_ held. Open → Closing; returns nullopt if not open, else whether the writer must be
  /// started (pass it to postClose()).
  std::optional<bool> closeLocked(std::uint16_t code, std::string reason, bool dropQueue) {
    if (state_ != State::Open) return std::nullopt;
    state_ = State::Closing;
    if (reason.size() > 123) reason.resize(123);
    closeRequest_.emplace(static_cast<websocket::close_code>(code), reason);
    if (dropQueue) dropQueueLocked();
    if (writing_) return false;
    writing_ = true;
    return true;
  }

  void postClose(bool kick) {
    net::post(ws_.get_executor(), [self = shared_from_this(), kick] {
      self->armCloseTimer();
      if (kick) self->writeNext();
    });
  }

  void armCloseTimer() {
    if (timerArmed_ || finished_) return;
    timerArmed_ = true;
    timer_.expires_after(core_->limits.closeTimeout);
    timer_.async_wait([self = shared_from_this()](beast::error_code ec) {
      if (ec || self->finished_) return;
      spdlog::debug("transport: WebSocket #{} close timed out; dropping TCP", self->id_);
      self->finish(net::error::timed_out);
    });
  }

  /// Strand. Ends the connection (idempotent): closes the socket, calls onClose once.
  void finish(beast::error_code ec) {
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
    ws_.set_option(websocket::stream_base::timeout{websocket::stream_base::none(),
                                                   websocket::stream_base::none(), false});
    beast::error_code ignored;
    auto& stream = beast::get_lowest_layer(ws_);
    stream.socket().shutdown(tcp::socket::shutdown_both, ignored);
    stream.close();
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
    core_->removeSession(id_, !reject_);
  }

  void dropQueueLocked() {
    queue_.clear();
    byKey_.clear();
    queuedBytes_ = 0;
  }

  const std::shared_ptr<ServerCore> core_;
  websocket::stream<beast::tcp_stream> ws_;
  net::steady_timer timer_;
  const std::uint64_t id_;
  const std::string remote_;
  const bool reject_;

  // strand only
  beast::flat_buffer buffer_;
  std::optional<http::request_parser<http::empty_body>> parser_;
  std::string inFlight_;
  bool opened_ = false;
  bool timerArmed_ = false;
  std::atomic<bool> finished_{false};  // written on the strand; read under mutex_ in writeNext

  mutable std::mutex mutex_;
  State state_ = State::Handshake;
  std::string target_;
  std::list<Outgoing> queue_;
  std::unordered_map<std::string, std::list<Outgoing>::iterator> byKey_;
  std::size_t queuedBytes_ = 0;
  bool writing_ = false;  // a writeNext/async_write/async_close chain is active
  std::optional<websocket::close_reason> closeRequest_;
  bool closeStarted_ = false;
};

void ServerCore::startThreads() {
  const int n = std::max(1, limits.ioThreads);
  for (int i = 0; i < n; ++i) {
    threads.emplace_back([this] {
      for (;;) {
        try {
          ioc.run();
          break;
        } catch (const std::exception& e) {
          spdlog::error("transport: exception on io thread: {}", e.what());
        }
      }
      std::lock_guard<std::mutex> lk(mutex);
      ++threadsExited;
      cv.notify_all();
    });
  }
}

namespace {
std::string formatEndpoint(const tcp::endpoint& ep) {
  const auto address = ep.address();
  if (address.is_v6()) return "[" + address.to_string() + "]:" + std::to_string(ep.port());
  return address.to_string() + ":" + std::to_string(ep.port());
}
}  // namespace

bool ServerCore::adopt(int fd) {
  std::unique_lock<std::mutex> lk(mutex);
  if (stopping) return false;
  sockaddr_storage local{};
  socklen_t len = sizeof(local);
  if (::getsockname(fd, reinterpret_cast<sockaddr*>(&local), &len) != 0) return false;
  if (local.ss_family != AF_INET && local.ss_family != AF_INET6) return false;
  tcp::socket socket(net::make_strand(ioc));
  beast::error_code ec;
  socket.assign(local.ss_family == AF_INET6 ? tcp::v6() : tcp::v4(), fd, ec);
  if (ec) {
    spdlog::error("transport: cannot adopt socket: {}", ec.message());
    return false;
  }
  // From here on asio owns the fd. httplib set blocking-I/O timeouts on it; clear them.
  timeval zero{};
  ::setsockopt(fd, SOL_SOCKET, SO_RCVTIMEO, &zero, sizeof(zero));
  ::setsockopt(fd, SOL_SOCKET, SO_SNDTIMEO, &zero, sizeof(zero));
  socket.set_option(tcp::no_delay(true), ec);
  std::string remote = "?";
  const auto ep = socket.remote_endpoint(ec);
  if (!ec) remote = formatEndpoint(ep);

  const bool reject = admitted >= limits.maxConnections;
  if (!reject) ++admitted;
  const auto id = nextId++;
  auto session = std::make_shared<WebSocketSession>(shared_from_this(), std::move(socket), id,
                                                    std::move(remote), reject);
  sessions.emplace(id, session);
  lk.unlock();
  session->start();
  return true;
}

void ServerCore::removeSession(std::uint64_t id, bool admittedSlot) {
  std::lock_guard<std::mutex> lk(mutex);
  if (sessions.erase(id) > 0 && admittedSlot) --admitted;
  cv.notify_all();
}

void ServerCore::stopThreads() {
  work.reset();
  {
    std::unique_lock<std::mutex> lk(mutex);
    const bool done = cv.wait_for(lk, std::chrono::seconds(2),
                                  [&] { return threadsExited == threads.size(); });
    if (!done) {
      spdlog::debug("transport: io_context still has work after shutdown; stopping it");
      ioc.stop();
    }
  }
  for (auto& t : threads) {
    if (t.joinable()) t.join();
  }
  threads.clear();
}

}  // namespace detail

// ---- HTTP side -------------------------------------------------------------------------------
namespace {

int pollFor(int fd, short events, time_t sec, time_t usec) {
  pollfd pfd{fd, events, 0};
  const auto ms = static_cast<int>(sec * 1000 + usec / 1000);
  int r;
  do {
    r = ::poll(&pfd, 1, ms);
  } while (r < 0 && errno == EINTR);
  return r;
}

void ipAndPort(const sockaddr_storage& addr, socklen_t len, std::string& ip, int& port) {
  if (addr.ss_family == AF_INET) {
    port = ntohs(reinterpret_cast<const sockaddr_in*>(&addr)->sin_port);
  } else if (addr.ss_family == AF_INET6) {
    port = ntohs(reinterpret_cast<const sockaddr_in6*>(&addr)->sin6_port);
  } else {
    return;
  }
  std::array<char, NI_MAXHOST> host{};
  if (::getnameinfo(reinterpret_cast<const sockaddr*>(&addr), len, host.data(),
                    static_cast<socklen_t>(host.size()), nullptr, 0, NI_NUMERICHOST) == 0) {
    ip = host.data();
  }
}

/// Same behaviour as httplib 0.11.4's detail::SocketStream (not declared in Debian's split
/// header): poll-based timeouts, a 4 KiB read buffer, MSG_NOSIGNAL on send. One instance lives
/// for the whole connection, so bytes buffered beyond one request are not lost.
class HttpSocketStream final : public httplib::Stream {
 public:
  HttpSocketStream(socket_t sock, time_t readSec, time_t readUsec, time_t writeSec,
                   time_t writeUsec)
      : sock_(sock),
        readSec_(readSec),
        readUsec_(readUsec),
        writeSec_(writeSec),
        writeUsec_(writeUsec) {}

  bool is_readable() const override { return pollFor(sock_, POLLIN, readSec_, readUsec_) > 0; }

  bool is_writable() const override {
    return pollFor(sock_, POLLOUT, writeSec_, writeUsec_) > 0 && isAlive();
  }

  ssize_t read(char* ptr, size_t size) override {
    if (offset_ < filled_) {
      const auto n = std::min(size, filled_ - offset_);
      std::memcpy(ptr, buffer_.data() + offset_, n);
      offset_ += n;
      return static_cast<ssize_t>(n);
    }
    if (!is_readable()) return -1;
    offset_ = filled_ = 0;
    if (size < buffer_.size()) {
      const auto n = recvSome(buffer_.data(), buffer_.size());
      if (n <= 0) return n;
      const auto take = std::min(size, static_cast<size_t>(n));
      std::memcpy(ptr, buffer_.data(), take);
      offset_ = take;
      filled_ = static_cast<size_t>(n);
      return static_cast<ssize_t>(take);
    }
    return recvSome(ptr, size);
  }

  ssize_t write(const char* ptr, size_t size) override {
    if (!is_writable()) return -1;
    ssize_t n;
    do {
      n = ::send(sock_, ptr, size, MSG_NOSIGNAL);
    } while (n < 0 && errno == EINTR);
    return n;
  }

  void get_remote_ip_and_port(std::string& ip, int& port) const override {
    sockaddr_storage addr{};
    socklen_t len = sizeof(addr);
    if (::getpeername(sock_, reinterpret_cast<sockaddr*>(&addr), &len) == 0) {
      ipAndPort(addr, len, ip, port);
    }
  }

  void get_local_ip_and_port(std::string& ip, int& port) const override {
    sockaddr_storage addr{};
    socklen_t len = sizeof(addr);
    if (::getsockname(sock_, reinterpret_cast<sockaddr*>(&addr), &len) == 0) {
      ipAndPort(addr, len, ip, port);
    }
  }

  socket_t socket() const override { return sock_; }

  bool hasBufferedData() const { return offset_ < filled_; }

 private:
  ssize_t recvSome(char* ptr, size_t size) {
    ssize_t n;
    do {
      n = ::recv(sock_, ptr, size, 0);
    } while (n < 0 && errno == EINTR);
    return n;
  }

  bool isAlive() const {
    const int r = pollFor(sock_, POLLIN, 0, 0);
    if (r == 0) return true;
    if (r < 0) return false;
    char c;
    return ::recv(sock_, &c, 1, MSG_PEEK | MSG_DONTWAIT) > 0;
  }

  socket_t sock_;
  time_t readSec_, readUsec_, writeSec_, writeUsec_;
  std::array<char, 4096> buffer_{};
  size_t offset_ = 0;
  size_t filled_ = 0;
};

enum class RequestKind { Http, WebSocket, Closed };

/// Peeks (without consuming) at the start of the next request. "GET /ws " and "GET /ws?" are
/// WebSocket upgrades; anything else, or a prefix that does not complete within a second, is
/// left to httplib.
RequestKind classifyRequest(socket_t sock, const std::atomic<socket_t>& svrSock) {
  static constexpr char kPrefix[] = "GET /ws";  // followed by ' ' or '?'
  static constexpr size_t kPrefixLen = sizeof(kPrefix) - 1;
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(1);
  for (;;) {
    char buf[kPrefixLen + 1];
    const ssize_t n = ::recv(sock, buf, sizeof(buf), MSG_PEEK | MSG_DONTWAIT);
    if (n == 0) return RequestKind::Closed;
    if (n < 0 && errno != EAGAIN && errno != EWOULDBLOCK && errno != EINTR) {
      return RequestKind::Closed;
    }
    const size_t have = n > 0 ? static_cast<size_t>(n) : 0;
    if (std::memcmp(buf, kPrefix, std::min(have, kPrefixLen)) != 0) return RequestKind::Http;
    if (have == sizeof(buf)) {
      return (buf[kPrefixLen] == ' ' || buf[kPrefixLen] == '?') ? RequestKind::WebSocket
                                                                  : RequestKind::Http;
    }
    // A consistent but incomplete prefix: wait for more bytes (rare; TCP may split anything).
    if (std::chrono::steady_clock::now() > deadline || svrSock == INVALID_SOCKET) {
      return RequestKind::Http;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
}

/// httplib's keep_alive(): wait until the socket is readable, at most `timeoutSec`, giving up
/// early when the server stops.
bool waitForRequest(socket_t sock, time_t timeoutSec, const std::atomic<socket_t>& svrSock) {
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(timeoutSec);
  while (svrSock != INVALID_SOCKET) {
    const int r = pollFor(sock, POLLIN, 0, 10000);
    if (r < 0) return false;
    if (r > 0) return true;
    if (std::chrono::steady_clock::now() > deadline) return false;
  }
  return false;
}

}  // namespace

// ---- Server ----------------------------------------------------------------------------------

Server::Server(WebSocketHandlers handlers, TransportLimits limits)
    : core_(std::make_shared<detail::ServerCore>(std::move(handlers), limits)) {
  core_->startThreads();
}

Server::~Server() { stop(); }

int Server::bind(const std::string& host, int port) {
  {
    std::lock_guard<std::mutex> lk(serveMutex_);
    if (stopRequested_) throw std::runtime_error("transport: bind() after stop()");
  }
  int bound = -1;
  if (port == 0) {
    bound = bind_to_any_port(host);
  } else if (bind_to_port(host, port)) {
    bound = port;
  }
  if (bound <= 0) {
    throw std::runtime_error("transport: cannot bind " + host + ":" + std::to_string(port) +
                             ": " + std::strerror(errno));
  }
  // libcpp-httplib 0.11.4 listens with a backlog of 5 (CPPHTTPLIB_LISTEN_BACKLOG, compiled into
  // the shared library); a burst of clients would see SYN retransmits. listen() again raises it.
  ::listen(svr_sock_, SOMAXCONN);
  port_ = bound;
  spdlog::info("transport: listening on {}:{}", host, bound);
  return bound;
}

void Server::serve() {
  {
    std::lock_guard<std::mutex> lk(serveMutex_);
    if (stopRequested_) return;
    if (port_ == 0) throw std::runtime_error("transport: serve() before bind()");
    if (serving_) throw std::runtime_error("transport: serve() called twice");
    serving_ = true;
  }
  listen_after_bind();
  std::lock_guard<std::mutex> lk(serveMutex_);
  serving_ = false;
  serveCv_.notify_all();
}

void Server::stop() {
  std::call_once(stopOnce_, [this] {
    auto& core = *core_;
    std::vector<std::shared_ptr<detail::WebSocketSession>> sessions;
    {
      std::lock_guard<std::mutex> lk(core.mutex);
      core.stopping = true;
      core.stoppingFlag = true;
      for (const auto& entry : core.sessions) sessions.push_back(entry.second);
    }
    // 1. Stop accepting. A worker that peeks a /ws request from now on closes it (adopt fails).
    bool serving;
    {
      std::lock_guard<std::mutex> lk(serveMutex_);
      stopRequested_ = true;
      serving = serving_;
    }
    httplib::Server::stop();
    if (!serving && svr_sock_ != INVALID_SOCKET) {
      // Bound but never served (serve() will not start any more): close the listening socket.
      const socket_t sock = svr_sock_.exchange(INVALID_SOCKET);
      ::shutdown(sock, SHUT_RDWR);
      ::close(sock);
    }

    // 2. Close every WebSocket with 1001 and wait for the closing handshakes.
    for (auto& session : sessions) session->shutdown();
    sessions.clear();
    {
      std::unique_lock<std::mutex> lk(core.mutex);
      const auto grace = core.limits.closeTimeout + std::chrono::milliseconds(500);
      if (!core.cv.wait_for(lk, grace, [&] { return core.sessions.empty(); })) {
        spdlog::warn("transport: {} WebSocket(s) did not close in time; dropping them",
                     core.sessions.size());
        for (const auto& entry : core.sessions) sessions.push_back(entry.second);
      }
    }
    if (!sessions.empty()) {
      for (auto& session : sessions) session->abort();
      sessions.clear();
      std::unique_lock<std::mutex> lk(core.mutex);
      core.cv.wait_for(lk, std::chrono::seconds(2), [&] { return core.sessions.empty(); });
    }

    // 3. Wait for serve() (httplib joins its workers before listen returns).
    {
      std::unique_lock<std::mutex> lk(serveMutex_);
      while (serving_) {
        lk.unlock();
        httplib::Server::stop();  // no-op until listen_internal has started
        lk.lock();
        serveCv_.wait_for(lk, std::chrono::milliseconds(5));
      }
    }

    // 4. Join the io threads.
    core.stopThreads();
    spdlog::debug("transport: stopped");
  });
}

std::size_t Server::connectionCount() const { return core_->openCount.load(); }

bool Server::process_and_close_socket(socket_t sock) {
  // Re-creates httplib 0.11.4's Server::process_and_close_socket (private, so not callable):
  // the keep-alive loop of detail::process_server_socket around the protected process_request,
  // plus the WebSocket hand-over before each request.
  HttpSocketStream strm(sock, read_timeout_sec_, read_timeout_usec_, write_timeout_sec_,
                        write_timeout_usec_);
  bool ret = false;
  auto count = std::max<size_t>(keep_alive_max_count_, 1);
  while (svr_sock_ != INVALID_SOCKET && count > 0 &&
         (strm.hasBufferedData() || waitForRequest(sock, keep_alive_timeout_sec_, svr_sock_))) {
    if (!strm.hasBufferedData()) {
      const auto kind = classifyRequest(sock, svr_sock_);
      if (kind == RequestKind::Closed) break;
      if (kind == RequestKind::WebSocket) {
        if (core_->adopt(sock)) return true;  // the fd now belongs to asio: do not close it
        break;                                // stopping: close it below
      }
    }
    const bool closeConnection = count == 1;
    bool connectionClosed = false;
    ret = process_request(strm, closeConnection, connectionClosed, nullptr);
    if (!ret || connectionClosed) break;
    --count;
  }
  ::shutdown(sock, SHUT_RDWR);
  ::close(sock);
  return ret;
}

}  // namespace devsurf::server::transport
