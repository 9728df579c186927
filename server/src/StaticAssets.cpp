// The web app in memory: precompressed representations, ETags, cache headers (see
// StaticAssets.h). Brotli through libbrotli, gzip through zlib, ETags from SHA-256 (Tokens.h).
#include "devsurf/server/StaticAssets.h"

#include <brotli/decode.h>
#include <brotli/encode.h>
#include <httplib.h>
#include <spdlog/spdlog.h>
#include <zlib.h>

#include <algorithm>
#include <cctype>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <string>
#include <system_error>
#include <unordered_map>
#include <utility>
#include <vector>

#include "devsurf/server/Tokens.h"

namespace devsurf::server {

namespace fs = std::filesystem;

namespace {

struct AssetType {
  const char* mediaType;
  bool compressible;
};

/// By the file name's extension (lowercase); unknown ones are application/octet-stream.
AssetType assetTypeOf(const fs::path& file) {
  std::string ext = file.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  static const std::unordered_map<std::string, AssetType> types = {
      {".html", {"text/html; charset=utf-8", true}},
      {".htm", {"text/html; charset=utf-8", true}},
      {".js", {"text/javascript; charset=utf-8", true}},
      {".mjs", {"text/javascript; charset=utf-8", true}},
      {".css", {"text/css; charset=utf-8", true}},
      {".json", {"application/json", true}},
      {".map", {"application/json", true}},
      {".webmanifest", {"application/manifest+json", true}},
      {".svg", {"image/svg+xml", true}},
      {".txt", {"text/plain; charset=utf-8", true}},
      {".xml", {"application/xml", true}},
      {".wasm", {"application/wasm", true}},
      {".png", {"image/png", false}},
      {".jpg", {"image/jpeg", false}},
      {".jpeg", {"image/jpeg", false}},
      {".gif", {"image/gif", false}},
      {".webp", {"image/webp", false}},
      {".avif", {"image/avif", false}},
      {".ico", {"image/x-icon", false}},
      {".woff", {"font/woff", false}},
      {".woff2", {"font/woff2", false}},
      {".ttf", {"font/ttf", false}},
      {".otf", {"font/otf", false}},
  };
  const auto it = types.find(ext);
  return it == types.end() ? AssetType{"application/octet-stream", false} : it->second;
}

std::string readAssetFile(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  if (!in) throw std::runtime_error("web root: cannot read " + file.string());
  std::ostringstream buffer;
  buffer << in.rdbuf();
  if (in.bad()) throw std::runtime_error("web root: cannot read " + file.string());
  return buffer.str();
}

std::string brotliCompress(const std::string& bytes, int quality, bool text) {
  std::string out(BrotliEncoderMaxCompressedSize(bytes.size()), '\0');
  std::size_t size = out.size();
  if (out.empty() ||
      !BrotliEncoderCompress(quality, BROTLI_DEFAULT_WINDOW, text ? BROTLI_MODE_TEXT : BROTLI_MODE_GENERIC, bytes.size(),
                             reinterpret_cast<const std::uint8_t*>(bytes.data()), &size,
                             reinterpret_cast<std::uint8_t*>(out.data())))
    throw std::runtime_error("web root: Brotli compression failed");
  out.resize(size);
  return out;
}

/// Whether `encoded` is a Brotli stream of exactly `original`.
bool brotliDecodesTo(const std::string& encoded, const std::string& original) {
  std::string decoded(original.size() + 1, '\0');  // one spare byte: a longer stream does not fit
  std::size_t size = decoded.size();
  if (BrotliDecoderDecompress(encoded.size(), reinterpret_cast<const std::uint8_t*>(encoded.data()), &size,
                              reinterpret_cast<std::uint8_t*>(decoded.data())) != BROTLI_DECODER_RESULT_SUCCESS)
    return false;
  return size == original.size() && decoded.compare(0, size, original) == 0;
}

std::string gzipCompress(const std::string& bytes, int level) {
  z_stream z{};
  if (deflateInit2(&z, level, Z_DEFLATED, 15 + 16, 8, Z_DEFAULT_STRATEGY) != Z_OK)
    throw std::runtime_error("web root: gzip compression failed");
  std::string out(deflateBound(&z, static_cast<uLong>(bytes.size())) + 32, '\0');
  z.next_in = reinterpret_cast<Bytef*>(const_cast<char*>(bytes.data()));
  z.avail_in = static_cast<uInt>(bytes.size());
  z.next_out = reinterpret_cast<Bytef*>(out.data());
  z.avail_out = static_cast<uInt>(out.size());
  const int rc = deflate(&z, Z_FINISH);
  const std::size_t size = z.total_out;
  deflateEnd(&z);
  if (rc != Z_STREAM_END) throw std::runtime_error("web root: gzip compression failed");
  out.resize(size);
  return out;
}

/// Whether `encoded` is one gzip member holding exactly `original`.
bool gzipDecodesTo(const std::string& encoded, const std::string& original) {
  z_stream z{};
  if (inflateInit2(&z, 15 + 16) != Z_OK) return false;
  std::string decoded(original.size() + 1, '\0');
  z.next_in = reinterpret_cast<Bytef*>(const_cast<char*>(encoded.data()));
  z.avail_in = static_cast<uInt>(encoded.size());
  z.next_out = reinterpret_cast<Bytef*>(decoded.data());
  z.avail_out = static_cast<uInt>(decoded.size());
  const int rc = inflate(&z, Z_FINISH);
  const std::size_t size = z.total_out;
  inflateEnd(&z);
  return rc == Z_STREAM_END && size == original.size() && decoded.compare(0, size, original) == 0;
}

/// The sibling FILE.br / FILE.gz if it exists and decodes to `original`, else nullopt (a stale
/// sibling is reported and ignored).
std::optional<std::string> validSibling(const fs::path& file, const char* suffix, const std::string& original,
                                        bool (*decodesTo)(const std::string&, const std::string&)) {
  fs::path sibling = file;
  sibling += suffix;
  std::error_code ec;
  if (!fs::is_regular_file(sibling, ec)) return std::nullopt;
  std::string encoded = readAssetFile(sibling);
  if (decodesTo(encoded, original)) return encoded;
  spdlog::warn("web root: {} does not decode to {} (a stale build?): compressing it again", sibling.string(),
               file.string());
  return std::nullopt;
}

std::string trimmedField(const std::string& s, std::size_t begin, std::size_t end) {
  while (begin < end && (s[begin] == ' ' || s[begin] == '\t')) ++begin;
  while (end > begin && (s[end - 1] == ' ' || s[end - 1] == '\t')) --end;
  return s.substr(begin, end - begin);
}

/// Calls f(item) for each comma-separated, trimmed, non-empty item of a header value.
template <class F>
void forEachListItem(const std::string& value, F f) {
  std::size_t begin = 0;
  while (begin <= value.size()) {
    std::size_t end = value.find(',', begin);
    if (end == std::string::npos) end = value.size();
    const std::string item = trimmedField(value, begin, end);
    if (!item.empty()) f(item);
    begin = end + 1;
  }
}

/// A response header the post-routing handler turns into Content-Type (see install()).
constexpr const char* kDeferredContentType = "X-Devsurf-Deferred-Content-Type";

}  // namespace

struct StaticAssets::Table {
  struct Representation {
    std::shared_ptr<const std::string> bytes;
    std::string etag;
  };
  struct File {
    std::string contentType;
    std::string cacheControl;
    Representation identity;
    std::optional<Representation> br, gzip;
  };
  std::unordered_map<std::string, File> files;  ///< by URL path ("/index.html")
  std::size_t totalBytes = 0;
};

std::string negotiateEncoding(const std::string& acceptEncoding, bool brAvailable, bool gzipAvailable) {
  // q-values by coding; identity is acceptable unless excluded, but ranks below any listed coding.
  constexpr double kUnlisted = -1.0;
  double qBr = kUnlisted, qGzip = kUnlisted, qIdentity = kUnlisted, qStar = kUnlisted;
  forEachListItem(acceptEncoding, [&](const std::string& item) {
    const std::size_t semicolon = item.find(';');
    std::string coding = trimmedField(item, 0, semicolon == std::string::npos ? item.size() : semicolon);
    std::transform(coding.begin(), coding.end(), coding.begin(),
                   [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
    double q = 1.0;
    if (semicolon != std::string::npos) {
      const std::string params = trimmedField(item, semicolon + 1, item.size());
      if (params.size() >= 2 && (params[0] == 'q' || params[0] == 'Q') && params[1] == '=') {
        char* end = nullptr;
        q = std::strtod(params.c_str() + 2, &end);
        if (end == params.c_str() + 2 || !(q >= 0.0)) return;  // unreadable weight: ignore the item
        q = std::min(q, 1.0);
      }
    }
    if (coding == "br") qBr = q;
    else if (coding == "gzip" || coding == "x-gzip") qGzip = q;
    else if (coding == "identity") qIdentity = q;
    else if (coding == "*") qStar = q;
  });
  const auto weight = [&](double listed, double unlisted) { return listed != kUnlisted ? listed : unlisted; };
  const double starOrZero = qStar != kUnlisted ? qStar : 0.0;
  const double br = brAvailable ? weight(qBr, starOrZero) : 0.0;
  const double gzip = gzipAvailable ? weight(qGzip, starOrZero) : 0.0;
  // Unlisted identity: below every acceptable coding (q ≥ 0.001), unless "*" weighs it.
  const double identity = weight(qIdentity, qStar != kUnlisted ? qStar : 0.0005);
  if (br > 0.0 && br >= gzip && br >= identity) return "br";
  if (gzip > 0.0 && gzip >= identity) return "gzip";
  return "";  // identity, also when it was excluded: nothing else is there to send
}

StaticAssets StaticAssets::load(const fs::path& root, const StaticAssetsOptions& options) {
  if (options.brotliQuality < BROTLI_MIN_QUALITY || options.brotliQuality > BROTLI_MAX_QUALITY)
    throw std::invalid_argument("static assets: brotliQuality must be in [0, 11]");
  if (options.gzipLevel < 1 || options.gzipLevel > 9)
    throw std::invalid_argument("static assets: gzipLevel must be in [1, 9]");
  std::error_code ec;
  if (!fs::is_directory(root, ec))
    throw std::runtime_error("web root " + root.string() + ": not a folder (build the web app: npm --prefix web run build)");

  // The file list first (limits before reading), without FILE.br / FILE.gz siblings of a FILE.
  std::vector<fs::path> paths;  // relative to root
  std::size_t total = 0;
  fs::recursive_directory_iterator it(root, ec), end;
  if (ec) throw std::runtime_error("web root " + root.string() + ": " + ec.message());
  for (; it != end; it.increment(ec)) {
    if (ec) throw std::runtime_error("web root " + root.string() + ": " + ec.message());
    const fs::path& p = it->path();
    std::error_code fileEc;
    if (!fs::is_regular_file(p, fileEc)) continue;
    const std::string ext = p.extension().string();
    if ((ext == ".br" || ext == ".gz") && fs::is_regular_file(p.parent_path() / p.stem(), fileEc)) continue;
    if (paths.size() == options.maxFiles)
      throw std::runtime_error("web root " + root.string() + ": more than " + std::to_string(options.maxFiles) + " files");
    total += static_cast<std::size_t>(fs::file_size(p, fileEc));
    if (total > options.maxTotalBytes)
      throw std::runtime_error("web root " + root.string() + ": more than " + std::to_string(options.maxTotalBytes >> 20) +
                               " MiB of files");
    paths.push_back(p.lexically_relative(root));
  }

  auto table = std::make_shared<Table>();
  std::size_t compressedHere = 0;
  for (const fs::path& relative : paths) {
    const fs::path file = root / relative;
    auto bytes = std::make_shared<const std::string>(readAssetFile(file));
    table->totalBytes += bytes->size();
    if (table->totalBytes > options.maxTotalBytes)  // grew since it was listed
      throw std::runtime_error("web root " + root.string() + ": more than " + std::to_string(options.maxTotalBytes >> 20) +
                               " MiB of files");
    const std::string urlPath = "/" + relative.generic_string();
    const AssetType type = assetTypeOf(file);
    const std::string hash = sha256Hex(*bytes).substr(0, 24);

    Table::File entry;
    entry.contentType = type.mediaType;
    entry.cacheControl = urlPath.rfind(options.immutablePrefix, 0) == 0 && !options.immutablePrefix.empty()
                             ? "public, max-age=31536000, immutable"
                             : "no-cache";
    entry.identity = {bytes, "\"" + hash + "\""};
    if (type.compressible && bytes->size() >= options.minCompressBytes) {
      const bool text = type.mediaType[0] == 't' || std::string(type.mediaType).find("json") != std::string::npos;
      std::optional<std::string> br = validSibling(file, ".br", *bytes, brotliDecodesTo);
      if (!br) {
        br = brotliCompress(*bytes, options.brotliQuality, text);
        ++compressedHere;
      }
      std::optional<std::string> gz = validSibling(file, ".gz", *bytes, gzipDecodesTo);
      if (!gz) gz = gzipCompress(*bytes, options.gzipLevel);
      if (br->size() < bytes->size())
        entry.br = Table::Representation{std::make_shared<const std::string>(std::move(*br)), "\"" + hash + "-br\""};
      if (gz->size() < bytes->size())
        entry.gzip = Table::Representation{std::make_shared<const std::string>(std::move(*gz)), "\"" + hash + "-gz\""};
    }
    table->files.emplace(urlPath, std::move(entry));
  }
  spdlog::info("web root {}: {} files, {} KiB ({} compressed at start-up)", root.string(), table->files.size(),
               table->totalBytes >> 10, compressedHere);
  StaticAssets assets;
  assets.table_ = std::move(table);
  return assets;
}

std::optional<StaticReply> StaticAssets::reply(const std::string& path, const std::string& acceptEncoding,
                                               const std::string& ifNoneMatch) const {
  if (!table_ || path.empty() || path[0] != '/') return std::nullopt;
  const auto it = table_->files.find(path.back() == '/' ? path + "index.html" : path);
  if (it == table_->files.end()) return std::nullopt;
  const Table::File& file = it->second;

  StaticReply r;
  r.contentType = file.contentType;
  r.cacheControl = file.cacheControl;
  r.varyAcceptEncoding = file.br || file.gzip;
  const std::string coding = negotiateEncoding(acceptEncoding, file.br.has_value(), file.gzip.has_value());
  const Table::Representation& chosen = coding == "br" ? *file.br : coding == "gzip" ? *file.gzip : file.identity;
  r.contentEncoding = coding;
  r.etag = chosen.etag;
  r.body = chosen.bytes;

  bool matched = false;
  forEachListItem(ifNoneMatch, [&](const std::string& tag) {
    const std::string opaque = tag.rfind("W/", 0) == 0 ? tag.substr(2) : tag;  // weak comparison
    if (opaque == "*" || opaque == chosen.etag) matched = true;
  });
  if (matched) r.status = 304;
  return r;
}

void StaticAssets::install(httplib::Server& server) const {
  server.set_pre_routing_handler([assets = *this](const httplib::Request& req, httplib::Response& res) {
    if (req.method != "GET" && req.method != "HEAD") return httplib::Server::HandlerResponse::Unhandled;
    const auto r = assets.reply(req.path, req.get_header_value("Accept-Encoding"), req.get_header_value("If-None-Match"));
    if (!r) return httplib::Server::HandlerResponse::Unhandled;
    res.set_header("ETag", r->etag);
    res.set_header("Cache-Control", r->cacheControl);
    if (r->varyAcceptEncoding) res.set_header("Vary", "Accept-Encoding");
    if (r->status == 304) {
      res.status = 304;
      // The length a 200 would have had (RFC 9110 §8.6); httplib would say 0.
      res.set_header("Content-Length", std::to_string(r->body->size()));
      return httplib::Server::HandlerResponse::Handled;
    }
    if (!r->contentEncoding.empty()) res.set_header("Content-Encoding", r->contentEncoding);
    // httplib compresses a body whose Content-Type it deems compressible when the request accepts
    // br or gzip, whatever Content-Encoding says. Without a Content-Type it leaves the body alone;
    // the post-routing handler (after that step) sets the real one. Several ranges: httplib builds
    // multipart/byteranges from the type (and never compresses that), so it gets it at once.
    res.set_header(req.ranges.size() > 1 ? "Content-Type" : kDeferredContentType, r->contentType);
    res.body = *r->body;
    // res.status stays unset: httplib answers 200, or 206 for a Range request.
    return httplib::Server::HandlerResponse::Handled;
  });
  server.set_post_routing_handler([](const httplib::Request&, httplib::Response& res) {
    const auto it = res.headers.find(kDeferredContentType);
    if (it == res.headers.end()) return;
    std::string type = it->second;
    res.headers.erase(kDeferredContentType);
    res.headers.erase("Content-Type");  // httplib's "text/plain" for a body without a type
    res.headers.emplace("Content-Type", std::move(type));
  });
}

fs::path defaultWebRoot(const fs::path& workingDir, const fs::path& exeDir) {
  for (const fs::path& candidate : {workingDir / "web" / "dist", exeDir / ".." / ".." / "web" / "dist",
                                    exeDir / ".." / "share" / "devsurf" / "web" / "dist"}) {
    std::error_code ec;
    if (fs::is_regular_file(candidate / "index.html", ec)) return candidate.lexically_normal();
  }
  return {};
}

std::size_t StaticAssets::fileCount() const { return table_ ? table_->files.size() : 0; }

std::size_t StaticAssets::totalBytes() const { return table_ ? table_->totalBytes : 0; }

}  // namespace devsurf::server
