// Where a daemon's sessions come from: restored from the store at start, adopted from a shared
// store when a request arrives, handed over between daemons under leases (issue 18), created from
// demos and requests. Routes and messages: Daemon.cpp.

#include "devsurf/server/Daemon.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <numeric>
#include <sstream>
#include <system_error>
#include <thread>

#include <boost/asio/post.hpp>
#include <spdlog/spdlog.h>

#include "DaemonClient.h"
#include "devsurf/proto/Scene.h"
#include "devsurf/server/SceneSolver.h"
#include "devsurf/server/Tokens.h"
#include "devsurf/server/store/PostgresStore.h"

namespace devsurf::server {

using nlohmann::json;

void Daemon::restoreSessions() {
  const std::vector<store::RestoredSession> stored = store_->loadSessions();
  if (!stored.empty()) spdlog::info("restoring {} stored session(s)", stored.size());
  for (const store::RestoredSession& r : stored) {
    if (startAbandoned_) return;  // a signal during start-up: what is restored so far is stored
    restoreSession(r);
  }
}

bool Daemon::restoreSession(const store::RestoredSession& r) {
  // A quarantined session is tried again at every start: what stopped it may have been
  // transient (an I/O error) or fixed since (an upgrade, an operator's repair).
  std::string reason = r.loadError.value_or("");
  // What was built and shown before comes back without a time budget (a restart may run on a
  // busier machine); the session's budget applies again to the edits that follow.
  SessionSettings restoring = options_.session;
  restoring.rebuildTimeBudgetMs = 0.0;
  if (reason.empty()) {
    try {
      const json scene = r.snapshot ? r.snapshot->scene : r.session.initialScene;
      auto session = std::make_shared<Session>(
          r.session.id, proto::sceneFromJson(scene, options_.session.resources), Session::Tokens{r.session.editTokenHash, r.session.viewTokenHash},
          restoring, [this](std::function<void()> f) { boost::asio::post(pool_, std::move(f)); },
          journal_.get(), &counters_, r.session.demo);
      if (r.snapshot) session->setInitialScene(proto::sceneFromJson(r.session.initialScene));
      std::vector<std::pair<std::int64_t, json>> edits;
      for (const store::EditRecord& e : r.editsAfterSnapshot) edits.emplace_back(e.seq, e.edit);
      session->restore(r.snapshot ? r.snapshot->sessionState : json(), r.snapshot ? r.snapshot->revision : 0, edits,
                       r.lastSeq);
      session->setRebuildTimeBudget(options_.session.rebuildTimeBudgetMs);
      if (r.session.quarantine) {
        spdlog::info("session {} was quarantined ({}) and is restored now", r.session.id, *r.session.quarantine);
        store_->liftQuarantine(r.session.id);
      }
      std::lock_guard<std::mutex> lock(mutex_);
      if (const auto demo = demoTokens_.find(r.session.id); demo != demoTokens_.end())
        session->setTokens({tokenHash(demo->second.first), tokenHash(demo->second.second)});
      sessions_[r.session.id] = session;
      return true;
    } catch (const std::exception& e) {
      reason = e.what();
    }
  }
  // Kept, never deleted: the store still holds its initial scene, snapshot and journal, and its
  // last stored scene can be downloaded (GET /api/sessions/{id}/export?format=json).
  if (r.session.quarantine != reason) {
    spdlog::error("session {} could not be restored and is quarantined: {}", r.session.id, reason);
    try {
      store_->quarantineSession(r.session.id, reason);
    } catch (const std::exception& e) {
      spdlog::error("session {}: cannot record the quarantine: {}", r.session.id, e.what());
    }
  }
  Quarantined q;
  q.reason = reason;
  q.tokens = Session::Tokens{r.session.editTokenHash, r.session.viewTokenHash};
  q.scene = r.snapshot ? r.snapshot->scene : r.session.initialScene;  // null if even that did not parse
  q.seq = r.snapshot ? r.snapshot->seq : 0;
  std::lock_guard<std::mutex> lock(mutex_);
  if (const auto demo = demoTokens_.find(r.session.id); demo != demoTokens_.end())
    q.tokens = {tokenHash(demo->second.first), tokenHash(demo->second.second)};
  quarantined_[r.session.id] = std::move(q);
  return false;
}

std::shared_ptr<Session> Daemon::adoptSession(const std::string& id) {
  std::lock_guard<std::mutex> adopting(adoptMutex_);
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (const auto it = sessions_.find(id); it != sessions_.end()) return it->second;  // adopted meanwhile
  }
  try {
    if (!store_->acquireSessionLease(id, options_.nodeId, store::wallClockMs(), static_cast<std::int64_t>(options_.leaseMs))) {
      // The proxy routes this session here now (a node came back, or it was created elsewhere):
      // its holder hands it over at its next renewal, and the client's retry finds it free.
      store_->requestSessionHandover(id, options_.nodeId);
      ++handoversRequested_;
      spdlog::info("session {} is held by another node; handover requested", id);
      return nullptr;
    }
    const std::optional<store::RestoredSession> stored = store_->loadSession(id);
    if (!stored) return nullptr;
    spdlog::info("session {} adopted: journal replayed from seq {} to {}", id, stored->snapshot ? stored->snapshot->seq : 0,
                 stored->lastSeq);
    ++sessionsAdopted_;
    restoreSession(*stored);
  } catch (const store::NotFoundError&) {
    return nullptr;
  } catch (const std::exception& e) {
    spdlog::error("session {} could not be adopted: {}", id, e.what());
    return nullptr;
  }
  std::lock_guard<std::mutex> lock(mutex_);
  const auto it = sessions_.find(id);
  return it == sessions_.end() ? nullptr : it->second;
}

std::optional<std::string> Daemon::sessionHolder(const std::string& id) const {
  if (!store_->shared()) return std::nullopt;
  try {
    // The session exists but is not served here: another node holds it, or it is between holders
    // (its lease released for a handover after this node's adoption found it taken: a join was
    // answered "unauthorized" in that window once, in the cluster test). The client retries. One
    // this node leases but could not restore (quarantined) stays unknown to a wrong token.
    const auto lease = store_->sessionLease(id);
    if (!lease) return std::string("between nodes (its lease was just released for a handover)");
    if (lease->first != options_.nodeId)
      return "served by node " + lease->first + " (it moves here when that node's lease ends)";
  } catch (const store::NotFoundError&) {
  } catch (const std::exception& e) {  // the store is unreachable: the session may exist
    return std::string("perhaps served by another node (the store is unreachable: ") + e.what() + ")";
  }
  return std::nullopt;
}

void Daemon::renewSessionLeases() {
  // Lock order: adoptMutex_ → mutex_, and never a client's mutex under either (a join holds its
  // client's mutex while it looks the session up).
  std::vector<std::shared_ptr<Session>> dropped;
  std::vector<std::shared_ptr<Client>> clients;
  {
    // One at a time with adoptions and creations: a lease taken after the renewal read the held
    // ones must not be dropped as lost.
    std::lock_guard<std::mutex> adopting(adoptMutex_);
    std::vector<std::string> held;
    try {
      held = store_->renewSessionLeases(options_.nodeId, store::wallClockMs(), static_cast<std::int64_t>(options_.leaseMs));
    } catch (const std::exception& e) {  // the store is unreachable: keep serving; writes fail until it is back
      spdlog::warn("cannot renew session leases: {}", e.what());
      return;
    }
    std::sort(held.begin(), held.end());
    std::lock_guard<std::mutex> lock(mutex_);
    for (auto it = sessions_.begin(); it != sessions_.end();) {
      if (std::binary_search(held.begin(), held.end(), it->first)) {
        ++it;
        continue;
      }
      spdlog::info("session {}: handed over to another node (or its lease was taken); dropped here", it->first);
      dropped.push_back(it->second);
      it = sessions_.erase(it);
      ++sessionsHandedOff_;
    }
    if (dropped.empty()) return;
    for (const auto& [cid, client] : clients_) clients.push_back(client);
  }
  std::vector<std::shared_ptr<transport::Connection>> toClose;
  for (const auto& client : clients) {
    std::lock_guard<std::mutex> clientLock(client->mutex);
    const auto session = client->session.lock();
    if (session && std::find(dropped.begin(), dropped.end(), session) != dropped.end())
      if (auto c = client->connection.lock()) toClose.push_back(std::move(c));
  }
  for (const auto& c : toClose) c->close(transport::CloseCode::ServiceRestart, "session moved to another node; reconnect");
}

void Daemon::openDemos() {
  // Which demos are built here: not those kept quarantined or restored with their edits, nor one
  // another node of a shared store created.
  struct Pending {
    std::string path, id, edit, view;
    std::shared_ptr<Session> session;
    proto::Scene scene;
    std::string error;
  };
  std::vector<Pending> pending;
  for (const std::string& path : options_.demoScenes) {
    if (startAbandoned_) return;
    const std::string id = "demo-" + std::filesystem::path(path).stem().string();
    const std::string edit = demoToken(path, "edit"), view = demoToken(path, "view");
    {
      std::lock_guard<std::mutex> lock(mutex_);
      demoTokens_[id] = {edit, view};
      if (const auto q = quarantined_.find(id); q != quarantined_.end()) {
        q->second.tokens = {tokenHash(edit), tokenHash(view)};
        continue;  // kept as it is; reported by /api/health
      }
      if (const auto restored = sessions_.find(id); restored != sessions_.end()) {
        // Restored with its edits; its public tokens are derived anew (they may have been stored
        // with an earlier derivation or hash).
        restored->second->setTokens({tokenHash(edit), tokenHash(view)});
        continue;
      }
    }
    try {
      // A shared store: a demo another node created is adopted on its first request.
      if (store_->shared() && store_->loadSession(id)) continue;
      std::ifstream file(path, std::ios::binary);
      std::ostringstream text;
      text << file.rdbuf();
      pending.push_back({path, id, edit, view, nullptr, proto::sceneFromText(text.str()), {}});
    } catch (const std::exception& e) {
      spdlog::error("demo scene {}: {}", path, e.what());
    }
  }

  // Solving and building a demo is most of a start's time (the 32 examples: 18 s on one core) and
  // touches nothing shared, so the demos are built on every core; they are then stored and served
  // in the order given.
  // The costliest first, so that the last to finish is a short one: spline surfaces (a quad mesh
  // refined from a control net), then other quad meshes (the larger first), then the rest.
  std::vector<std::size_t> order(pending.size());
  std::iota(order.begin(), order.end(), std::size_t{0});
  auto expectedCost = [&pending](std::size_t k) -> std::pair<int, std::size_t> {
    const auto* quad = std::get_if<models::quad_mesh::QuadMeshDesign>(&pending[k].scene.model);
    if (!quad) return {0, 0};
    return {quad->control ? 2 : 1, static_cast<std::size_t>(quad->mesh.rows())};
  };
  std::stable_sort(order.begin(), order.end(),
                   [&expectedCost](std::size_t a, std::size_t b) { return expectedCost(a) > expectedCost(b); });
  std::atomic<std::size_t> next{0};
  auto buildDemos = [this, &pending, &order, &next]() {
    for (std::size_t k = next++; k < order.size(); k = next++) {
      if (startAbandoned_) return;
      Pending& demo = pending[order[k]];
      try {
        // A demo starts from its solved state (as `devsurf solve` leaves it): a visitor's first
        // drag must not also carry out the preset's own pending solve.
        const auto started = std::chrono::steady_clock::now();
        demo.scene = SceneSolver::solvedScene(std::move(demo.scene));
        const auto solved = std::chrono::steady_clock::now();
        demo.session = buildSession(demo.scene, demo.edit, demo.view, true, demo.id);
        const auto built = std::chrono::steady_clock::now();
        spdlog::debug("demo {}: solved in {:.0f} ms, built in {:.0f} ms", demo.id,
                      std::chrono::duration<double, std::milli>(solved - started).count(),
                      std::chrono::duration<double, std::milli>(built - solved).count());
      } catch (const std::exception& e) {
        demo.error = e.what();
      } catch (...) {  // nothing may leave a worker (std::terminate) or this thread with workers running
        demo.error = "an unknown error";
      }
    }
  };
  // As many as the session pool has (--workers; default: the cores).
  const std::size_t cores = options_.workerThreads > 0 ? static_cast<std::size_t>(options_.workerThreads)
                                                       : std::max(1u, std::thread::hardware_concurrency());
  const std::size_t threads = std::min<std::size_t>(pending.size(), cores);
  std::vector<std::thread> workers;
  workers.reserve(threads);
  for (std::size_t t = 1; t < threads; ++t) {
    try {
      workers.emplace_back(buildDemos);
    } catch (const std::system_error&) {
      break;  // no thread to be had (a process at its limit): the ones started and this one build them all
    }
  }
  buildDemos();
  for (std::thread& w : workers) w.join();
  if (startAbandoned_) return;

  for (Pending& demo : pending) {
    if (!demo.session) {
      spdlog::error("demo scene {}: {}", demo.path, demo.error);
      continue;
    }
    try {
      registerSession(demo.session, demo.scene);
    } catch (const store::AlreadyExistsError&) {
      // Another daemon on the shared store created it meanwhile: adopted on its first request.
    } catch (const std::exception& e) {
      spdlog::error("demo scene {}: {}", demo.path, e.what());
    }
  }
}

std::shared_ptr<Session> Daemon::createSession(const proto::Scene& scene, const std::string& editToken,
                                               const std::string& viewToken, bool demo, const std::string& id) {
  auto session = buildSession(scene, editToken, viewToken, demo, id);
  registerSession(session, scene);
  return session;
}

std::shared_ptr<Session> Daemon::buildSession(const proto::Scene& scene, const std::string& editToken,
                                              const std::string& viewToken, bool demo, const std::string& id) {
  const Session::Tokens tokens{tokenHash(editToken), tokenHash(viewToken)};
  // A demo is the operator's own scene (--demo), built at startup: like a restored session it
  // is built without the session's time budget (a slower machine, or a sanitizer build, must not
  // drop it: three conical demos took over 5 s under ASan), which then applies to its edits.
  SessionSettings settings = options_.session;
  if (demo) settings.rebuildTimeBudgetMs = 0.0;
  auto session = std::make_shared<Session>(
      id, scene, tokens, settings, [this](std::function<void()> f) { boost::asio::post(pool_, std::move(f)); },
      journal_.get(), &counters_, demo);
  if (demo) session->setRebuildTimeBudget(options_.session.rebuildTimeBudgetMs);
  return session;
}

void Daemon::registerSession(const std::shared_ptr<Session>& session, const proto::Scene& scene) {
  const Session::Tokens tokens = session->tokens();
  store::SessionRecord record;
  record.id = session->id();
  record.editTokenHash = tokens.editHash;
  record.viewTokenHash = tokens.viewHash;
  record.name = scene.name;
  record.demo = session->demo();
  record.initialScene = proto::sceneToJson(scene);
  record.createdMs = store::wallClockMs();
  std::lock_guard<std::mutex> adopting(adoptMutex_);  // held with its lease before a renewal looks
  store_->createSession(record);
  if (store_->shared())
    store_->acquireSessionLease(record.id, options_.nodeId, store::wallClockMs(), static_cast<std::int64_t>(options_.leaseMs));
  std::lock_guard<std::mutex> lock(mutex_);
  sessions_[record.id] = session;
}

std::optional<Daemon::Quarantined> Daemon::quarantinedSession(const std::string& id, const std::string& token) const {
  std::lock_guard<std::mutex> lock(mutex_);
  const auto it = quarantined_.find(id);
  if (it == quarantined_.end() || Session::roleOf(it->second.tokens, token) == Role::None) return std::nullopt;
  return it->second;
}

std::shared_ptr<Session> Daemon::findSession(const std::string& id) {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    const auto it = sessions_.find(id);
    if (it != sessions_.end()) return it->second;
    if (quarantined_.count(id)) return nullptr;  // tried at start or adoption; kept as it is
  }
  return store_->shared() ? adoptSession(id) : nullptr;
}

}  // namespace devsurf::server
