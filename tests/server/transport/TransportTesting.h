#pragma once
// Shared by the transport tests: a server on an ephemeral 127.0.0.1 port with recording
// WebSocket handlers, and raw-socket helpers for requests httplib::Client would not send.

#include "devsurf/server/transport/Client.h"
#include "devsurf/server/transport/Server.h"

#include <gtest/gtest.h>

#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <sys/time.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <cstdlib>
#include <chrono>
#include <condition_variable>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

namespace devsurf::server::transport::testing {

/// Records every handler call; optionally echoes messages.
struct Recorder {
  std::mutex mutex;
  std::condition_variable cv;
  std::vector<std::shared_ptr<Connection>> opened;
  std::map<std::uint64_t, int> closeCount;
  std::map<std::uint64_t, std::vector<std::string>> messages;
  std::atomic<int> handlerCalls{0};
  std::atomic<int> concurrentInOneConnection{0};
  bool echo = true;

  WebSocketHandlers handlers() {
    WebSocketHandlers h;
    h.onOpen = [this](const std::shared_ptr<Connection>& c) {
      ++handlerCalls;
      std::lock_guard<std::mutex> lk(mutex);
      opened.push_back(c);
      cv.notify_all();
    };
    h.onMessage = [this](const std::shared_ptr<Connection>& c, std::string message) {
      ++handlerCalls;
      if (echo) c->send(message);
      std::lock_guard<std::mutex> lk(mutex);
      messages[c->id()].push_back(std::move(message));
      cv.notify_all();
    };
    h.onClose = [this](const std::shared_ptr<Connection>& c) {
      ++handlerCalls;
      std::lock_guard<std::mutex> lk(mutex);
      ++closeCount[c->id()];
      cv.notify_all();
    };
    return h;
  }

  template <class Pred>
  bool waitFor(Pred pred, std::chrono::milliseconds timeout = std::chrono::seconds(5)) {
    std::unique_lock<std::mutex> lk(mutex);
    return cv.wait_for(lk, timeout, pred);
  }

  std::shared_ptr<Connection> waitOpened(std::size_t index) {
    std::unique_lock<std::mutex> lk(mutex);
    if (!cv.wait_for(lk, std::chrono::seconds(5), [&] { return opened.size() > index; })) return nullptr;
    return opened[index];
  }

  int totalCloses() {
    int n = 0;
    for (const auto& entry : closeCount) n += entry.second;
    return n;
  }
};

/// Server + serve() thread.
struct Harness {
  explicit Harness(TransportLimits limits = {}, bool echo = true) {
    recorder.echo = echo;
    server = std::make_unique<Server>(recorder.handlers(), limits);
    server->Get("/api/hello", [](const httplib::Request&, httplib::Response& res) {
      res.set_content("hello", "text/plain");
    });
    port = server->bind("127.0.0.1", 0);
    thread = std::thread([this] { server->serve(); });
  }
  ~Harness() {
    server->stop();
    if (thread.joinable()) thread.join();
  }

  Recorder recorder;
  std::unique_ptr<Server> server;
  int port = 0;
  std::thread thread;
};

inline std::string numbered(int i, std::size_t size) {
  std::string s = std::to_string(i) + ":";
  if (s.size() < size) s.resize(size, 'x');
  return s;
}

inline int numberOf(const std::string& s) { return std::stoi(s.substr(0, s.find(':'))); }

// ---- raw sockets (for requests httplib::Client would not send) ---------------------------
inline int rawConnect(int port) {
  const int fd = ::socket(AF_INET, SOCK_STREAM, 0);
  sockaddr_in addr{};
  addr.sin_family = AF_INET;
  addr.sin_port = htons(static_cast<uint16_t>(port));
  addr.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  if (::connect(fd, reinterpret_cast<sockaddr*>(&addr), sizeof(addr)) != 0) {
    ::close(fd);
    return -1;
  }
  timeval tv{5, 0};
  ::setsockopt(fd, SOL_SOCKET, SO_RCVTIMEO, &tv, sizeof(tv));
  return fd;
}

inline void rawSend(int fd, const std::string& data) {
  ASSERT_EQ(::send(fd, data.data(), data.size(), MSG_NOSIGNAL), static_cast<ssize_t>(data.size()));
}

/// Reads one HTTP response head (and a Content-Length body).
inline std::string rawReadResponse(int fd) {
  std::string data;
  char buf[4096];
  std::size_t headEnd = std::string::npos;
  while ((headEnd = data.find("\r\n\r\n")) == std::string::npos) {
    const auto n = ::recv(fd, buf, sizeof(buf), 0);
    if (n <= 0) return data;
    data.append(buf, static_cast<std::size_t>(n));
  }
  std::size_t length = 0;
  const auto pos = data.find("Content-Length: ");
  if (pos != std::string::npos && pos < headEnd) length = std::stoul(data.substr(pos + 16));
  while (data.size() < headEnd + 4 + length) {
    const auto n = ::recv(fd, buf, sizeof(buf), 0);
    if (n <= 0) break;
    data.append(buf, static_cast<std::size_t>(n));
  }
  return data;
}

/// A raw TCP client that reads HTTP responses one at a time (pipelined ones too), for requests
/// httplib::Client would not send. Every receive waits at most `timeout`.
class RawClient {
 public:
  explicit RawClient(int port, std::chrono::milliseconds timeout = std::chrono::seconds(5))
      : fd_(rawConnect(port)) {
    if (fd_ < 0) return;
    timeval tv{static_cast<time_t>(timeout.count() / 1000),
               static_cast<suseconds_t>((timeout.count() % 1000) * 1000)};
    ::setsockopt(fd_, SOL_SOCKET, SO_RCVTIMEO, &tv, sizeof(tv));
  }
  ~RawClient() {
    if (fd_ >= 0) ::close(fd_);
  }
  RawClient(const RawClient&) = delete;
  RawClient& operator=(const RawClient&) = delete;

  bool connected() const { return fd_ >= 0; }

  /// False when the server has closed or reset the connection.
  bool send(const std::string& data) {
    std::size_t sent = 0;
    while (sent < data.size()) {
      const auto n = ::send(fd_, data.data() + sent, data.size() - sent, MSG_NOSIGNAL);
      if (n <= 0) return false;
      sent += static_cast<std::size_t>(n);
    }
    return true;
  }

  /// Whether a response (or the server's close) is waiting to be read, without waiting.
  bool readable() const {
    if (!pending_.empty()) return true;
    char c;
    const auto n = ::recv(fd_, &c, 1, MSG_PEEK | MSG_DONTWAIT);
    return n >= 0 || (errno != EAGAIN && errno != EWOULDBLOCK);
  }

  /// One response: status line, headers and a Content-Length body (1xx responses have none).
  /// Empty when the connection ended (or the timeout passed) before a whole head arrived.
  std::string readResponse() {
    std::size_t headEnd;
    while ((headEnd = pending_.find("\r\n\r\n")) == std::string::npos) {
      if (!fill()) return {};
    }
    std::size_t length = 0;
    const auto head = pending_.substr(0, headEnd);
    const auto pos = head.find("Content-Length: ");
    if (pos != std::string::npos) length = std::stoul(head.substr(pos + 16));
    while (pending_.size() < headEnd + 4 + length) {
      if (!fill()) break;
    }
    const auto size = std::min(pending_.size(), headEnd + 4 + length);
    std::string response = pending_.substr(0, size);
    pending_.erase(0, size);
    return response;
  }

  /// True when the server closes the connection within the timeout, with nothing (more) to read.
  bool closedByServer() {
    if (!pending_.empty()) return false;
    char buf[256];
    const auto n = ::recv(fd_, buf, sizeof(buf), 0);
    if (n > 0) {
      pending_.append(buf, static_cast<std::size_t>(n));
      return false;
    }
    return n == 0 || (errno != EAGAIN && errno != EWOULDBLOCK);
  }

 private:
  bool fill() {
    char buf[16384];
    const auto n = ::recv(fd_, buf, sizeof(buf), 0);
    if (n <= 0) return false;
    pending_.append(buf, static_cast<std::size_t>(n));
    return true;
  }

  int fd_;
  std::string pending_;
};

/// The status code of a response ("HTTP/1.1 431 …" → 431), or 0.
inline int statusOf(const std::string& response) {
  if (response.size() < 12 || response.rfind("HTTP/1.", 0) != 0) return 0;
  return std::atoi(response.c_str() + 9);
}

/// The body of a response (after the blank line).
inline std::string bodyOf(const std::string& response) {
  const auto pos = response.find("\r\n\r\n");
  return pos == std::string::npos ? std::string() : response.substr(pos + 4);
}

inline const char* const kUpgradeHeaders =
    "Host: 127.0.0.1\r\nUpgrade: websocket\r\nConnection: Upgrade\r\n"
    "Sec-WebSocket-Key: dGhlIHNhbXBsZSBub25jZQ==\r\nSec-WebSocket-Version: 13\r\n\r\n";

}  // namespace devsurf::server::transport::testing
