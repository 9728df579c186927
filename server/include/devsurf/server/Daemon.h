#pragma once

#include <atomic>
#include <condition_variable>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include <boost/asio/thread_pool.hpp>
#include <nlohmann/json.hpp>

#include "devsurf/server/JobQueue.h"
#include "devsurf/server/Session.h"
#include "devsurf/server/StaticAssets.h"
#include "devsurf/server/store/Store.h"
#include "devsurf/server/transport/Server.h"

namespace devsurf::server {

/// Everything `devsurf serve` can be told; every limit has a flag (see `devsurf help`).
struct DaemonOptions {
  std::string bind = "127.0.0.1";
  int port = 8080;                          ///< 0 = ephemeral (tests)
  std::string dataDir = "./var";            ///< SQLite database and nothing else
  /// Where sessions and jobs are stored (`--store`): empty = SQLite in dataDir; a
  /// "postgresql://…" URI = the shared PostgreSQL store of several daemons (issue 18).
  std::string store;
  /// This daemon's name among several (`--node-id`): in job leases, /api/health and the metrics.
  /// Empty = the host name and the process id.
  std::string nodeId;
  /// Leases on a shared store (`--lease-ms`): a session or job whose node stops renewing it for
  /// this long (the node died) is taken over by another node. Renewed every leaseMs / 10.
  double leaseMs = 10000.0;
  std::string apiKey;                       ///< when set, creating sessions and jobs needs it
  /// Built web app served at / (empty = none); read into memory by start() (StaticAssets),
  /// which throws when it is not a folder it can serve.
  std::string webRoot;
  std::vector<std::string> demoScenes;      ///< scene files opened as public demo sessions
  std::size_t maxMessageBytes = 1u << 20;   ///< one WebSocket message
  double messageRate = 200.0;               ///< WebSocket messages per second per connection (burst 2×)
  int maxSessions = 256;
  int maxClientsPerSession = 32;
  int maxControlPoints = 20000;             ///< per scene (sum over curves), proto::ResourceLimits
  int maxIterationsPerRequest = 1000;
  /// Estimated peak memory of one session's or job's model (proto::ResourceLimits::memoryBudgetBytes).
  double memoryBudgetMb = 512.0;
  int workerThreads = 0;                    ///< session workers; 0 = hardware concurrency
  /// HTTP requests and connections: body (--max-body), head size and fields, deadlines,
  /// connection caps, route workers (defaults in transport/Limits.h).
  transport::HttpLimits http;
  JobLimits jobs;
  SessionSettings session;
};

/// The daemon: one port for REST, the web app and the WebSocket (transport::Server), sessions on
/// a worker pool, a batch job queue, SQLite persistence. Thin route handlers; the work happens in
/// Session, JobQueue and SceneSolver.
class Daemon {
 public:
  explicit Daemon(DaemonOptions options);
  ~Daemon();

  /// Opens the store, restores sessions and jobs, opens demo sessions, binds. Returns the port,
  /// or −1 when abandonStart() was called meanwhile (nothing bound).
  int start();
  /// From another thread (a signal during start-up): start() stops restoring and returns −1.
  void abandonStart() { startAbandoned_ = true; }
  /// Serves until stop() (blocking).
  void run();
  /// Graceful: closes WebSockets (1001), stops accepting, finishes the current iteration.
  void stop();

  std::size_t sessionCount() const;

 private:
  struct Client;  // per WebSocket connection
  void routes();
  void restoreSessions();
  /// Restores one stored session into sessions_, or quarantines it. @return whether it is served
  bool restoreSession(const store::RestoredSession& stored);
  /// A shared store: takes a session that no live node holds (its lease), replays its journal and
  /// serves it here. @return nullptr when it does not exist or another node holds it
  std::shared_ptr<Session> adoptSession(const std::string& id);
  /// A shared store: renews this node's session leases; sessions it lost are dropped here and
  /// their clients disconnected (they reconnect to the node that holds them now).
  void renewSessionLeases();
  /// A shared store: why a session the store knows is not served here ("served by node X (…)",
  /// "between nodes (…)", …), for an `unavailable` answer the client retries; nullopt for a
  /// session the store does not know (or a store that is not shared).
  std::optional<std::string> sessionHolder(const std::string& id) const;
  void openDemos();
  /// Builds a session (buildSession), stores it and serves it (registerSession).
  std::shared_ptr<Session> createSession(const proto::Scene& scene, const std::string& editToken,
                                         const std::string& viewToken, bool demo, const std::string& id);
  /// A session of `scene` (its model built), not yet stored nor served; safe on any thread.
  std::shared_ptr<Session> buildSession(const proto::Scene& scene, const std::string& editToken,
                                        const std::string& viewToken, bool demo, const std::string& id);
  /// Stores a built session's record (and on a shared store takes its lease), then serves it.
  /// @throws store::AlreadyExistsError when the store has the id already
  void registerSession(const std::shared_ptr<Session>& session, const proto::Scene& scene);
  /// The session served here; on a shared store one no live node holds is adopted.
  std::shared_ptr<Session> findSession(const std::string& id);
  void onMessage(const std::shared_ptr<transport::Connection>& c, std::string text);
  void onClose(const std::shared_ptr<transport::Connection>& c);
  nlohmann::json openApi() const;
  std::string prometheus() const;

  /// A session a restart could not restore: kept in the store, reported, its last stored scene
  /// downloadable by its owner.
  struct Quarantined {
    std::string reason;
    Session::Tokens tokens;
    nlohmann::json scene;  ///< the newest stored scene (checkpoint, else the initial one)
    std::int64_t seq = 0;
  };
  /// The quarantined session `id` if `token` opens it, else nullopt.
  std::optional<Quarantined> quarantinedSession(const std::string& id, const std::string& token) const;

  DaemonOptions options_;
  std::unique_ptr<store::Store> store_;
  std::unique_ptr<SessionJournal> journal_;
  std::unique_ptr<JobQueue> jobs_;
  boost::asio::thread_pool pool_;
  SessionCounters counters_;
  std::unique_ptr<transport::Server> http_;
  std::unique_ptr<StaticAssets> assets_;  ///< the web app, when webRoot is set

  mutable std::mutex mutex_;
  std::map<std::string, std::shared_ptr<Session>> sessions_;
  std::map<std::string, std::pair<std::string, std::string>> demoTokens_;  ///< id → edit, view
  std::map<std::uint64_t, std::shared_ptr<Client>> clients_;
  std::map<std::string, Quarantined> quarantined_;
  std::atomic<std::uint64_t> httpRequests_{0};
  std::atomic<std::uint64_t> sessionsAdopted_{0};     ///< a shared store: sessions taken over or taken back
  std::atomic<std::uint64_t> handoversRequested_{0};  ///< … asked of another node
  std::atomic<std::uint64_t> sessionsHandedOff_{0};   ///< … given up to another node
  std::atomic<bool> startAbandoned_{false};
  std::mutex adoptMutex_;                ///< one adoption at a time (two requests for one session)
  std::thread leaseThread_;              ///< a shared store: renews session leases
  std::mutex leaseMutex_;
  std::condition_variable leaseWake_;
  bool leaseStopping_ = false;
};

/// Demo sessions are public: their tokens derive from the scene's file name.
std::string demoToken(const std::string& scenePath, const std::string& role);

}  // namespace devsurf::server
