#include "devsurf/server/Daemon.h"

#include "DaemonClient.h"
#include "devsurf/server/CreasePatternImport.h"
#include "devsurf/server/ShapeApproximation.h"
#include "devsurf/server/ShapeFitting.h"
#include "devsurf/server/StaticAssets.h"

#include "devsurf/proto/BoundedJson.h"

#include <unistd.h>

#include <cctype>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <sstream>

#include <boost/asio/post.hpp>
#include <spdlog/spdlog.h>

#include "devsurf/engine/LinearSolver.h"
#include "devsurf/proto/Scene.h"
#include "devsurf/server/Tokens.h"
#include "devsurf/server/store/PostgresStore.h"

namespace devsurf::server {
namespace {

using nlohmann::json;
using Clock = std::chrono::steady_clock;

/// POST /api/covers and /api/fits run in the request's thread: a cover gives up after this long.
constexpr double kRegionRouteTimeLimitMs = 60000.0;

/// The store as a session journal.
class StoreJournal final : public SessionJournal {
 public:
  explicit StoreJournal(store::Store& store) : store_(store) {}
  void appendEdit(const std::string& session, std::int64_t seq, const json& edit) override {
    guarded("the edit was not stored, so it is not applied",
            [this, &session, seq, &edit]() { store_.appendEdit(session, seq, edit); });
  }
  void saveCheckpoint(const std::string& session, const SessionCheckpoint& c) override {
    guarded("the new state was not stored, so it is not shown",
            [this, &session, &c]() { store_.saveSnapshot(session, store::Snapshot{c.seq, c.scene, c.state, c.revision}); });
  }

 private:
  // A store that cannot write is the participants' to know, by a code of its own.
  template <typename Write>
  static void guarded(const char* consequence, const Write& write) {
    try {
      write();
    } catch (const store::LeaseLostError& e) {
      throw JournalError("session_moved", std::string("this session is served by another daemon now (") + e.what() +
                                              "); " + consequence + ": reconnect");
    } catch (const store::StoreUnavailableError& e) {
      throw JournalError("store_unavailable",
                         std::string("the store is unreachable (") + e.what() + "); " + consequence + ": retry later");
    }
  }

  store::Store& store_;
};

/// A REST error (counted by its code in /api/metrics: the daemon's logger reads it back).
void replyError(httplib::Response& res, int status, const std::string& code, const std::string& message,
                const std::string& path = "") {
  json e{{"code", code}, {"message", message}};
  if (!path.empty()) e["path"] = path;
  res.status = status;
  res.set_content(proto::wireText(json{{"error", e}}), "application/json");
}

/// A refused scene: 400 `invalid` or `limit` (a resource limit), 422 `time_budget` (building the
/// model took longer than the session's time budget), naming the field.
void replySceneError(httplib::Response& res, const proto::SceneError& e) {
  if (e.rule() == "time_budget") return replyError(res, 422, "time_budget", e.what(), e.path());
  replyError(res, 400, e.rule() == "limit" ? "limit" : "invalid", e.what(), e.path());
}

void replyJson(httplib::Response& res, int status, const json& body) {
  res.status = status;
  res.set_content(proto::wireText(body), "application/json");
}

/// The token of "Authorization: Bearer <token>" (the scheme's case ignored, as HTTP's are; spaces
/// after it skipped), or empty.
std::string bearer(const httplib::Request& req) {
  const std::string h = req.get_header_value("Authorization");
  const std::string scheme = "bearer";
  if (h.size() <= scheme.size() || h[scheme.size()] != ' ') return std::string();
  for (std::size_t i = 0; i < scheme.size(); ++i)
    if (std::tolower(static_cast<unsigned char>(h[i])) != scheme[i]) return std::string();
  const std::size_t token = h.find_first_not_of(' ', scheme.size());
  return token == std::string::npos ? std::string() : h.substr(token);
}

/// The methods the OpenAPI document `api` lists for the path template that `path` fills
/// ("/api/jobs/{id}" matches "/api/jobs/AbC_1"; a parameter is one segment of [A-Za-z0-9_-]),
/// upper case and comma-separated, "GET, DELETE"; empty when no template matches.
std::string allowedMethods(const json& api, const std::string& path) {
  auto segments = [](const std::string& text) {
    std::vector<std::string> parts;
    std::size_t start = 0;
    while (start <= text.size()) {
      const std::size_t slash = text.find('/', start);
      parts.push_back(text.substr(start, slash == std::string::npos ? std::string::npos : slash - start));
      if (slash == std::string::npos) break;
      start = slash + 1;
    }
    return parts;
  };
  const std::vector<std::string> given = segments(path);
  const auto paths = api.find("paths");
  if (paths == api.end() || !paths->is_object()) return std::string();
  for (const auto& [pattern, item] : paths->items()) {
    const std::vector<std::string> wanted = segments(pattern);
    if (wanted.size() != given.size() || !item.is_object()) continue;
    bool same = true;
    for (std::size_t k = 0; same && k < wanted.size(); ++k) {
      if (wanted[k].size() > 2 && wanted[k].front() == '{' && wanted[k].back() == '}')
        same = !given[k].empty() && given[k].find_first_not_of(
                                        "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789_-") == std::string::npos;
      else
        same = wanted[k] == given[k];
    }
    if (!same) continue;
    std::string methods;
    for (const auto& [method, operation] : item.items()) {
      if (method != "get" && method != "post" && method != "delete" && method != "put" && method != "patch") continue;
      std::string upper = method;
      for (char& c : upper) c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
      methods += (methods.empty() ? "" : ", ") + upper;
    }
    return methods;
  }
  return std::string();
}

/// Parses a JSON body; on failure answers 400 and returns nullopt.
std::optional<json> parseBody(const httplib::Request& req, httplib::Response& res) {
  try {
    return proto::parseBoundedJson(req.body);
  } catch (const proto::JsonTooDeep& e) {
    replyError(res, 400, "too_deep", std::string("body: ") + e.what());
    return std::nullopt;
  } catch (const proto::JsonSyntaxError& e) {
    replyError(res, 400, "invalid_json", std::string("body is not valid JSON: ") + e.what());
    return std::nullopt;
  }
}

/// Answers an export (SceneSolver::exportAs) as an attachment named `stem`.`extension`; a format
/// that does not apply is a 400, a model state that cannot be exported a 422, both naming "format".
void replyExport(httplib::Response& res, const std::string& stem, const std::function<ExportedFile()>& produce) {
  auto fail = [&res](int status, const std::string& code, std::string message) {
    const std::string prefix = "format: ";
    if (message.rfind(prefix, 0) == 0) message.erase(0, prefix.size());
    replyError(res, status, code, "format: " + message, "format");
  };
  try {
    const ExportedFile file = produce();
    res.set_header("Content-Disposition", "attachment; filename=\"" + stem + "." + file.extension + "\"");
    res.set_content(file.content, file.mediaType);
  } catch (const ExportUnavailable& e) {
    fail(400, "invalid", e.what());
  } catch (const ExportFailed& e) {
    fail(422, "unprocessable", e.what());
  }
}

transport::Delivery toTransport(Delivery d) {
  return d == Delivery::Latest ? transport::Delivery::Latest : transport::Delivery::Reliable;
}

}  // namespace

std::string demoToken(const std::string& scenePath, const std::string& role) {
  return sha256Hex("devsurf demo " + role + " " + std::filesystem::path(scenePath).stem().string()).substr(0, 32);
}


Daemon::Daemon(DaemonOptions options)
    : options_(std::move(options)),
      pool_(options_.workerThreads > 0 ? options_.workerThreads
                                       : std::max(1u, std::thread::hardware_concurrency())) {
  options_.session.maxParticipants = options_.maxClientsPerSession;
  options_.session.maxIterationsPerRequest = options_.maxIterationsPerRequest;
  // One set of scene limits for sessions (creation, edits, restore) and jobs.
  proto::ResourceLimits& limits = options_.session.resources;
  limits.maxControlPoints = options_.maxControlPoints;
  limits.maxIterations = std::max(options_.maxIterationsPerRequest, options_.jobs.maxIterations);
  limits.memoryBudgetBytes = options_.memoryBudgetMb * 1024.0 * 1024.0;
  options_.jobs.resources = limits;
}

Daemon::~Daemon() {
  stop();
  pool_.join();
}

std::size_t Daemon::sessionCount() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return sessions_.size();
}

int Daemon::start() {
  // The web app first: a web root that cannot be served stops the start before anything else.
  if (!options_.webRoot.empty()) assets_ = std::make_unique<StaticAssets>(StaticAssets::load(options_.webRoot));
  store_ = store::openStore(options_.store.empty() ? options_.dataDir : options_.store);
  journal_ = std::make_unique<StoreJournal>(*store_);
  if (options_.nodeId.empty()) {
    char host[256] = {0};
    if (::gethostname(host, sizeof host - 1) != 0) std::snprintf(host, sizeof host, "node");
    options_.nodeId = std::string(host) + "-" + std::to_string(::getpid());
  }
  options_.jobs.leaseMs = options_.leaseMs;
  options_.jobs.heartbeatMs = std::min(options_.jobs.heartbeatMs, options_.leaseMs / 10.0);
  jobs_ = std::make_unique<JobQueue>(*store_, options_.jobs, options_.nodeId);
  if (store_->shared()) {
    // Several daemons share the store: a session is served by the one node that holds its lease,
    // adopted when a request for it arrives (findSession). What this node held before a restart
    // under the same --node-id comes back now, as an embedded daemon restores everything.
    store_->setSessionOwner(options_.nodeId);
    const std::vector<std::string> mine = store_->sessionsLeasedBy(options_.nodeId);
    if (!mine.empty()) spdlog::info("restoring {} stored session(s) this node held", mine.size());
    for (const std::string& id : mine) {
      if (startAbandoned_) break;
      adoptSession(id);
    }
    leaseThread_ = std::thread([this]() {
      std::unique_lock<std::mutex> lock(leaseMutex_);
      while (!leaseWake_.wait_for(lock, std::chrono::duration<double, std::milli>(options_.leaseMs / 10.0),
                                  [this]() { return leaseStopping_; })) {
        lock.unlock();
        renewSessionLeases();
        lock.lock();
      }
    });
  } else {
    restoreSessions();
  }
  if (engine::blasCallsSerialized())
    spdlog::warn("the BLAS is a serial or OpenMP OpenBLAS, which is not safe to call from two threads at once: "
                 "factorizations run one at a time (install libopenblas0-pthread: scripts/setup.sh)");
  openDemos();
  if (startAbandoned_) {
    spdlog::info("stopped during start-up");
    return -1;
  }

  transport::TransportLimits limits;
  limits.http = options_.http;
  limits.maxMessageBytes = options_.maxMessageBytes * 4;  // beyond this: close 1009; below: error message
  transport::WebSocketHandlers handlers;
  handlers.onOpen = [this](const std::shared_ptr<transport::Connection>& c) {
    auto client = std::make_shared<Client>();
    client->connection = c;
    client->tokens = 2.0 * options_.messageRate;
    std::lock_guard<std::mutex> lock(mutex_);
    clients_[c->id()] = client;
  };
  handlers.onMessage = [this](const std::shared_ptr<transport::Connection>& c, std::string text) {
    onMessage(c, std::move(text));
  };
  handlers.onClose = [this](const std::shared_ptr<transport::Connection>& c) { onClose(c); };
  handlers.onRefused = [this](const std::string& code) { counters_.recordError(code); };
  http_ = std::make_unique<transport::Server>(handlers, limits);
  routes();
  const int port = http_->bind(options_.bind, options_.port);
  spdlog::info("devsurf node {} listening on http://{}:{} (store {}, {} sessions)", options_.nodeId, options_.bind,
               port, store_->info().path, sessionCount());
  return port;
}

void Daemon::run() { http_->serve(); }

void Daemon::stop() {
  if (http_) http_->stop();
  jobs_.reset();
  if (leaseThread_.joinable()) {
    {
      std::lock_guard<std::mutex> lock(leaseMutex_);
      leaseStopping_ = true;
    }
    leaseWake_.notify_all();
    leaseThread_.join();
    try {  // handed over at once: the next node need not wait for the leases to end
      const int ended = store_->endSessionLeases(options_.nodeId);
      if (ended > 0) spdlog::info("ended {} session lease(s): other nodes may take the sessions at once", ended);
    } catch (const std::exception& e) {
      spdlog::warn("could not release session leases ({}); they end by themselves", e.what());
    }
  }
}

void Daemon::routes() {
  httplib::Server& s = *http_;
  auto needApiKey = [this](const httplib::Request& req, httplib::Response& res) {
    if (options_.apiKey.empty() || constantTimeEquals(bearer(req), options_.apiKey)) return true;
    replyError(res, 401, "unauthorized", "this server needs an API key (Authorization: Bearer KEY)");
    return false;
  };
  s.set_logger([this](const httplib::Request& req, const httplib::Response& res) {
    ++httpRequests_;
    // Only the method and path: tokens travel in headers and in WebSocket messages, never here.
    spdlog::debug("{} {} → {}", req.method, req.path, res.status);
    if (res.status >= 400) {
      std::string code = "http_" + std::to_string(res.status);
      try {
        const json body = json::parse(res.body);
        if (body.contains("error") && body["error"].contains("code")) code = body["error"]["code"].get<std::string>();
      } catch (const std::exception&) {
      }
      counters_.recordError(code);
    }
  });
  // A request no route answers gets an error in the API's own form, not an empty 404: 405 with
  // `Allow` for a method a path does not take (the methods from the OpenAPI document, so the two
  // cannot disagree), 404 for a path no route has; error responses with a body are left as they are.
  s.set_error_handler(httplib::Server::HandlerWithResponse([this](const httplib::Request& req, httplib::Response& res) {
    if (res.status != 404 || !res.body.empty() || req.path.rfind("/api/", 0) != 0)
      return httplib::Server::HandlerResponse::Unhandled;
    if (const std::string allowed = allowedMethods(openApi(), req.path); !allowed.empty()) {
      replyError(res, 405, "method_not_allowed", req.method + " is not a method of " + req.path + "; it takes " + allowed);
      res.set_header("Allow", allowed);
      return httplib::Server::HandlerResponse::Handled;
    }
    replyError(res, 404, "not_found",
               "no route answers " + req.method + " " + req.path + " (GET /api/openapi.json lists the routes and their methods)");
    return httplib::Server::HandlerResponse::Handled;
  }));
  s.set_exception_handler([](const httplib::Request&, httplib::Response& res, std::exception_ptr ep) {
    std::string what = "internal error";
    try {
      std::rethrow_exception(ep);
    } catch (const store::StoreUnavailableError& e) {
      // PostgreSQL is down: nothing was stored, and the request may be repeated once it is back.
      res.set_header("Retry-After", "5");
      return replyError(res, 503, "store_unavailable", std::string("the store is unreachable: ") + e.what());
    } catch (const std::exception& e) {
      what = e.what();
    } catch (...) {
    }
    replyError(res, 500, "internal", what);
  });

  s.Get("/api/health", [this](const httplib::Request&, httplib::Response& res) {
    std::size_t quarantined = 0;
    {
      std::lock_guard<std::mutex> lock(mutex_);
      quarantined = quarantined_.size();
    }
    json health{{"status", "ok"},
                {"node", options_.nodeId},
                {"store", store_->shared() ? "postgresql" : "sqlite"},
                {"sessions", sessionCount()},
                {"sessions_quarantined", quarantined}};
    try {
      health["jobs_queued"] = jobs_->queued();
    } catch (const std::exception& e) {
      // The store is unreachable: this node still serves the sessions it holds (their edits are
      // refused until the store is back), so it stays alive for a proxy's health check (200).
      health["status"] = "store_unavailable";
      health["error"] = e.what();
    }
    replyJson(res, 200, health);
  });
  s.Get("/api/metrics", [this](const httplib::Request&, httplib::Response& res) {
    res.set_content(prometheus(), "text/plain; version=0.0.4");
  });
  s.Get("/api/openapi.json", [this](const httplib::Request&, httplib::Response& res) { replyJson(res, 200, openApi()); });

  // --- sessions ---
  s.Get("/api/sessions", [this](const httplib::Request&, httplib::Response& res) {
    json list = json::array();
    std::map<std::string, std::pair<std::string, std::string>> demos;
    std::map<std::string, std::shared_ptr<Session>> held;
    {
      std::lock_guard<std::mutex> lock(mutex_);
      demos = demoTokens_;
      held = sessions_;
    }
    for (const auto& [id, t] : demos) {
      const auto session = held.find(id);
      if (session != held.end()) {
        list.push_back({{"id", id}, {"name", session->second->name()}, {"participants", session->second->participantCount()},
                        {"edit_token", t.first}, {"view_token", t.second}});
      } else if (store_->shared()) {
        // Held by another node (or by none yet): listed from the store, not adopted here.
        try {
          if (const auto stored = store_->loadSession(id))
            list.push_back({{"id", id}, {"name", stored->session.name}, {"participants", 0},
                            {"edit_token", t.first}, {"view_token", t.second}});
        } catch (const std::exception& e) {
          spdlog::warn("demo {}: {}", id, e.what());
        }
      }
    }
    replyJson(res, 200, {{"sessions", list}});
  });
  s.Post("/api/sessions", [this, needApiKey](const httplib::Request& req, httplib::Response& res) {
    if (!needApiKey(req, res)) return;
    const auto body = parseBody(req, res);
    if (!body) return;
    if (static_cast<int>(sessionCount()) >= options_.maxSessions)
      return replyError(res, 503, "limit", "this server holds its maximum of " + std::to_string(options_.maxSessions) + " sessions");
    // ?solved=true: the session starts from the scene's solved state, as a demo does (the web app's
    // "New session from an example": the design as its picture shows it, not its unsolved start).
    const std::string solved = req.has_param("solved") ? req.get_param_value("solved") : "false";
    if (solved != "true" && solved != "false")
      return replyError(res, 400, "invalid", "solved must be true or false, not \"" + solved.substr(0, 40) + "\"", "solved");
    try {
      proto::Scene scene = proto::sceneFromJson(*body, options_.session.resources);
      if (solved == "true") scene = SceneSolver::solvedScene(scene);
      const std::string id = randomToken().substr(0, 16), edit = randomToken(), view = viewTokenFor(edit);
      createSession(scene, edit, view, false, id);
      res.set_header("Location", "/api/sessions/" + id);
      replyJson(res, 201, {{"id", id}, {"edit_token", edit}, {"view_token", view},
                           {"links", {{"edit", "/?session=" + id + "&token=" + edit},
                                      {"view", "/?session=" + id + "&token=" + view}}}});
    } catch (const proto::SceneError& e) {
      replySceneError(res, e);
    } catch (const std::invalid_argument& e) {
      // Valid JSON the model cannot build (a degenerate design): the message names the field.
      replyError(res, 422, "invalid_design", e.what(), "model");
    }
  });
  auto sessionFor = [this](const httplib::Request& req, httplib::Response& res, Role need) -> std::shared_ptr<Session> {
    auto session = findSession(req.matches[1]);
    const Role role = session ? session->authenticate(bearer(req)) : Role::None;
    if (!session) {
      if (const auto q = quarantinedSession(req.matches[1], bearer(req))) {
        replyError(res, 503, "quarantined",
                   "this session could not be restored after a restart and is kept unchanged for its owner (" +
                       q->reason + "); its last stored scene: GET /api/sessions/" + std::string(req.matches[1]) +
                       "/export?format=json",
                   "session");
        return nullptr;
      }
    }
    if (!session) {
      if (const auto holder = sessionHolder(req.matches[1])) {
        res.set_header("Retry-After", "1");
        replyError(res, 503, "unavailable",
                   "this session is " + *holder,
                   "session");
        return nullptr;
      }
    }
    if (!session || role == Role::None) {
      replyError(res, 404, "not_found", "no such session, or the token does not open it");
      return nullptr;
    }
    if (need == Role::Edit && role != Role::Edit) {
      replyError(res, 403, "forbidden", "this needs the session's edit token");
      return nullptr;
    }
    return session;
  };
  s.Get(R"(/api/sessions/([A-Za-z0-9_-]+))", [sessionFor](const httplib::Request& req, httplib::Response& res) {
    auto session = sessionFor(req, res, Role::View);
    if (!session) return;
    // seq, revision, scene and metrics of one checkpoint (the last state shown), read together.
    const Session::Shown shown = session->shown();
    replyJson(res, 200, {{"id", session->id()}, {"seq", shown.seq}, {"revision", shown.revision},
                         {"scene", shown.scene}, {"metrics", shown.metrics},
                         {"participants", session->participantCount()}});
  });
  s.Delete(R"(/api/sessions/([A-Za-z0-9_-]+))", [this, sessionFor](const httplib::Request& req, httplib::Response& res) {
    if (const auto q = quarantinedSession(req.matches[1], bearer(req))) {
      // Its owner may delete a quarantined session (the daemon never does).
      if (Session::roleOf(q->tokens, bearer(req)) != Role::Edit)
        return replyError(res, 403, "forbidden", "this needs the session's edit token");
      {
        std::lock_guard<std::mutex> lock(mutex_);
        quarantined_.erase(req.matches[1]);
      }
      store_->deleteSession(req.matches[1]);
      res.status = 204;
      return;
    }
    auto session = sessionFor(req, res, Role::Edit);
    if (!session) return;
    {
      std::lock_guard<std::mutex> lock(mutex_);
      sessions_.erase(session->id());
    }
    store_->deleteSession(session->id());
    res.status = 204;
  });
  s.Get(R"(/api/sessions/([A-Za-z0-9_-]+)/export)", [this, sessionFor](const httplib::Request& req, httplib::Response& res) {
    const std::string format = req.has_param("format") ? req.get_param_value("format") : "json";
    if (!findSession(req.matches[1]) && format == "json") {
      // A quarantined session's last stored scene, for its owner: nothing is lost.
      if (const auto q = quarantinedSession(req.matches[1], bearer(req))) {
        if (q->scene.is_null())
          return replyError(res, 503, "quarantined", "this session's stored rows do not parse (" + q->reason + ")", "session");
        res.set_header("Content-Disposition", "attachment; filename=\"" + std::string(req.matches[1]) + ".json\"");
        return replyJson(res, 200, q->scene);
      }
    }
    auto session = sessionFor(req, res, Role::View);
    if (!session) return;
    if (format == "json") {
      res.set_header("Content-Disposition", "attachment; filename=\"" + session->id() + ".json\"");
      return replyJson(res, 200, session->sceneJson());
    }
    replyExport(res, session->id(), [&session, &format]() { return session->exportAs(format); });
  });

  // A picture of the session's current surface (start page thumbnails), kept per revision.
  s.Get(R"(/api/sessions/([A-Za-z0-9_-]+)/thumbnail)", [sessionFor](const httplib::Request& req, httplib::Response& res) {
    auto session = sessionFor(req, res, Role::View);
    if (!session) return;
    res.set_header("Cache-Control", "private, no-cache");
    res.set_header("ETag", "\"" + session->id() + "-" + std::to_string(session->revision()) + "\"");
    replyExport(res, session->id(), [&session]() { return session->thumbnail(); });
  });

  // --- a user's mesh → glued developable patches (issue 15): the scene to open or submit ---
  s.Post("/api/approximations", [needApiKey](const httplib::Request& req, httplib::Response& res) {
    if (!needApiKey(req, res)) return;
    try {
      const std::multimap<std::string, std::string> params(req.params.begin(), req.params.end());
      const ApproximationRequest request = approximationRequestFromQuery(params);
      reference::ReferenceLimits limits;
      limits.maxTriangles = 400'000;  // the map to the plane runs in this request's thread
      const ApproximationResult result =
          approximateUpload(req.body, req.has_param("format") ? req.get_param_value("format") : "", request, limits);
      replyJson(res, 200, {{"scene", proto::sceneToJson(result.scene)}, {"summary", result.summaryJson()}});
    } catch (const ApproximationInputError& e) {
      replyError(res, e.tooLarge() ? 413 : 400, e.tooLarge() ? "limit" : "invalid", e.what(), e.field());
    }
  });

  // --- a crease pattern (FOLD) → a composite scene to open or submit (issue 16) ---
  s.Post("/api/imports", [needApiKey](const httplib::Request& req, httplib::Response& res) {
    if (!needApiKey(req, res)) return;
    try {
      CreasePatternImportRequest request;
      for (const auto& [key, value] : req.params) {
        if (key == "format") request.format = value;
        else if (key == "name") request.name = value;
        else if (key == "units") request.units = value;
        else throw ApproximationInputError(key, key + ": unknown parameter (format, name, units)");
      }
      // The file is the body, or the one file of a form upload (curl -F file=@pattern.svg).
      const std::string* body = &req.body;
      std::string fileName;
      if (req.is_multipart_form_data()) {
        if (req.files.size() != 1)
          throw ApproximationInputError("body", "body: a form upload carries one file (the crease pattern); this one has " +
                                                    std::to_string(req.files.size()) + " parts");
        body = &req.files.begin()->second.content;
        fileName = req.files.begin()->second.filename;
      }
      if (request.format.empty()) request.format = creasePatternFormatOf(*body, fileName);
      const CreasePatternImportResult result = importCreasePattern(*body, request);
      replyJson(res, 200, {{"scene", proto::sceneToJson(result.scene)}, {"summary", result.summaryJson()}});
    } catch (const ApproximationInputError& e) {
      replyError(res, e.tooLarge() ? 413 : 400, e.tooLarge() ? "limit" : "invalid", e.what(), e.field());
    }
  });

  // --- a user's shape → a preview, a fitted strip, strips covering a region (issue 15) ---
  // The body is the shape's file (a cloud or a mesh); query parameters as `devsurf fit`/`cover`.
  auto uploadedShape = [](const httplib::Request& req) {
    reference::ReferenceLimits limits;
    limits.maxPoints = 2'000'000;  // thinned and searched in this request's thread
    limits.maxTriangles = 4'000'000;
    return readUploadedShape(req.body, req.has_param("format") ? req.get_param_value("format") : "",
                             {"off", "obj", "ply", "stl", "xyz", "pwn"}, limits);
  };
  s.Post("/api/references", [needApiKey, uploadedShape](const httplib::Request& req, httplib::Response& res) {
    if (!needApiKey(req, res)) return;
    try {
      int shown = 20000;
      for (const auto& [key, value] : req.params) {
        if (key == "points") shown = static_cast<int>(integerParameter(key, value, 1, 200000));
        else if (key != "format") throw ApproximationInputError(key, key + ": unknown parameter (format, points)");
      }
      replyJson(res, 200, referencePreview(uploadedShape(req), shown));
    } catch (const ApproximationInputError& e) {
      replyError(res, e.tooLarge() ? 413 : 400, e.tooLarge() ? "limit" : "invalid", e.what(), e.field());
    }
  });
  auto regionRoute = [needApiKey, uploadedShape](bool cover) {
    return [needApiKey, uploadedShape, cover](const httplib::Request& req, httplib::Response& res) {
      if (!needApiKey(req, res)) return;
      try {
        const std::multimap<std::string, std::string> params(req.params.begin(), req.params.end());
        RegionFitRequest request = regionFitRequestFromQuery(params, cover);
        request.timeLimitMs = kRegionRouteTimeLimitMs;  // the work runs in this request's thread
        const reference::ReferenceShape shape = uploadedShape(req);
        const std::string source = request.name.empty() ? "the uploaded shape" : request.name;
        const RegionFitResult result =
            cover ? coverShapeWithStrips(shape, source, request) : fitStripToShape(shape, source, request);
        replyJson(res, 200, {{"scene", proto::sceneToJson(result.scene)}, {"summary", result.summary}});
      } catch (const ApproximationInputError& e) {
        replyError(res, e.tooLarge() ? 413 : 400, e.tooLarge() ? "limit" : "invalid", e.what(), e.field());
      } catch (const std::invalid_argument& e) {
        replyError(res, 400, "invalid", e.what(), "body");
      }
    };
  };
  s.Post("/api/fits", regionRoute(false));
  s.Post("/api/covers", regionRoute(true));

  // --- jobs ---
  s.Post("/api/jobs", [this, needApiKey](const httplib::Request& req, httplib::Response& res) {
    if (!needApiKey(req, res)) return;
    const auto body = parseBody(req, res);
    if (!body) return;
    std::optional<std::string> key;
    if (req.has_header("Idempotency-Key")) key = req.get_header_value("Idempotency-Key");
    if (key && (key->empty() || key->size() > 200))
      return replyError(res, 400, "invalid", "Idempotency-Key: 1 to 200 characters", "Idempotency-Key");
    try {
      const JobQueue::Submitted s = jobs_->submit(*body, key);
      res.set_header("Location", "/api/jobs/" + s.id);
      replyJson(res, s.created ? 202 : 200, {{"id", s.id}, {"state", store::jobStateName(jobs_->job(s.id)->state)}});
    } catch (const proto::SceneError& e) {
      replySceneError(res, e);
    } catch (const QueueFullError& e) {
      res.set_header("Retry-After", "5");
      replyError(res, 503, "queue_full", e.what());
    } catch (const IdempotencyMismatchError& e) {
      replyError(res, 422, "idempotency_mismatch", e.what(), "Idempotency-Key");
    }
  });
  s.Get(R"(/api/jobs/([A-Za-z0-9_-]+))", [this, needApiKey](const httplib::Request& req, httplib::Response& res) {
    if (!needApiKey(req, res)) return;
    const auto job = jobs_->job(req.matches[1]);
    if (!job) return replyError(res, 404, "not_found", "no such job");
    json body{{"id", job->id}, {"state", store::jobStateName(job->state)},
              {"progress", {{"iteration", job->progressIteration}, {"of", job->progressOf}}}};
    if (job->report) body["report"] = *job->report;
    if (job->error) body["error"] = *job->error;
    if (!store::isFinished(job->state)) res.set_header("Retry-After", "1");
    replyJson(res, 200, body);
  });
  s.Post(R"(/api/jobs/([A-Za-z0-9_-]+)/cancel)", [this, needApiKey](const httplib::Request& req, httplib::Response& res) {
    if (!needApiKey(req, res)) return;
    try {
      if (!jobs_->cancel(req.matches[1])) return replyError(res, 409, "conflict", "the job has already finished");
      replyJson(res, 202, {{"id", std::string(req.matches[1])}, {"state", store::jobStateName(jobs_->job(req.matches[1])->state)}});
    } catch (const store::NotFoundError&) {
      replyError(res, 404, "not_found", "no such job");
    }
  });
  s.Get(R"(/api/jobs/([A-Za-z0-9_-]+)/result)", [this, needApiKey](const httplib::Request& req, httplib::Response& res) {
    if (!needApiKey(req, res)) return;
    const auto job = jobs_->job(req.matches[1]);
    if (!job) return replyError(res, 404, "not_found", "no such job");
    if (job->state != store::JobState::Succeeded || !job->report) {
      if (!store::isFinished(job->state)) res.set_header("Retry-After", "1");
      return replyError(res, 409, "not_ready", "the job is " + store::jobStateName(job->state));
    }
    const std::string format = req.has_param("format") ? req.get_param_value("format") : "json";
    if (format == "json") return replyJson(res, 200, *job->report);
    replyExport(res, job->id, [this, &job, &format]() {
      return SceneSolver::exportScene((*job->report)["scene"], format, options_.jobs.resources,
                                      engine::Deadline::after(options_.jobs.maxRunMs, "the job's time limit"));
    });
  });

  // The web app from memory, precompressed, with ETags and cache headers (StaticAssets.h).
  if (assets_) assets_->install(s);
}

void Daemon::onMessage(const std::shared_ptr<transport::Connection>& c, std::string text) {
  std::shared_ptr<Client> client;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    const auto it = clients_.find(c->id());
    if (it == clients_.end()) return;
    client = it->second;
  }
  auto reply = [&c](const json& m) { c->send(proto::wireText(m)); };
  auto fail = [this, &reply](const json& op, const std::string& code, const std::string& message, const std::string& path) {
    counters_.recordError(code);
    json e{{"type", "error"}, {"code", code}, {"message", message}};
    if (!op.is_null()) e["op"] = op;
    if (!path.empty()) e["path"] = path;
    reply(e);
  };
  ++counters_.messages;
  std::lock_guard<std::mutex> clientLock(client->mutex);
  // Rate limit: a token bucket of 2× the rate, refilled continuously.
  const auto now = Clock::now();
  client->tokens = std::min(2.0 * options_.messageRate,
                            client->tokens + options_.messageRate * std::chrono::duration<double>(now - client->refilled).count());
  client->refilled = now;
  if (client->tokens < 1.0) return fail(nullptr, "rate_limited", "too many messages; the limit is " + std::to_string(static_cast<int>(options_.messageRate)) + " per second", "");
  client->tokens -= 1.0;
  if (text.size() > options_.maxMessageBytes)
    return fail(nullptr, "too_large", "message of " + std::to_string(text.size()) + " bytes; the limit is " + std::to_string(options_.maxMessageBytes), "");
  json message;
  try {
    message = proto::parseBoundedJson(text);
  } catch (const proto::JsonTooDeep& e) {
    return fail(nullptr, "too_deep", e.what(), "");
  } catch (const proto::JsonSyntaxError& e) {
    return fail(nullptr, "invalid_json", std::string("not valid JSON: ") + e.what(), "");
  }
  // Echoed in the answer only as the schema allows it (an integer, a string of ≤ 64 characters).
  const json op = message.is_object() && message.contains("op") ? proto::echoableId(message["op"]) : json();
  const auto errors = proto::schemaRegistry().validate(message, "ws-client.schema.json", 1);
  if (!errors.empty()) return fail(op, "invalid", errors[0].toString(), errors[0].path);

  const std::string type = message["type"];
  if (type == "join") {
    if (client->participant >= 0) return fail(op, "conflict", "already joined a session on this connection", "type");
    auto session = findSession(message["session"]);
    const Role role = session ? session->authenticate(message["token"]) : Role::None;
    if (!session) {
      if (const auto q = quarantinedSession(message["session"], message["token"])) {
        fail(op, "quarantined",
             "this session could not be restored after a restart and is kept unchanged (" + q->reason +
                 "); its last stored scene: GET /api/sessions/" + message["session"].get<std::string>() +
                 "/export?format=json",
             "session");
        c->close(transport::CloseCode::PolicyViolation, "quarantined");
        return;
      }
    }
    if (!session) {
      if (const auto holder = sessionHolder(message["session"])) {
        fail(op, "unavailable",
             "this session is " + *holder + "; reconnect",
             "session");
        c->close(transport::CloseCode::TryAgainLater, "session held by another node");
        return;
      }
    }
    if (role == Role::None) {
      fail(op, "unauthorized", "unknown session or wrong token", "token");
      c->close(transport::CloseCode::PolicyViolation, "unauthorized");
      return;
    }
    std::weak_ptr<transport::Connection> weak = c;
    const int pid = session->join(role, message.value("name", ""), [weak](std::string text, Delivery d, const std::string& key) {
      if (auto conn = weak.lock()) conn->send(std::move(text), toTransport(d), key);
    });
    if (pid < 0) {
      c->close(transport::CloseCode::PolicyViolation, "session full");
      return;
    }
    client->session = session;
    client->participant = pid;
    // Every editor knows the view link (of sessions whose view token derives from the edit token).
    if (role == Role::Edit) {
      const std::string view = viewTokenFor(message["token"].get<std::string>());
      if (session->authenticate(view) == Role::View)
        session->post(pid, json{{"type", "_links"}, {"view_token", view}});  // after its state
    }
    return;
  }
  auto session = client->session.lock();
  if (!session || client->participant < 0) return fail(op, "not_joined", "send a join message first", "type");
  session->post(client->participant, std::move(message));
}

void Daemon::onClose(const std::shared_ptr<transport::Connection>& c) {
  std::shared_ptr<Client> client;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    const auto it = clients_.find(c->id());
    if (it == clients_.end()) return;
    client = it->second;
    clients_.erase(it);
  }
  std::lock_guard<std::mutex> lock(client->mutex);
  if (auto session = client->session.lock()) session->leave(client->participant);
}

nlohmann::json Daemon::openApi() const { return proto::embeddedDocument("openapi.json"); }

std::string Daemon::prometheus() const {
  std::ostringstream out;
  out << "# HELP devsurf_node_info This daemon: its node id and its store.\n# TYPE devsurf_node_info gauge\n"
      << "devsurf_node_info{node=\"" << options_.nodeId << "\",store=\"" << (store_->shared() ? "postgresql" : "sqlite")
      << "\"} 1\n";
  std::size_t clients = 0;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    clients = clients_.size();
    out << "# HELP devsurf_sessions Open editing sessions.\n# TYPE devsurf_sessions gauge\ndevsurf_sessions " << sessions_.size() << "\n";
  }
  out << "# HELP devsurf_clients Open WebSocket connections.\n# TYPE devsurf_clients gauge\ndevsurf_clients " << clients << "\n";
  out << "# HELP devsurf_jobs Batch jobs by state.\n# TYPE devsurf_jobs gauge\n";
  try {
    for (const auto& [state, n] : jobs_->counts()) out << "devsurf_jobs{state=\"" << store::jobStateName(state) << "\"} " << n << "\n";
  } catch (const std::exception&) {  // the store is unreachable: no job counts, the rest is this node's
  }
  out << "# HELP devsurf_iterations_total Guided-projection iterations run in sessions.\n# TYPE devsurf_iterations_total counter\n"
      << "devsurf_iterations_total " << counters_.iterations.load() << "\n";
  out << "# HELP devsurf_iteration_seconds Wall time of one guided-projection iteration in a session.\n"
      << "# TYPE devsurf_iteration_seconds histogram\n";
  std::uint64_t cumulative = 0;
  for (std::size_t b = 0; b <= std::size(SessionCounters::kBucketsMs); ++b) {
    cumulative += counters_.iterationBuckets[b].load();
    out << "devsurf_iteration_seconds_bucket{le=\""
        << (b < std::size(SessionCounters::kBucketsMs) ? std::to_string(SessionCounters::kBucketsMs[b] / 1000.0) : std::string("+Inf"))
        << "\"} " << cumulative << "\n";
  }
  out << "devsurf_iteration_seconds_sum " << counters_.iterationMicros.load() / 1e6 << "\n"
      << "devsurf_iteration_seconds_count " << cumulative << "\n";
  out << "# HELP devsurf_ws_messages_total WebSocket messages received.\n# TYPE devsurf_ws_messages_total counter\n"
      << "devsurf_ws_messages_total " << counters_.messages.load() << "\n";
  out << "# HELP devsurf_errors_total Errors answered to clients (WebSocket error messages, REST 4xx/5xx), by code.\n"
      << "# TYPE devsurf_errors_total counter\n";
  for (const auto& [code, n] : counters_.errorsByCode()) out << "devsurf_errors_total{code=\"" << code << "\"} " << n << "\n";
  out << "# HELP devsurf_http_requests_total HTTP requests served.\n# TYPE devsurf_http_requests_total counter\n"
      << "devsurf_http_requests_total " << httpRequests_.load() << "\n";
  const JobQueue::Counters& jobs = jobs_->counters();
  out << "# HELP devsurf_node_jobs_total What this node's job workers did: claims, results written, jobs another node took over.\n"
      << "# TYPE devsurf_node_jobs_total counter\n"
      << "devsurf_node_jobs_total{event=\"claimed\"} " << jobs.claimed.load() << "\n"
      << "devsurf_node_jobs_total{event=\"finished\"} " << jobs.finished.load() << "\n"
      << "devsurf_node_jobs_total{event=\"lease_lost\"} " << jobs.leaseLost.load() << "\n";
  out << "# HELP devsurf_node_sessions_total Sessions moving between nodes of a shared store, seen from this node.\n"
      << "# TYPE devsurf_node_sessions_total counter\n"
      << "devsurf_node_sessions_total{event=\"adopted\"} " << sessionsAdopted_.load() << "\n"
      << "devsurf_node_sessions_total{event=\"handover_requested\"} " << handoversRequested_.load() << "\n"
      << "devsurf_node_sessions_total{event=\"handed_off\"} " << sessionsHandedOff_.load() << "\n";
  return out.str();
}

}  // namespace devsurf::server
