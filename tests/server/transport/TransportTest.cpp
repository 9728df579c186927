// HTTP + WebSocket transport: every test runs its own server on an ephemeral 127.0.0.1 port.
#include <filesystem>
#include <fstream>

#include "server/transport/TransportTesting.h"

namespace devsurf::server::transport {
namespace {

using namespace std::chrono_literals;
using namespace devsurf::server::transport::testing;
using Clock = std::chrono::steady_clock;

// ---- tests -----------------------------------------------------------------------------------

TEST(TransportTest, RestAndWebSocketShareOnePort) {
  Harness h;
  httplib::Client http("127.0.0.1", h.port);
  auto res = http.Get("/api/hello");
  ASSERT_TRUE(res);
  EXPECT_EQ(res->status, 200);
  EXPECT_EQ(res->body, "hello");

  Client ws;
  ws.connect("127.0.0.1", h.port, "/ws?session=7");
  EXPECT_EQ(ws.httpStatus(), 101);
  ws.send("ping");
  EXPECT_EQ(ws.receive(5s), std::optional<std::string>("ping"));

  auto connection = h.recorder.waitOpened(0);
  ASSERT_TRUE(connection);
  EXPECT_EQ(connection->target(), "/ws?session=7");
  EXPECT_EQ(connection->remoteAddress().rfind("127.0.0.1:", 0), 0u) << connection->remoteAddress();
  EXPECT_TRUE(connection->isOpen());
  EXPECT_EQ(h.server->connectionCount(), 1u);

  // REST still works while the WebSocket is open.
  res = http.Get("/api/hello");
  ASSERT_TRUE(res);
  EXPECT_EQ(res->body, "hello");

  ws.close();
  EXPECT_TRUE(h.recorder.waitFor([&] { return h.recorder.totalCloses() == 1; }));
  EXPECT_EQ(h.server->connectionCount(), 0u);
  EXPECT_FALSE(connection->isOpen());
}

TEST(TransportTest, UpgradeAfterKeepAliveRequestAndSplitRequestLine) {
  Harness h;
  // A REST request, then an upgrade on the same kept-alive connection.
  const int fd = rawConnect(h.port);
  ASSERT_GE(fd, 0);
  rawSend(fd, "GET /api/hello HTTP/1.1\r\nHost: 127.0.0.1\r\n\r\n");
  const auto first = rawReadResponse(fd);
  EXPECT_EQ(first.rfind("HTTP/1.1 200", 0), 0u) << first;
  EXPECT_NE(first.find("hello"), std::string::npos);
  rawSend(fd, std::string("GET /ws HTTP/1.1\r\n") + kUpgradeHeaders);
  const auto second = rawReadResponse(fd);
  EXPECT_EQ(second.rfind("HTTP/1.1 101", 0), 0u) << second;
  EXPECT_TRUE(h.recorder.waitOpened(0));
  ::close(fd);

  // The request line arrives in pieces: the peek waits for enough bytes.
  const int fd2 = rawConnect(h.port);
  ASSERT_GE(fd2, 0);
  rawSend(fd2, "GE");
  std::this_thread::sleep_for(50ms);
  rawSend(fd2, "T /w");
  std::this_thread::sleep_for(50ms);
  rawSend(fd2, std::string("s HTTP/1.1\r\n") + kUpgradeHeaders);
  const auto third = rawReadResponse(fd2);
  EXPECT_EQ(third.rfind("HTTP/1.1 101", 0), 0u) << third;
  EXPECT_TRUE(h.recorder.waitOpened(1));
  ::close(fd2);
  EXPECT_TRUE(h.recorder.waitFor([&] { return h.recorder.totalCloses() == 2; }));
}

TEST(TransportTest, ManyMessagesStayInOrderBothWays) {
  Harness h;
  Client ws;
  ws.connect("127.0.0.1", h.port);
  constexpr int kCount = 2000;
  for (int i = 0; i < kCount; ++i) ws.send(numbered(i, 10 + (i % 200)));
  for (int i = 0; i < kCount; ++i) {
    auto message = ws.receive(5s);
    ASSERT_TRUE(message) << "message " << i;
    ASSERT_EQ(numberOf(*message), i);
  }
  auto connection = h.recorder.waitOpened(0);
  ASSERT_TRUE(connection);
  {
    std::lock_guard<std::mutex> lk(h.recorder.mutex);
    const auto& got = h.recorder.messages[connection->id()];
    ASSERT_EQ(got.size(), static_cast<std::size_t>(kCount));
    for (int i = 0; i < kCount; ++i) ASSERT_EQ(numberOf(got[i]), i);
  }
  // Server-initiated burst from another thread, reliable: all arrive, in order.
  std::thread pusher([&] {
    for (int i = 0; i < kCount; ++i) connection->send(numbered(i, 100));
  });
  for (int i = 0; i < kCount; ++i) {
    auto message = ws.receive(5s);
    ASSERT_TRUE(message);
    ASSERT_EQ(numberOf(*message), i);
  }
  pusher.join();
}

TEST(TransportTest, TwentyConcurrentClients) {
  Harness h;
  constexpr int kClients = 20;
  constexpr int kMessages = 100;
  std::atomic<int> ok{0};
  std::atomic<int> connected{0};
  std::atomic<bool> release{false};
  std::vector<std::thread> threads;
  for (int c = 0; c < kClients; ++c) {
    threads.emplace_back([&, c] {
      Client ws;
      ws.connect("127.0.0.1", h.port);
      ++connected;
      for (int i = 0; i < kMessages; ++i) ws.send(std::to_string(c) + ":" + std::to_string(i));
      bool inOrder = true;
      for (int i = 0; i < kMessages; ++i) {
        auto message = ws.receive(10s);
        if (!message || *message != std::to_string(c) + ":" + std::to_string(i)) inOrder = false;
      }
      while (!release) std::this_thread::sleep_for(1ms);
      ws.close();
      if (inOrder) ++ok;
    });
  }
  const auto deadline = Clock::now() + 20s;
  while (connected < kClients && Clock::now() < deadline) std::this_thread::sleep_for(1ms);
  EXPECT_TRUE(h.recorder.waitFor([&] { return h.recorder.opened.size() == kClients; }, 10s));
  EXPECT_EQ(h.server->connectionCount(), static_cast<std::size_t>(kClients));
  release = true;
  for (auto& t : threads) t.join();
  EXPECT_EQ(ok, kClients);
  EXPECT_TRUE(h.recorder.waitFor([&] { return h.recorder.totalCloses() == kClients; }));
  std::lock_guard<std::mutex> lk(h.recorder.mutex);
  EXPECT_EQ(h.recorder.closeCount.size(), static_cast<std::size_t>(kClients));
  for (const auto& entry : h.recorder.closeCount) EXPECT_EQ(entry.second, 1);
  EXPECT_EQ(h.server->connectionCount(), 0u);
}

TEST(TransportTest, OnCloseExactlyOnceForEveryWayOfClosing) {
  Harness h;
  // 1. client closing handshake
  Client a;
  a.connect("127.0.0.1", h.port);
  auto ca = h.recorder.waitOpened(0);
  ASSERT_TRUE(ca);
  a.close(1000, "done");
  // 2. client drops TCP abruptly (RST, no close frame)
  Client b;
  b.connect("127.0.0.1", h.port);
  auto cb = h.recorder.waitOpened(1);
  ASSERT_TRUE(cb);
  b.abort();
  // 3. server closes (after flushing what was queued)
  Client c;
  c.connect("127.0.0.1", h.port);
  auto cc = h.recorder.waitOpened(2);
  ASSERT_TRUE(cc);
  cc->send("last words");
  cc->close(4000, "bye");
  cc->close(4001, "again");  // idempotent
  cc->send("ignored");
  EXPECT_EQ(c.receive(5s), std::optional<std::string>("last words"));
  EXPECT_FALSE(c.receive(5s));
  ASSERT_TRUE(c.closeInfo());
  EXPECT_EQ(c.closeInfo()->code, 4000);
  EXPECT_EQ(c.closeInfo()->reason, "bye");
  // 4. client closes TCP gracefully without a close frame (destructor)
  {
    Client d;
    d.connect("127.0.0.1", h.port);
    ASSERT_TRUE(h.recorder.waitOpened(3));
  }

  EXPECT_TRUE(h.recorder.waitFor([&] { return h.recorder.totalCloses() == 4; }));
  std::this_thread::sleep_for(200ms);  // nothing more may arrive
  std::lock_guard<std::mutex> lk(h.recorder.mutex);
  EXPECT_EQ(h.recorder.totalCloses(), 4);
  for (const auto& entry : h.recorder.closeCount) EXPECT_EQ(entry.second, 1);
  EXPECT_FALSE(ca->isOpen());
  EXPECT_FALSE(cb->isOpen());
}

TEST(TransportTest, OversizedMessageClosesWith1009AndServerKeepsServing) {
  TransportLimits limits;
  limits.maxMessageBytes = 64 * 1024;
  Harness h(limits);
  Client good;
  good.connect("127.0.0.1", h.port);
  good.send("before");
  EXPECT_EQ(good.receive(5s), std::optional<std::string>("before"));

  Client bad;
  bad.connect("127.0.0.1", h.port);
  bad.send(std::string(64 * 1024, 'a'));  // exactly the limit: fine
  EXPECT_EQ(bad.receive(5s)->size(), 64u * 1024u);
  bad.send(std::string(512 * 1024, 'b'));
  EXPECT_FALSE(bad.receive(5s));
  ASSERT_TRUE(bad.closeInfo());
  EXPECT_EQ(bad.closeInfo()->code, CloseCode::MessageTooBig);
  EXPECT_NE(bad.closeInfo()->reason.find("too big"), std::string::npos) << bad.closeInfo()->reason;
  EXPECT_NE(bad.closeInfo()->reason.find("65536"), std::string::npos) << bad.closeInfo()->reason;

  good.send("after");
  EXPECT_EQ(good.receive(5s), std::optional<std::string>("after"));
  Client fresh;
  fresh.connect("127.0.0.1", h.port);
  fresh.send("new");
  EXPECT_EQ(fresh.receive(5s), std::optional<std::string>("new"));
  EXPECT_TRUE(h.recorder.waitFor([&] { return h.recorder.totalCloses() == 1; }));
  // No onMessage for the oversized one.
  std::lock_guard<std::mutex> lk(h.recorder.mutex);
  for (const auto& entry : h.recorder.messages) {
    for (const auto& m : entry.second) EXPECT_LE(m.size(), limits.maxMessageBytes);
  }
}

TEST(TransportTest, BinaryFrameClosesWith1003) {
  Harness h;
  Client ws;
  ws.connect("127.0.0.1", h.port);
  ws.sendBinary(std::string("\x01\x02\x03", 3));
  EXPECT_FALSE(ws.receive(5s));
  ASSERT_TRUE(ws.closeInfo());
  EXPECT_EQ(ws.closeInfo()->code, CloseCode::UnsupportedData);
  EXPECT_FALSE(ws.closeInfo()->reason.empty());
  EXPECT_TRUE(h.recorder.waitFor([&] { return h.recorder.totalCloses() == 1; }));
}

TEST(TransportTest, SlowClientGetsCoalescedLatestMessagesWithBoundedQueue) {
  Harness h({}, /*echo=*/false);
  Client slow;  // does not read until the end
  slow.connect("127.0.0.1", h.port);
  auto connection = h.recorder.waitOpened(0);
  ASSERT_TRUE(connection);

  constexpr int kIterates = 2000;
  constexpr std::size_t kSize = 64 * 1024;  // 128 MB in total: far more than socket buffers
  std::size_t maxQueued = 0;
  for (int i = 0; i < kIterates; ++i) {
    connection->send(numbered(i, kSize), Delivery::Latest, "iterate");
    maxQueued = std::max(maxQueued, connection->queuedBytes());
    ASSERT_LE(connection->queuedMessages(), 1u);
  }
  EXPECT_LE(maxQueued, kSize);
  EXPECT_TRUE(connection->isOpen());
  connection->send("done");  // reliable, after the last iterate

  std::vector<int> got;
  for (;;) {
    auto message = slow.receive(5s);
    ASSERT_TRUE(message) << "after " << got.size() << " messages";
    if (*message == "done") break;
    got.push_back(numberOf(*message));
  }
  ASSERT_FALSE(got.empty());
  for (std::size_t i = 1; i < got.size(); ++i) EXPECT_LT(got[i - 1], got[i]);
  EXPECT_EQ(got.back(), kIterates - 1);  // the newest iterate always arrives
  EXPECT_LT(got.size(), static_cast<std::size_t>(kIterates / 2)) << "nothing was coalesced";
  EXPECT_TRUE(connection->isOpen());
}

TEST(TransportTest, SlowClientReliableBacklogOverflowClosesWith1008) {
  TransportLimits limits;
  limits.maxQueuedBytes = 1 << 20;
  limits.maxQueuedMessages = 64;
  limits.closeTimeout = 10s;
  Harness h(limits, /*echo=*/false);
  Client slow;
  slow.connect("127.0.0.1", h.port);
  auto connection = h.recorder.waitOpened(0);
  ASSERT_TRUE(connection);

  constexpr std::size_t kSize = 32 * 1024;
  int sent = 0;
  std::size_t maxQueued = 0;
  while (connection->isOpen() && sent < 100000) {
    connection->send(numbered(sent++, kSize));
    maxQueued = std::max(maxQueued, connection->queuedBytes());
  }
  EXPECT_FALSE(connection->isOpen());
  EXPECT_LT(sent, 100000);
  EXPECT_LE(maxQueued, limits.maxQueuedBytes + kSize);
  EXPECT_EQ(connection->queuedBytes(), 0u);  // the backlog was dropped

  int received = 0;
  while (auto message = slow.receive(5s)) {
    EXPECT_EQ(numberOf(*message), received);
    ++received;
  }
  EXPECT_LT(received, sent);
  ASSERT_TRUE(slow.closeInfo());
  EXPECT_EQ(slow.closeInfo()->code, CloseCode::PolicyViolation);
  EXPECT_EQ(slow.closeInfo()->reason, "client too slow");
  EXPECT_TRUE(h.recorder.waitFor([&] { return h.recorder.totalCloses() == 1; }));
}

TEST(TransportTest, ConnectionsBeyondTheLimitGet503) {
  TransportLimits limits;
  limits.http.maxConnections = 2;
  Harness h(limits);
  Client a, b, c;
  a.connect("127.0.0.1", h.port);
  b.connect("127.0.0.1", h.port);
  // The client sees the handshake before the server has counted the connection: wait for it.
  ASSERT_TRUE(h.recorder.waitFor([&] { return h.server->connectionCount() == 2u; }));
  try {
    c.connect("127.0.0.1", h.port);
    FAIL() << "third connection accepted";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("HTTP 503"), std::string::npos) << e.what();
  }
  EXPECT_EQ(c.httpStatus(), 503);
  EXPECT_EQ(h.server->connectionCount(), 2u);
  // A slot frees up when a connection ends.
  a.close();
  ASSERT_TRUE(h.recorder.waitFor([&] { return h.recorder.totalCloses() == 1; }));
  ASSERT_TRUE(h.recorder.waitFor([&] { return h.server->connectionCount() == 1u; }));
  Client d;
  d.connect("127.0.0.1", h.port);
  d.send("x");
  EXPECT_EQ(d.receive(5s), std::optional<std::string>("x"));
}

TEST(TransportTest, StopClosesClientsWith1001Promptly) {
  auto h = std::make_unique<Harness>();
  constexpr int kClients = 3;
  std::vector<std::optional<CloseInfo>> closes(kClients);
  std::atomic<int> connected{0};
  std::vector<std::thread> threads;
  for (int i = 0; i < kClients; ++i) {
    threads.emplace_back([&, i] {
      Client ws;
      ws.connect("127.0.0.1", h->port);
      ++connected;
      const auto deadline = Clock::now() + 20s;
      while (ws.isOpen() && Clock::now() < deadline) ws.receive(100ms);
      closes[i] = ws.closeInfo();
    });
  }
  ASSERT_TRUE(h->recorder.waitFor([&] { return h->recorder.opened.size() == kClients; }));
  // A busy sender does not delay shutdown.
  auto connection = h->recorder.waitOpened(0);
  for (int i = 0; i < 100; ++i) connection->send(numbered(i, 1000));

  const auto start = Clock::now();
  h->server->stop();
  const auto elapsed = Clock::now() - start;
  EXPECT_LT(elapsed, 2s);
  const int callsAtStop = h->recorder.handlerCalls;
  {
    std::lock_guard<std::mutex> lk(h->recorder.mutex);
    EXPECT_EQ(h->recorder.totalCloses(), kClients);  // onClose ran before stop() returned
  }
  for (auto& t : threads) t.join();
  for (int i = 0; i < kClients; ++i) {
    ASSERT_TRUE(closes[i]) << "client " << i;
    EXPECT_EQ(closes[i]->code, CloseCode::GoingAway);
    EXPECT_EQ(closes[i]->reason, "server shutting down");
  }
  EXPECT_FALSE(connection->isOpen());
  connection->send("after stop");  // ignored, no crash
  h->server->stop();               // idempotent
  std::this_thread::sleep_for(100ms);
  EXPECT_EQ(h->recorder.handlerCalls, callsAtStop);
  h.reset();
  connection->send("after destruction");  // the Connection outlives the Server safely
  EXPECT_FALSE(connection->isOpen());
}

TEST(TransportTest, StopDoesNotWaitForeverForAClientThatNeverReads) {
  TransportLimits limits;
  limits.closeTimeout = 300ms;
  Harness h(limits, /*echo=*/false);
  Client ws;
  ws.connect("127.0.0.1", h.port);
  auto connection = h.recorder.waitOpened(0);
  ASSERT_TRUE(connection);
  for (int i = 0; i < 200; ++i) connection->send(numbered(i, 64 * 1024));  // fill the buffers
  const auto start = Clock::now();
  h.server->stop();
  EXPECT_LT(Clock::now() - start, 3s);
  EXPECT_EQ(h.recorder.totalCloses(), 1);
  EXPECT_EQ(h.server->connectionCount(), 0u);
  // Also: a server that was stopped refuses new connections.
  Client late;
  EXPECT_THROW(late.connect("127.0.0.1", h.port, "/ws", 1s), std::runtime_error);
}

TEST(TransportTest, AHandlerBlockingTheIoThreadAtStopLeavesNoConnectionAlive) {
  // The shutdown leak of the long hostile run: a handler held the only io thread through the
  // whole close grace, the io_context was stopped with the connection's handlers still queued,
  // and handler → connection → core → io_context → handler kept them all alive.
  TransportLimits limits;
  limits.ioThreads = 2;  // one is held by the handler (and the connection's strand with it)
  limits.closeTimeout = 100ms;
  std::mutex mutex;
  std::weak_ptr<Connection> opened;
  std::atomic<int> closes{0};
  std::atomic<bool> blocking{false};
  WebSocketHandlers handlers;
  handlers.onOpen = [&mutex, &opened](const std::shared_ptr<Connection>& c) {
    std::lock_guard<std::mutex> lk(mutex);
    opened = c;
  };
  handlers.onMessage = [&blocking](const std::shared_ptr<Connection>&, std::string) {
    blocking = true;
    std::this_thread::sleep_for(5s);  // longer than the close grace and the io threads' wait
  };
  handlers.onClose = [&closes](const std::shared_ptr<Connection>&) { ++closes; };
  auto server = std::make_unique<Server>(handlers, limits);
  const int port = server->bind("127.0.0.1", 0);
  std::thread serving([&server] { server->serve(); });
  Client ws;
  ws.connect("127.0.0.1", port);
  ws.send("block the io thread");
  const auto deadline = Clock::now() + 5s;
  while (!blocking && Clock::now() < deadline) std::this_thread::sleep_for(10ms);
  ASSERT_TRUE(blocking);
  server->stop();
  serving.join();
  EXPECT_EQ(closes.load(), 1);  // the participant left: onClose ran
  server.reset();
  std::lock_guard<std::mutex> lk(mutex);
  EXPECT_TRUE(opened.expired()) << "a connection outlived the stopped and destroyed server";
}

TEST(TransportTest, NonWebSocketRequestsGoToHttplib) {
  Harness h;
  h.server->Get("/wsx", [](const httplib::Request&, httplib::Response& res) {
    res.set_content("wsx", "text/plain");
  });
  h.server->Post("/ws", [](const httplib::Request& req, httplib::Response& res) {
    res.set_content("post:" + req.body, "text/plain");
  });
  h.server->Get("/ws/info", [](const httplib::Request&, httplib::Response& res) {
    res.set_content("info", "text/plain");
  });
  httplib::Client http("127.0.0.1", h.port);
  auto res = http.Get("/wsx");
  ASSERT_TRUE(res);
  EXPECT_EQ(res->status, 200);
  EXPECT_EQ(res->body, "wsx");
  res = http.Post("/ws", "abc", "text/plain");
  ASSERT_TRUE(res);
  EXPECT_EQ(res->status, 200);
  EXPECT_EQ(res->body, "post:abc");
  res = http.Get("/ws/info");
  ASSERT_TRUE(res);
  EXPECT_EQ(res->body, "info");
  res = http.Get("/nothing-here");
  ASSERT_TRUE(res);
  EXPECT_EQ(res->status, 404);

  // A plain GET /ws (no upgrade headers) is answered by the WebSocket side with 400.
  httplib::Client plain("127.0.0.1", h.port);
  res = plain.Get("/ws");
  ASSERT_TRUE(res);
  EXPECT_EQ(res->status, 400);
  EXPECT_EQ(h.server->connectionCount(), 0u);

  // A WebSocket handshake on another path is not upgraded.
  Client wrongPath;
  EXPECT_THROW(wrongPath.connect("127.0.0.1", h.port, "/wsx"), std::runtime_error);
  EXPECT_EQ(wrongPath.httpStatus(), 200);
  EXPECT_EQ(h.recorder.opened.size(), 0u);
}

TEST(TransportTest, StaticMountCannotEscapeItsDirectory) {
  namespace fs = std::filesystem;
  const fs::path root = fs::temp_directory_path() /
                        ("devsurf-transport-" + std::to_string(::getpid()) + "-" +
                         std::to_string(Clock::now().time_since_epoch().count()));
  fs::create_directories(root / "public" / "sub");
  std::ofstream(root / "public" / "index.html") << "<h1>devsurf</h1>";
  std::ofstream(root / "public" / "sub" / "a.txt") << "in sub";
  std::ofstream(root / "secret.txt") << "TOP SECRET";

  {
    Harness h;
    ASSERT_TRUE(h.server->set_mount_point("/static", (root / "public").string()));
    httplib::Client http("127.0.0.1", h.port);
    auto res = http.Get("/static/index.html");
    ASSERT_TRUE(res);
    EXPECT_EQ(res->status, 200);
    EXPECT_EQ(res->body, "<h1>devsurf</h1>");
    res = http.Get("/static/sub/a.txt");
    ASSERT_TRUE(res);
    EXPECT_EQ(res->body, "in sub");

    for (const std::string path :
         {"/static/../secret.txt", "/static/sub/../../secret.txt", "/static/%2e%2e/secret.txt",
          "/static/..%2fsecret.txt", "/static/sub/%2E%2E/%2E%2E/secret.txt"}) {
      // Raw socket: the path is sent exactly as written.
      const int fd = rawConnect(h.port);
      ASSERT_GE(fd, 0);
      rawSend(fd, "GET " + path + " HTTP/1.1\r\nHost: 127.0.0.1\r\nConnection: close\r\n\r\n");
      const auto response = rawReadResponse(fd);
      ::close(fd);
      EXPECT_EQ(response.find("TOP SECRET"), std::string::npos) << path;
      EXPECT_EQ(response.rfind("HTTP/1.1 200", 0), std::string::npos) << path << "\n"
                                                                      << response;
    }
  }
  fs::remove_all(root);
}

TEST(TransportTest, BindErrorsAndServeWithoutBind) {
  Recorder recorder;
  Server a(recorder.handlers());
  const int port = a.bind("127.0.0.1", 0);
  EXPECT_GT(port, 0);
  EXPECT_EQ(a.port(), port);
  Server b(recorder.handlers());
  EXPECT_THROW(b.serve(), std::runtime_error);
  b.stop();
  b.serve();  // returns at once after stop()
  a.stop();   // bound but never served: closes the listening socket
  Client ws;
  EXPECT_THROW(ws.connect("127.0.0.1", port, "/ws", 1s), std::runtime_error);
}

}  // namespace
}  // namespace devsurf::server::transport
