// The web app served from memory (issue 16 item 8): encodings decoded with libbrotli and zlib
// themselves, ETags and 304, cache headers, HEAD, 404 and no way out of the web root — through a
// real transport::Server, so httplib's own compression step is part of what is tested.
#include "devsurf/server/StaticAssets.h"

#include <arpa/inet.h>
#include <brotli/decode.h>
#include <brotli/encode.h>
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <sys/time.h>
#include <unistd.h>
#include <zlib.h>

#include <cctype>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <string>
#include <thread>

#include "devsurf/server/transport/Server.h"
#include "support/TempDir.h"

namespace devsurf::server {
namespace {

namespace fs = std::filesystem;

void assetsWrite(const fs::path& file, const std::string& bytes) {
  fs::create_directories(file.parent_path());
  std::ofstream(file, std::ios::binary) << bytes;
}

std::string assetsBrotliDecode(const std::string& encoded) {
  std::string out(16u << 20, '\0');
  std::size_t size = out.size();
  if (BrotliDecoderDecompress(encoded.size(), reinterpret_cast<const std::uint8_t*>(encoded.data()), &size,
                              reinterpret_cast<std::uint8_t*>(out.data())) != BROTLI_DECODER_RESULT_SUCCESS)
    return "<not brotli>";
  out.resize(size);
  return out;
}

std::string assetsBrotliEncode(const std::string& bytes, int quality) {
  std::string out(BrotliEncoderMaxCompressedSize(bytes.size()), '\0');
  std::size_t size = out.size();
  BrotliEncoderCompress(quality, BROTLI_DEFAULT_WINDOW, BROTLI_MODE_TEXT, bytes.size(),
                        reinterpret_cast<const std::uint8_t*>(bytes.data()), &size,
                        reinterpret_cast<std::uint8_t*>(out.data()));
  out.resize(size);
  return out;
}

std::string assetsGunzip(const std::string& encoded) {
  z_stream z{};
  inflateInit2(&z, 15 + 16);
  std::string out(16u << 20, '\0');
  z.next_in = reinterpret_cast<Bytef*>(const_cast<char*>(encoded.data()));
  z.avail_in = static_cast<uInt>(encoded.size());
  z.next_out = reinterpret_cast<Bytef*>(out.data());
  z.avail_out = static_cast<uInt>(out.size());
  const int rc = inflate(&z, Z_FINISH);
  out.resize(z.total_out);
  inflateEnd(&z);
  return rc == Z_STREAM_END ? out : "<not gzip>";
}

std::string assetsGzip(const std::string& bytes, int level) {
  z_stream z{};
  deflateInit2(&z, level, Z_DEFLATED, 15 + 16, 8, Z_DEFAULT_STRATEGY);
  std::string out(deflateBound(&z, static_cast<uLong>(bytes.size())) + 32, '\0');
  z.next_in = reinterpret_cast<Bytef*>(const_cast<char*>(bytes.data()));
  z.avail_in = static_cast<uInt>(bytes.size());
  z.next_out = reinterpret_cast<Bytef*>(out.data());
  z.avail_out = static_cast<uInt>(out.size());
  deflate(&z, Z_FINISH);
  out.resize(z.total_out);
  deflateEnd(&z);
  return out;
}

struct AssetsResponse {
  int status = 0;
  std::map<std::string, std::string> headers;  ///< names in lowercase
  std::string body;
  std::string header(const std::string& name) const {
    const auto it = headers.find(name);
    return it == headers.end() ? std::string() : it->second;
  }
};

/// One request over a raw socket ("Connection: close" added), read until the server closes.
AssetsResponse assetsRequest(int port, const std::string& method, const std::string& target,
                             const std::string& extraHeaders = "") {
  AssetsResponse r;
  const int fd = ::socket(AF_INET, SOCK_STREAM, 0);
  sockaddr_in addr{};
  addr.sin_family = AF_INET;
  addr.sin_port = htons(static_cast<std::uint16_t>(port));
  addr.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  if (::connect(fd, reinterpret_cast<sockaddr*>(&addr), sizeof(addr)) != 0) {
    ::close(fd);
    return r;
  }
  timeval tv{5, 0};
  ::setsockopt(fd, SOL_SOCKET, SO_RCVTIMEO, &tv, sizeof(tv));
  const std::string request =
      method + " " + target + " HTTP/1.1\r\nHost: 127.0.0.1\r\nConnection: close\r\n" + extraHeaders + "\r\n";
  ::send(fd, request.data(), request.size(), MSG_NOSIGNAL);
  std::string data;
  char buf[65536];
  for (;;) {
    const auto n = ::recv(fd, buf, sizeof(buf), 0);
    if (n <= 0) break;
    data.append(buf, static_cast<std::size_t>(n));
  }
  ::close(fd);
  const std::size_t headEnd = data.find("\r\n\r\n");
  if (headEnd == std::string::npos || data.size() < 12) return r;
  r.status = std::stoi(data.substr(9, 3));
  std::size_t line = data.find("\r\n") + 2;
  while (line < headEnd) {
    const std::size_t next = data.find("\r\n", line);
    const std::string field = data.substr(line, next - line);
    const std::size_t colon = field.find(':');
    std::string name = field.substr(0, colon);
    for (char& c : name) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    std::string value = field.substr(colon + 1);
    while (!value.empty() && value.front() == ' ') value.erase(0, 1);
    r.headers[name] = value;
    line = next + 2;
  }
  r.body = data.substr(headEnd + 4);
  return r;
}

/// Text that compresses well, `lines` lines long.
std::string assetsScript(int lines) {
  std::string s;
  for (int i = 0; i < lines; ++i) s += "export const value" + std::to_string(i) + " = () => 'devsurf " + std::to_string(i % 7) + "';\n";
  return s;
}

/// A web root under a temp folder (with a secret file next to it) served by a transport::Server.
class StaticAssetsServer : public ::testing::Test {
 protected:
  void SetUp() override {
    root = dir.path() / "web";
    index = "<!doctype html><html><head><title>devsurf</title></head><body>" + std::string(600, ' ') +
            "<script type=module src=./assets/x-abc123.js></script></body></html>\n";
    script = assetsScript(400);
    png = std::string("\x89PNG\r\n\x1a\n", 8) + std::string(2000, '\x07');
    assetsWrite(root / "index.html", index);
    assetsWrite(root / "assets" / "x-abc123.js", script);
    assetsWrite(root / "assets" / "logo.png", png);
    assetsWrite(dir.path() / "secret.txt", "the secret");
  }
  void TearDown() override {
    if (server) server->stop();
    if (thread.joinable()) thread.join();
  }
  void start(const StaticAssetsOptions& options = {}) {
    assets = StaticAssets::load(root, options);
    server = std::make_unique<transport::Server>(transport::WebSocketHandlers{});
    server->Get("/api/hello", [](const httplib::Request&, httplib::Response& res) { res.set_content("hello", "text/plain"); });
    assets.install(*server);
    port = server->bind("127.0.0.1", 0);
    thread = std::thread([this] { server->serve(); });
  }

  devsurf::testing::TempDir dir{"devsurf-static"};
  fs::path root;
  std::string index, script, png;
  StaticAssets assets;
  std::unique_ptr<transport::Server> server;
  std::thread thread;
  int port = 0;
};

TEST(StaticAssetsNegotiation, FollowsAcceptEncodingWeights) {
  EXPECT_EQ(negotiateEncoding("gzip, deflate, br, zstd", true, true), "br");
  EXPECT_EQ(negotiateEncoding("gzip, deflate", true, true), "gzip");
  EXPECT_EQ(negotiateEncoding("", true, true), "") << "no Accept-Encoding: identity";
  EXPECT_EQ(negotiateEncoding("br;q=0, gzip", true, true), "gzip");
  EXPECT_EQ(negotiateEncoding("br;q=0,gzip;q=0", true, true), "");
  EXPECT_EQ(negotiateEncoding("gzip;q=0.5, br;q=0.4", true, true), "gzip");
  EXPECT_EQ(negotiateEncoding("identity;q=1, gzip;q=0.5", true, true), "");
  EXPECT_EQ(negotiateEncoding("identity", true, true), "");
  EXPECT_EQ(negotiateEncoding("*", true, true), "br");
  EXPECT_EQ(negotiateEncoding("*;q=0", true, true), "");
  EXPECT_EQ(negotiateEncoding("gzip;q=0, *", true, true), "br");
  EXPECT_EQ(negotiateEncoding("BR ; Q=1", true, true), "br");
  EXPECT_EQ(negotiateEncoding("br, gzip", false, true), "gzip");
  EXPECT_EQ(negotiateEncoding("br", false, false), "");
  EXPECT_EQ(negotiateEncoding("br;q=nonsense, gzip", true, true), "gzip");
}

TEST_F(StaticAssetsServer, BrotliAndGzipBodiesDecodeToTheFile) {
  start();
  const AssetsResponse br = assetsRequest(port, "GET", "/assets/x-abc123.js", "Accept-Encoding: gzip, deflate, br\r\n");
  ASSERT_EQ(br.status, 200);
  EXPECT_EQ(br.header("content-encoding"), "br");
  EXPECT_EQ(br.header("content-type"), "text/javascript; charset=utf-8");
  EXPECT_EQ(br.header("vary"), "Accept-Encoding");
  EXPECT_EQ(br.header("content-length"), std::to_string(br.body.size()));
  EXPECT_LT(br.body.size(), script.size() / 4);
  EXPECT_EQ(assetsBrotliDecode(br.body), script) << "compressed once, not twice";

  const AssetsResponse gz = assetsRequest(port, "GET", "/assets/x-abc123.js", "Accept-Encoding: gzip\r\n");
  ASSERT_EQ(gz.status, 200);
  EXPECT_EQ(gz.header("content-encoding"), "gzip");
  EXPECT_EQ(gz.header("content-type"), "text/javascript; charset=utf-8");
  EXPECT_EQ(assetsGunzip(gz.body), script);

  const AssetsResponse noBr = assetsRequest(port, "GET", "/assets/x-abc123.js", "Accept-Encoding: br;q=0, gzip;q=0.8\r\n");
  EXPECT_EQ(noBr.header("content-encoding"), "gzip");
  EXPECT_EQ(assetsGunzip(noBr.body), script);
}

TEST_F(StaticAssetsServer, IdentityWithoutAcceptEncoding) {
  start();
  const AssetsResponse r = assetsRequest(port, "GET", "/assets/x-abc123.js");
  ASSERT_EQ(r.status, 200);
  EXPECT_EQ(r.header("content-encoding"), "");
  EXPECT_EQ(r.header("vary"), "Accept-Encoding");
  EXPECT_EQ(r.body, script);
  // Explicitly refused codings: identity too.
  EXPECT_EQ(assetsRequest(port, "GET", "/assets/x-abc123.js", "Accept-Encoding: identity\r\n").body, script);
}

TEST_F(StaticAssetsServer, CacheHeadersAndETags) {
  start();
  const AssetsResponse js = assetsRequest(port, "GET", "/assets/x-abc123.js", "Accept-Encoding: br\r\n");
  EXPECT_EQ(js.header("cache-control"), "public, max-age=31536000, immutable");
  const std::string etag = js.header("etag");
  ASSERT_EQ(etag.size(), 2u + 24u + 3u) << etag;
  EXPECT_EQ(etag.front(), '"');
  EXPECT_EQ(etag.substr(etag.size() - 4), "-br\"");
  const std::string identityTag = assetsRequest(port, "GET", "/assets/x-abc123.js").header("etag");
  EXPECT_NE(identityTag, etag) << "one strong ETag per representation";
  EXPECT_EQ(assetsRequest(port, "GET", "/assets/x-abc123.js", "Accept-Encoding: gzip\r\n").header("etag"),
            identityTag.substr(0, identityTag.size() - 1) + "-gz\"");

  for (const char* target : {"/", "/index.html", "/?session=demo&token=abc"}) {
    const AssetsResponse page = assetsRequest(port, "GET", target);
    ASSERT_EQ(page.status, 200) << target;
    EXPECT_EQ(page.body, index) << target;
    EXPECT_EQ(page.header("cache-control"), "no-cache") << target;
    EXPECT_EQ(page.header("content-type"), "text/html; charset=utf-8") << target;
    EXPECT_FALSE(page.header("etag").empty()) << target;
  }
}

TEST_F(StaticAssetsServer, IfNoneMatchGives304) {
  start();
  const std::string ae = "Accept-Encoding: gzip, br\r\n";
  const std::string etag = assetsRequest(port, "GET", "/assets/x-abc123.js", ae).header("etag");
  const AssetsResponse same = assetsRequest(port, "GET", "/assets/x-abc123.js", ae + "If-None-Match: " + etag + "\r\n");
  EXPECT_EQ(same.status, 304);
  EXPECT_TRUE(same.body.empty());
  EXPECT_EQ(same.header("etag"), etag);
  EXPECT_EQ(same.header("cache-control"), "public, max-age=31536000, immutable");
  EXPECT_EQ(same.header("vary"), "Accept-Encoding");
  EXPECT_EQ(assetsRequest(port, "GET", "/assets/x-abc123.js", ae + "If-None-Match: \"other\", W/" + etag + "\r\n").status, 304)
      << "a list, weak comparison";
  EXPECT_EQ(assetsRequest(port, "GET", "/assets/x-abc123.js", ae + "If-None-Match: *\r\n").status, 304);
  EXPECT_EQ(assetsRequest(port, "GET", "/assets/x-abc123.js", ae + "If-None-Match: \"other\"\r\n").status, 200);
  // The br tag does not validate the gzip representation.
  const AssetsResponse gz = assetsRequest(port, "GET", "/assets/x-abc123.js", "Accept-Encoding: gzip\r\nIf-None-Match: " + etag + "\r\n");
  EXPECT_EQ(gz.status, 200);
  EXPECT_EQ(assetsGunzip(gz.body), script);

  const std::string pageTag = assetsRequest(port, "GET", "/").header("etag");
  const AssetsResponse page = assetsRequest(port, "GET", "/?session=x", "If-None-Match: " + pageTag + "\r\n");
  EXPECT_EQ(page.status, 304);
  EXPECT_EQ(page.header("cache-control"), "no-cache");
}

TEST_F(StaticAssetsServer, HeadHasTheHeadersOfGetAndNoBody) {
  start();
  const std::string ae = "Accept-Encoding: br\r\n";
  const AssetsResponse get = assetsRequest(port, "GET", "/assets/x-abc123.js", ae);
  const AssetsResponse head = assetsRequest(port, "HEAD", "/assets/x-abc123.js", ae);
  ASSERT_EQ(head.status, 200);
  EXPECT_TRUE(head.body.empty());
  EXPECT_EQ(head.header("content-length"), std::to_string(get.body.size()));
  EXPECT_EQ(head.header("content-encoding"), "br");
  EXPECT_EQ(head.header("content-type"), "text/javascript; charset=utf-8");
  EXPECT_EQ(head.header("etag"), get.header("etag"));
}

TEST_F(StaticAssetsServer, BinaryFilesAreSentAsTheyAre) {
  start();
  const AssetsResponse r = assetsRequest(port, "GET", "/assets/logo.png", "Accept-Encoding: gzip, br\r\n");
  ASSERT_EQ(r.status, 200);
  EXPECT_EQ(r.body, png);
  EXPECT_EQ(r.header("content-type"), "image/png");
  EXPECT_EQ(r.header("content-encoding"), "");
  EXPECT_EQ(r.header("vary"), "");
}

TEST_F(StaticAssetsServer, MissingFilesAndOtherPathsGoToTheRoutes) {
  start();
  EXPECT_EQ(assetsRequest(port, "GET", "/assets/missing.js").status, 404);
  EXPECT_EQ(assetsRequest(port, "GET", "/nothing").status, 404);
  EXPECT_EQ(assetsRequest(port, "HEAD", "/assets/missing.js").status, 404);
  EXPECT_EQ(assetsRequest(port, "POST", "/index.html", "Content-Length: 0\r\n").status, 404);
  const AssetsResponse hello = assetsRequest(port, "GET", "/api/hello", "Accept-Encoding: br\r\n");
  EXPECT_EQ(hello.status, 200);
  EXPECT_EQ(assetsBrotliDecode(hello.body), "hello") << "the routes' bodies are compressed by httplib, as before";
}

TEST_F(StaticAssetsServer, NoPathLeavesTheWebRoot) {
  start();
  for (const char* target : {"/../secret.txt", "/%2e%2e/secret.txt", "/assets/../../secret.txt",
                                    "/assets/%2E%2E/%2E%2E/secret.txt", "//secret.txt", "/..%2fsecret.txt",
                                    "/assets/..%2F..%2Fsecret.txt", "/./../secret.txt"}) {
    const AssetsResponse r = assetsRequest(port, "GET", target);
    EXPECT_NE(r.status, 200) << target;
    EXPECT_EQ(r.body.find("the secret"), std::string::npos) << target;
  }
  // Written after load(): not served either.
  assetsWrite(root / "late.txt", "written later");
  EXPECT_EQ(assetsRequest(port, "GET", "/late.txt").status, 404);
}

TEST_F(StaticAssetsServer, UsesValidPrecompressedSiblingsOnly) {
  // A valid FILE.gz (level 1, so it differs from what load() would make at level 9) and a stale
  // FILE.br (another file's bytes).
  const std::string gzSibling = assetsGzip(script, 1);
  ASSERT_NE(gzSibling, assetsGzip(script, 9));
  assetsWrite(root / "assets" / "x-abc123.js.gz", gzSibling);
  assetsWrite(root / "assets" / "x-abc123.js.br", assetsBrotliEncode(assetsScript(300), 5));
  start();
  const AssetsResponse gz = assetsRequest(port, "GET", "/assets/x-abc123.js", "Accept-Encoding: gzip\r\n");
  EXPECT_EQ(gz.body, gzSibling) << "the build's FILE.gz, as it is";
  const AssetsResponse br = assetsRequest(port, "GET", "/assets/x-abc123.js", "Accept-Encoding: br\r\n");
  EXPECT_EQ(assetsBrotliDecode(br.body), script) << "the stale FILE.br is not used";
  EXPECT_EQ(assetsRequest(port, "GET", "/assets/x-abc123.js.gz").status, 404) << "siblings are no files of their own";
  EXPECT_EQ(assets.fileCount(), 3u);
  EXPECT_EQ(assets.totalBytes(), index.size() + script.size() + png.size());
}

TEST_F(StaticAssetsServer, LoadRefusesWhatItCannotServe) {
  StaticAssetsOptions small;
  small.maxTotalBytes = 1000;
  EXPECT_THROW(StaticAssets::load(root, small), std::runtime_error);
  StaticAssetsOptions few;
  few.maxFiles = 2;
  EXPECT_THROW(StaticAssets::load(root, few), std::runtime_error);
  EXPECT_THROW(StaticAssets::load(dir.path() / "missing"), std::runtime_error);
  EXPECT_THROW(StaticAssets::load(dir.path() / "secret.txt"), std::runtime_error);
  StaticAssetsOptions badQuality;
  badQuality.brotliQuality = 12;
  EXPECT_THROW(StaticAssets::load(root, badQuality), std::invalid_argument);
}

TEST(StaticAssetsDefaultRoot, FindsTheBuiltAppNextToTheSourcesOrTheExecutable) {
  devsurf::testing::TempDir dir{"devsurf-webroot"};
  const fs::path tree = dir.path() / "tree";
  assetsWrite(tree / "web" / "dist" / "index.html", "<!doctype html>");
  fs::create_directories(tree / "build" / "server");
  fs::create_directories(dir.path() / "elsewhere");
  EXPECT_EQ(defaultWebRoot(tree, dir.path() / "elsewhere"), tree / "web" / "dist") << "the working directory";
  EXPECT_EQ(defaultWebRoot(dir.path() / "elsewhere", tree / "build" / "server"), tree / "web" / "dist")
      << "a build tree's executable";
  assetsWrite(dir.path() / "usr" / "share" / "devsurf" / "web" / "dist" / "index.html", "<!doctype html>");
  fs::create_directories(dir.path() / "usr" / "bin");
  EXPECT_EQ(defaultWebRoot(dir.path() / "elsewhere", dir.path() / "usr" / "bin"),
            dir.path() / "usr" / "share" / "devsurf" / "web" / "dist")
      << "an installed layout";
  EXPECT_TRUE(defaultWebRoot(dir.path() / "elsewhere", dir.path() / "elsewhere").empty());
}

}  // namespace
}  // namespace devsurf::server
