#pragma once
// The built web app (web/dist) held in memory and served at / with precompressed bodies, strong
// ETags and cache headers (issue 16 item 8: a page recompressed its script with Brotli on every
// request and was cached nowhere).
//
// Conventions
//  * Read once: load() reads every file under the root into memory (up to maxTotalBytes) and
//    compresses what is compressible then; no request opens a file or compresses anything. Files
//    added to the root later are not served (restart the daemon after a rebuild).
//  * URL paths: "/" + the file's path relative to the root, '/'-separated, as decoded by httplib
//    (no query string: `/?session=…` is `/`). A path ending in "/" means that folder's index.html,
//    as httplib's set_mount_point did. Only the files listed at load() answer, so no request path
//    (`/../x`, `/%2e%2e/x`, `//etc/passwd`) can reach outside the root. Anything else is not
//    handled here: it goes on to the REST routes (and to httplib's 404).
//  * Representations: the file as it is ("identity") always; for compressible types (text/*,
//    JavaScript, JSON, SVG, source maps, wasm) of at least minCompressBytes also "br" and "gzip",
//    each kept only when smaller than the file. Precompressed siblings FILE.br and FILE.gz (written
//    by the Vite build, web/vite.config.js) are used when they decode to FILE's bytes; otherwise
//    load() compresses (Brotli at brotliQuality, gzip at gzipLevel). The siblings are not served as
//    files of their own.
//  * Negotiation (RFC 9110 §12.5.3): Accept-Encoding's codings with their q-values ("*" stands for
//    any coding not listed, q=0 excludes); the highest q wins, ties go br > gzip > identity. No
//    Accept-Encoding header: identity. When nothing listed is available, identity.
//  * Validators: a strong ETag per representation, "<24 hex digits of SHA-256 of the file>" with
//    "-br" / "-gz" appended for the encoded ones. If-None-Match (weak comparison, a list or "*")
//    naming the selected representation → 304 with its ETag and no body.
//  * Caching: paths under immutablePrefix ("/assets/": Vite's content-hashed file names) get
//    `Cache-Control: public, max-age=31536000, immutable`; every other file (index.html) `no-cache`
//    (stored, but revalidated with its ETag on every use). Compressible files carry
//    `Vary: Accept-Encoding` in every answer (200, HEAD and 304).
//  * Thread-safety: a loaded StaticAssets is immutable; copies share the same table and any
//    number of threads may call reply() at once.

#include <cstddef>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>

namespace httplib {
class Server;
}

namespace devsurf::server {

/// What load() reads and how it compresses.
struct StaticAssetsOptions {
  /// All files together (their bytes as on disk, siblings not counted); more: load() throws.
  std::size_t maxTotalBytes = 256u << 20;
  /// Files under the root; more: load() throws.
  std::size_t maxFiles = 20000;
  /// Brotli quality (0–11) for files without a valid FILE.br. 11 costs ~5 s per MB of
  /// JavaScript on one core, 5 about 0.2 s at ~15 % larger output; the Vite build writes quality 11.
  int brotliQuality = 5;
  /// gzip level (1–9) for files without a valid FILE.gz.
  int gzipLevel = 9;
  /// Smaller files are served only as they are.
  std::size_t minCompressBytes = 256;
  /// URL prefix of content-hashed (never changing) files, cached for a year as immutable.
  std::string immutablePrefix = "/assets/";
};

/// One answer of reply(): the status, the headers to set and the body.
struct StaticReply {
  int status = 200;                 ///< 200 or 304
  std::string contentType;          ///< e.g. "text/javascript; charset=utf-8"
  std::string contentEncoding;      ///< "", "br" or "gzip"
  std::string etag;                 ///< quoted strong ETag of the selected representation
  std::string cacheControl;
  bool varyAcceptEncoding = false;  ///< the file has encoded representations
  /// The selected representation's bytes (shared, never copied per request); for a 304 its
  /// length is still the representation's (Content-Length), but nothing is sent.
  std::shared_ptr<const std::string> body;
};

/// The files of a built web app, in memory, ready to answer GET and HEAD.
class StaticAssets {
 public:
  /// Reads every regular file under `root` (recursively; symbolic links to files are followed)
  /// and prepares its representations.
  /// @throws std::runtime_error if `root` is not a readable folder, a file cannot be read,
  ///         the limits are exceeded or compression fails; std::invalid_argument for bad options.
  static StaticAssets load(const std::filesystem::path& root, const StaticAssetsOptions& options = {});

  /// The answer to GET/HEAD of `path` (a decoded URL path without query) given the request's
  /// Accept-Encoding and If-None-Match values ("" when absent), or nullopt when no file answers
  /// to that path.
  std::optional<StaticReply> reply(const std::string& path, const std::string& acceptEncoding,
                                   const std::string& ifNoneMatch) const;

  /// Answers GET and HEAD of the files on `server` (a pre-routing handler, so files come before
  /// the routes as with set_mount_point; other requests go on to the routes). httplib would
  /// compress a body again by its Content-Type (it does not look at Content-Encoding), so the type
  /// is set by a post-routing handler, after httplib's compression step has seen none: install()
  /// takes both of the server's pre- and post-routing handler slots. The server keeps a copy
  /// (shared table) of this object.
  void install(httplib::Server& server) const;

  std::size_t fileCount() const;
  /// Bytes of the files as on disk.
  std::size_t totalBytes() const;

 private:
  struct Table;
  std::shared_ptr<const Table> table_;
};

/// Where `devsurf serve` finds the built web app without --web: the first of
/// `workingDir`/web/dist (the source tree's root), `exeDir`/../../web/dist (the executable in a
/// build tree, build/server/devsurf) and `exeDir`/../share/devsurf/web/dist (an installed layout)
/// that holds an index.html; empty when none does.
std::filesystem::path defaultWebRoot(const std::filesystem::path& workingDir, const std::filesystem::path& exeDir);

/// The coding reply() picks for an Accept-Encoding value among those available ("br", "gzip";
/// identity is always available): "br", "gzip" or "" (identity). Exposed for tests.
std::string negotiateEncoding(const std::string& acceptEncoding, bool brAvailable, bool gzipAvailable);

}  // namespace devsurf::server
