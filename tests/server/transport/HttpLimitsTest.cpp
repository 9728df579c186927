// The HTTP side of the transport under slow, idle, oversized and non-reading clients: every limit
// answers with its status and a JSON error, deadlines hold for the whole head or body, and no
// such client holds a route worker. Every test runs its own server on an ephemeral port.
#include <atomic>
#include <string>
#include <thread>
#include <vector>

#include "server/transport/TransportTesting.h"

namespace devsurf::server::transport {
namespace {

using namespace std::chrono_literals;
using namespace devsurf::server::transport::testing;

std::string get(const std::string& path, const std::string& extra = {}) {
  return "GET " + path + " HTTP/1.1\r\nHost: 127.0.0.1\r\n" + extra + "\r\n";
}

bool hasErrorCode(const std::string& response, const std::string& code) {
  return bodyOf(response).find("{\"error\":{\"code\":\"" + code + "\",\"message\":") == 0;
}

/// POST /api/echo answers with the body it got and the framing headers httplib saw.
void addEcho(Server& server, std::atomic<int>& calls) {
  server.Post("/api/echo", [&calls](const httplib::Request& req, httplib::Response& res) {
    ++calls;
    res.set_header("X-Seen-Length", req.get_header_value("Content-Length"));
    res.set_header("X-Seen-Chunked", req.has_header("Transfer-Encoding") ? "yes" : "no");
    res.set_content(req.body, "text/plain");
  });
}

TEST(HttpLimitsTest, AHeadOverTheSizeLimitIsAnswered431AndTheServerKeepsServing) {
  Harness h;
  RawClient client(h.port);
  std::string filler;
  for (int i = 0; i < 10000; ++i) filler += "X-Filler-" + std::to_string(i) + ": v\r\n";
  ASSERT_TRUE(client.send(get("/api/hello", filler)));
  const auto response = client.readResponse();
  EXPECT_EQ(statusOf(response), 431) << response;
  EXPECT_TRUE(hasErrorCode(response, "too_large")) << response;
  EXPECT_NE(response.find("16384 bytes"), std::string::npos) << response;
  EXPECT_TRUE(client.closedByServer());

  httplib::Client http("127.0.0.1", h.port);
  auto res = http.Get("/api/hello");
  ASSERT_TRUE(res);
  EXPECT_EQ(res->status, 200);
}

TEST(HttpLimitsTest, MoreHeaderFieldsThanTheLimitAre431AndTheLimitItselfIsServed) {
  TransportLimits limits;
  limits.http.maxHeaderFields = 20;
  Harness h(limits);
  auto fields = [](int n) {
    std::string s;
    for (int i = 0; i < n; ++i) s += "X-F" + std::to_string(i) + ": v\r\n";
    return s;
  };
  RawClient atLimit(h.port);
  ASSERT_TRUE(atLimit.send(get("/api/hello", fields(19))));  // + Host = 20
  EXPECT_EQ(statusOf(atLimit.readResponse()), 200);

  RawClient overLimit(h.port);
  ASSERT_TRUE(overLimit.send(get("/api/hello", fields(20))));
  const auto response = overLimit.readResponse();
  EXPECT_EQ(statusOf(response), 431) << response;
  EXPECT_TRUE(hasErrorCode(response, "too_large")) << response;
  EXPECT_NE(response.find("21 header fields (limit 20)"), std::string::npos) << response;
}

TEST(HttpLimitsTest, AChunkedBodyReachesTheRouteDecodedWithAContentLength) {
  Harness h;
  std::atomic<int> calls{0};
  addEcho(*h.server, calls);
  RawClient client(h.port);
  ASSERT_TRUE(client.send("POST /api/echo HTTP/1.1\r\nHost: 127.0.0.1\r\n"
                          "Transfer-Encoding: chunked\r\n\r\n"
                          "5\r\nhello\r\n6\r\n world\r\n0\r\n\r\n"));
  const auto response = client.readResponse();
  EXPECT_EQ(statusOf(response), 200) << response;
  EXPECT_EQ(bodyOf(response), "hello world");
  EXPECT_NE(response.find("X-Seen-Length: 11\r\n"), std::string::npos) << response;
  EXPECT_NE(response.find("X-Seen-Chunked: no\r\n"), std::string::npos) << response;
  EXPECT_EQ(calls, 1);
}

TEST(HttpLimitsTest, AChunkedBodyOverTheLimitIs413AsSoonAsItCrossesTheLimit) {
  TransportLimits limits;
  limits.http.maxBodyBytes = 64 * 1024;
  limits.http.bodyTimeout = 60s;  // the answer must not wait for the body's end or deadline
  Harness h(limits);
  std::atomic<int> calls{0};
  addEcho(*h.server, calls);
  RawClient client(h.port);
  ASSERT_TRUE(client.send("POST /api/echo HTTP/1.1\r\nHost: 127.0.0.1\r\n"
                          "Transfer-Encoding: chunked\r\n\r\n"));
  const std::string chunk = "4000\r\n" + std::string(0x4000, 'a') + "\r\n";  // 16 KiB
  for (int i = 0; i < 5; ++i) ASSERT_TRUE(client.send(chunk));  // 80 KiB, and no last chunk
  const auto response = client.readResponse();
  EXPECT_EQ(statusOf(response), 413) << response;
  EXPECT_TRUE(hasErrorCode(response, "too_large")) << response;
  EXPECT_NE(response.find("65536 bytes"), std::string::npos) << response;
  EXPECT_TRUE(client.closedByServer());
  EXPECT_EQ(calls, 0);

  // Just under the limit is served.
  RawClient fits(h.port);
  std::string body = "POST /api/echo HTTP/1.1\r\nHost: 127.0.0.1\r\nTransfer-Encoding: chunked\r\n\r\n";
  for (int i = 0; i < 4; ++i) body += chunk;
  ASSERT_TRUE(fits.send(body + "0\r\n\r\n"));
  const auto served = fits.readResponse();
  EXPECT_EQ(statusOf(served), 200);
  EXPECT_EQ(bodyOf(served).size(), 64u * 1024u);
}

TEST(HttpLimitsTest, AContentLengthOverTheLimitIs413BeforeTheBodyIsSent) {
  TransportLimits limits;
  limits.http.maxBodyBytes = 64 * 1024;
  Harness h(limits);
  std::atomic<int> calls{0};
  addEcho(*h.server, calls);
  RawClient client(h.port);
  ASSERT_TRUE(client.send("POST /api/echo HTTP/1.1\r\nHost: 127.0.0.1\r\nContent-Length: 65537\r\n\r\n"));
  const auto response = client.readResponse();
  EXPECT_EQ(statusOf(response), 413) << response;
  EXPECT_TRUE(hasErrorCode(response, "too_large")) << response;
  EXPECT_EQ(calls, 0);
}

TEST(HttpLimitsTest, AHeadThatDoesNotArriveInTimeIs408AndASilentConnectionIsClosed) {
  TransportLimits limits;
  limits.http.headerTimeout = 1s;
  Harness h(limits);
  RawClient slow(h.port);
  ASSERT_TRUE(slow.send("GET /api/hello HTTP/1.1\r\nHost: 127"));
  std::this_thread::sleep_for(100ms);
  ASSERT_TRUE(slow.send(".0.0.1\r\n"));  // progress does not extend the deadline
  const auto response = slow.readResponse();
  EXPECT_EQ(statusOf(response), 408) << response;
  EXPECT_TRUE(hasErrorCode(response, "timeout")) << response;
  EXPECT_NE(response.find("1000 ms"), std::string::npos) << response;
  EXPECT_TRUE(slow.closedByServer());

  RawClient silent(h.port);
  EXPECT_TRUE(silent.closedByServer());  // closed, without an answer
}

TEST(HttpLimitsTest, ABodyThatDoesNotArriveInTimeIs408) {
  TransportLimits limits;
  limits.http.bodyTimeout = 300ms;
  Harness h(limits);
  std::atomic<int> calls{0};
  addEcho(*h.server, calls);
  RawClient client(h.port);
  ASSERT_TRUE(client.send("POST /api/echo HTTP/1.1\r\nHost: 127.0.0.1\r\nContent-Length: 100\r\n\r\n"
                          "0123456789"));
  const auto response = client.readResponse();
  EXPECT_EQ(statusOf(response), 408) << response;
  EXPECT_TRUE(hasErrorCode(response, "timeout")) << response;
  EXPECT_NE(response.find("body"), std::string::npos) << response;
  EXPECT_EQ(calls, 0);
}

TEST(HttpLimitsTest, SlowClientsHoldNoWorkerWhileRestAndWebSocketsKeepAnswering) {
  TransportLimits limits;
  limits.http.workers = 1;
  Harness h(limits);
  constexpr int kSlow = 40;
  std::vector<std::unique_ptr<RawClient>> slow;
  for (int i = 0; i < kSlow; ++i) {
    slow.push_back(std::make_unique<RawClient>(h.port, 200ms));
    ASSERT_TRUE(slow.back()->send("GET /api/hello HTTP/1.1\r\nHo"));
  }
  for (auto& client : slow) ASSERT_TRUE(client->send("s"));  // a byte at a time, never finishing

  httplib::Client http("127.0.0.1", h.port);
  http.set_read_timeout(10, 0);
  for (int i = 0; i < 3; ++i) {
    auto res = http.Get("/api/hello");
    ASSERT_TRUE(res) << "request " << i;
    EXPECT_EQ(res->status, 200);
  }
  Client ws;
  ws.connect("127.0.0.1", h.port);
  ws.send("still here");
  EXPECT_EQ(ws.receive(10s), std::optional<std::string>("still here"));
  // The slow clients were still connected and unanswered all along.
  for (auto& client : slow) EXPECT_FALSE(client->readable());
}

TEST(HttpLimitsTest, AClientThatDoesNotReadItsResponseHoldsNoWorkerAndIsDropped) {
  TransportLimits limits;
  limits.http.workers = 1;
  limits.http.writeTimeout = 500ms;
  Harness h(limits);
  constexpr std::size_t kBig = 32u << 20;  // far more than the socket buffers hold
  h.server->Get("/api/big", [](const httplib::Request&, httplib::Response& res) {
    res.set_content(std::string(kBig, 'b'), "application/octet-stream");
  });
  RawClient reader(h.port);
  ASSERT_TRUE(reader.send(get("/api/big")));  // and does not read (yet)

  httplib::Client http("127.0.0.1", h.port);
  http.set_read_timeout(10, 0);
  auto res = http.Get("/api/hello");
  ASSERT_TRUE(res);
  EXPECT_EQ(res->status, 200);

  std::this_thread::sleep_for(2500ms);  // well past the write deadline
  const auto response = reader.readResponse();
  EXPECT_EQ(statusOf(response), 200);
  EXPECT_LT(bodyOf(response).size(), kBig) << "the response was not cut at the write deadline";
}

TEST(HttpLimitsTest, ConnectionsFromOneAddressAreCappedWith503) {
  TransportLimits limits;
  limits.http.maxConnectionsPerAddress = 4;
  Harness h(limits);
  std::vector<std::unique_ptr<RawClient>> held;
  for (int i = 0; i < 4; ++i) held.push_back(std::make_unique<RawClient>(h.port));
  RawClient fifth(h.port);
  ASSERT_TRUE(fifth.send(get("/api/hello")));
  const auto response = fifth.readResponse();
  EXPECT_EQ(statusOf(response), 503) << response;
  EXPECT_TRUE(hasErrorCode(response, "limit")) << response;
  EXPECT_NE(response.find("from 127.0.0.1 (limit 4)"), std::string::npos) << response;

  // The held connections are served, and a slot frees up when one closes.
  ASSERT_TRUE(held[0]->send(get("/api/hello")));
  EXPECT_EQ(statusOf(held[0]->readResponse()), 200);
  held.pop_back();
  const auto deadline = std::chrono::steady_clock::now() + 5s;
  int status = 0;
  while (status != 200 && std::chrono::steady_clock::now() < deadline) {
    RawClient again(h.port);
    again.send(get("/api/hello"));
    status = statusOf(again.readResponse());
    if (status != 200) std::this_thread::sleep_for(20ms);
  }
  EXPECT_EQ(status, 200);
}

TEST(HttpLimitsTest, KeepAliveServesSequentialAndPipelinedRequestsUpToItsCount) {
  TransportLimits limits;
  limits.http.maxRequestsPerConnection = 3;
  Harness h(limits);
  RawClient client(h.port);
  ASSERT_TRUE(client.send(get("/api/hello")));
  const auto first = client.readResponse();
  EXPECT_EQ(statusOf(first), 200);
  EXPECT_EQ(bodyOf(first), "hello");
  EXPECT_NE(first.find("Keep-Alive: "), std::string::npos) << first;
  ASSERT_TRUE(client.send(get("/api/hello") + get("/nothing-here")));  // pipelined
  const auto second = client.readResponse();
  const auto third = client.readResponse();
  EXPECT_EQ(statusOf(second), 200);
  EXPECT_EQ(statusOf(third), 404);
  EXPECT_NE(third.find("Connection: close"), std::string::npos) << third;  // the third of 3
  EXPECT_TRUE(client.closedByServer());
}

TEST(HttpLimitsTest, AnIdleKeptAliveConnectionIsClosed) {
  TransportLimits limits;
  limits.http.keepAliveTimeout = 300ms;
  Harness h(limits);
  RawClient client(h.port);
  ASSERT_TRUE(client.send(get("/api/hello")));
  EXPECT_EQ(statusOf(client.readResponse()), 200);
  EXPECT_TRUE(client.closedByServer());
}

TEST(HttpLimitsTest, ExpectContinueIsAnsweredBeforeTheBody) {
  Harness h;
  std::atomic<int> calls{0};
  addEcho(*h.server, calls);
  RawClient client(h.port);
  ASSERT_TRUE(client.send("POST /api/echo HTTP/1.1\r\nHost: 127.0.0.1\r\nContent-Length: 5\r\n"
                          "Expect: 100-continue\r\n\r\n"));
  EXPECT_EQ(statusOf(client.readResponse()), 100);
  ASSERT_TRUE(client.send("hello"));
  const auto response = client.readResponse();
  EXPECT_EQ(statusOf(response), 200) << response;
  EXPECT_EQ(bodyOf(response), "hello");
}

TEST(HttpLimitsTest, CompressedAndMalformedRequestsAreRefusedWithJsonErrors) {
  Harness h;
  std::atomic<int> calls{0};
  addEcho(*h.server, calls);
  RawClient gzip(h.port);
  ASSERT_TRUE(gzip.send("POST /api/echo HTTP/1.1\r\nHost: 127.0.0.1\r\nContent-Encoding: gzip\r\n"
                        "Content-Length: 4\r\n\r\nabcd"));
  const auto refused = gzip.readResponse();
  EXPECT_EQ(statusOf(refused), 415) << refused;
  EXPECT_TRUE(hasErrorCode(refused, "unsupported")) << refused;

  RawClient garbage(h.port);
  ASSERT_TRUE(garbage.send("NOT HTTP AT ALL\r\n\r\n"));
  const auto malformed = garbage.readResponse();
  EXPECT_EQ(statusOf(malformed), 400) << malformed;
  EXPECT_TRUE(hasErrorCode(malformed, "invalid")) << malformed;
  EXPECT_EQ(calls, 0);
}

TEST(HttpLimitsTest, StopAnswersARequestInProgressThenCloses) {
  auto h = std::make_unique<Harness>();
  std::atomic<bool> started{false};
  h->server->Get("/api/slow", [&started](const httplib::Request&, httplib::Response& res) {
    started = true;
    std::this_thread::sleep_for(500ms);
    res.set_content("done", "text/plain");
  });
  RawClient client(h->port);
  ASSERT_TRUE(client.send(get("/api/slow")));
  const auto deadline = std::chrono::steady_clock::now() + 5s;
  while (!started && std::chrono::steady_clock::now() < deadline) std::this_thread::sleep_for(1ms);
  ASSERT_TRUE(started);
  h->server->stop();
  const auto response = client.readResponse();
  EXPECT_EQ(statusOf(response), 200) << response;
  EXPECT_EQ(bodyOf(response), "done");
  EXPECT_TRUE(client.closedByServer());
}

}  // namespace
}  // namespace devsurf::server::transport
