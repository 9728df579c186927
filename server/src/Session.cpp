#include "devsurf/server/Session.h"

#include <algorithm>
#include <cmath>

#include <spdlog/spdlog.h>

#include "devsurf/proto/BoundedJson.h"
#include "devsurf/proto/Report.h"
#include "devsurf/server/Tokens.h"

#include "SessionPointRefs.h"

namespace devsurf::server {
namespace {

using nlohmann::json;
using models::strip::StripDesign;
namespace composite = models::composite;
namespace qm = models::quad_mesh;

const char* kPalette[] = {"#e6194b", "#3cb44b", "#4363d8", "#f58231", "#911eb4",
                          "#42d4f4", "#f032e6", "#9a6324", "#800000", "#469990"};

bool isEdit(const std::string& type) {
  return type != "presence" && type != "ping" && type != "join";
}

/// What the targets of edits address in a scene, without the coordinates: how many vertices, each
/// edge's ends, type and number of control points (composites), how many points each curve and
/// mesh has. Two scenes with one key number their points alike.
std::string numberingKey(const proto::Scene& scene) {
  const json model = proto::sceneToJson(scene)["model"];
  json key = json::object();
  for (const auto& [name, value] : model.items()) {
    if (name == "vertices" && value.is_array()) {
      key[name] = value.size();
    } else if (name == "edges" && value.is_array()) {
      json edges = json::array();
      for (const json& e : value)
        edges.push_back({e.value("v", json()), e.value("type", json()), e.value("points", json::array()).size()});
      key[name] = std::move(edges);
    } else if (value.is_object() && (value.contains("points") || value.contains("vertices"))) {
      key[name] = {value.value("points", json::array()).size(), value.value("vertices", json::array()).size()};
    }
  }
  return key.dump();
}

}  // namespace

using detail::codeOf;
using detail::compositeTargetJson;
using detail::quadTargetJson;
using detail::targetJson;

Session::Session(std::string id, proto::Scene scene, Tokens tokens, SessionSettings settings,
                 Scheduler schedule, SessionJournal* journal, SessionCounters* counters, bool demo)
    : id_(std::move(id)),
      name_(scene.name),
      tokens_(std::move(tokens)),
      settings_(settings),
      schedule_(std::move(schedule)),
      journal_(journal),
      counters_(counters),
      demo_(demo),
      initialScene_(scene) {
  try {
    rebuild(scene);
  } catch (const SolveFailed& e) {
    throw proto::SceneError("model", "solve", e.what());
  }
  // Revision 0 is the scene the session was built from, as given (it is stored already: the
  // initial scene, or the checkpoint a restart builds it from).
  cachedScene_ = proto::sceneToJson(scene);
  cachedMetrics_ = json(solver_->metrics());
  changed_ = false;
}

Role Session::roleOf(const Tokens& tokens, const std::string& token) {
  // Compare against both (each in constant time) so the time does not tell which one matched.
  const bool edit = hashMatches(token, tokens.editHash);
  const bool view = hashMatches(token, tokens.viewHash);
  return edit ? Role::Edit : (view ? Role::View : Role::None);
}

Role Session::authenticate(const std::string& token) const {
  Tokens tokens;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    tokens = tokens_;
  }
  return roleOf(tokens, token);
}

Session::Tokens Session::tokens() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return tokens_;
}

void Session::setTokens(Tokens tokens) {
  std::lock_guard<std::mutex> lock(mutex_);
  tokens_ = std::move(tokens);
}

void Session::setInitialScene(proto::Scene scene) { initialScene_ = std::move(scene); }

void Session::setRebuildTimeBudget(double ms) { settings_.rebuildTimeBudgetMs = ms; }

Session::Shown Session::shown() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return {shownSeq_, cachedRevision_, cachedScene_, cachedMetrics_};
}

void Session::rebuild(const proto::Scene& scene) {
  // Building the model (and solving quasi/conical strips whole) runs under the session's time
  // budget; over it, nothing changes (the current model stays).
  const engine::Deadline deadline = engine::Deadline::after(settings_.rebuildTimeBudgetMs, "this session's time budget");
  std::unique_ptr<SceneSolver> next;
  engine::SolveSummary summary;
  try {
    next = std::make_unique<SceneSolver>(scene, deadline);  // throws SceneError on a bad design
    next->setSceneTimeBudgetApplies(false);  // the same scene, the same strip: a restart recomputes it
    if (next->keepsInputGeometry()) {
      // The curves' models are solved whole on every change; a failure leaves the current model.
      proto::Metrics m;
      try {
        summary = next->solve();
        m = next->metrics();
      } catch (const engine::DeadlineExceeded&) {
        throw;
      } catch (const std::exception& e) {
        throw SolveFailed("solve_failed", std::string("the solve failed (") + e.what() +
                                              "); the session keeps its last good state");
      }
      const bool finite = std::all_of(m.begin(), m.end(), [](const auto& kv) { return std::isfinite(kv.second); });
      if (summary.reason == engine::TerminationReason::Diverged || !finite)
        throw SolveFailed("diverged", "the solve diverged; the session keeps its last good state");
    }
  } catch (const engine::DeadlineExceeded& e) {
    throw proto::SceneError("model", "time_budget",
                            std::string("building") + (next && next->keepsInputGeometry() ? " and solving" : "") +
                                " the model took too long: " + e.what() +
                                " (devsurf serve --session-time-budget-ms); nothing was applied");
  }
  next->setDeadline({});  // later solves (drags) have budgets of their own
  if (next->keepsInputGeometry()) lastSummary_ = std::move(summary);
  solver_ = std::move(next);
  changed_ = true;  // shown (and checkpointed) by the message that reports the change
}

proto::Scene Session::persistentScene() const {
  proto::Scene s = withoutZeroWeightHandles(solver_->currentScene());
  if (keepsInput()) return s;
  if (auto* c = std::get_if<composite::CompositeDesign>(&s.model)) {
    const composite::CompositeDesign& design = *c;
    c->handles.erase(std::remove_if(c->handles.begin(), c->handles.end(),
                                    [this, &design](const composite::Handle& h) {
                                      return isDragHandle(compositeTargetJson(design, h.point));
                                    }),
                     c->handles.end());
    return s;
  }
  if (auto* q = std::get_if<qm::QuadMeshDesign>(&s.model)) {
    q->handles.erase(std::remove_if(q->handles.begin(), q->handles.end(),
                                    [this](const qm::VertexHandle& h) { return isDragHandle(quadTargetJson(h.vertex)); }),
                     q->handles.end());
    return s;
  }
  auto& d = std::get<StripDesign>(s.model);
  d.handles.erase(std::remove_if(d.handles.begin(), d.handles.end(),
                                 [this](const models::strip::Handle& h) { return isDragHandle(targetJson(h.point)); }),
                  d.handles.end());
  return s;
}

json Session::sceneJson() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return cachedScene_;
}

std::int64_t Session::revision() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return cachedRevision_;
}

json Session::metricsJson() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return cachedMetrics_;
}

ExportedFile Session::exportAs(const std::string& format) const {
  return SceneSolver::exportScene(sceneJson(), format, settings_.resources,
                                  engine::Deadline::after(settings_.rebuildTimeBudgetMs, "this session's time budget"));
}

ExportedFile Session::thumbnail() const {
  std::lock_guard<std::mutex> lock(thumbnailMutex_);
  const std::int64_t current = revision();  // read before the scene: a newer scene only renders again
  if (thumbnailRevision_ != current || thumbnail_.content.empty()) {
    thumbnail_ = exportAs("png");
    thumbnailRevision_ = current;
  }
  return thumbnail_;
}

int Session::participantCount() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return static_cast<int>(participants_.size());
}

int Session::join(Role role, const std::string& name, MessageSink sink) {
  int pid;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (static_cast<int>(participants_.size()) >= settings_.maxParticipants) {
      sink(proto::wireText(json{{"type", "error"}, {"code", "session_full"},
                {"message", "this session has the maximum of " + std::to_string(settings_.maxParticipants) + " participants"},
                {"path", "session"}}),
           Delivery::Reliable, "");
      return -1;
    }
    pid = nextParticipant_++;
    Participant p{pid, name.empty() ? "guest " + std::to_string(pid) : name,
                  kPalette[(pid - 1) % (sizeof(kPalette) / sizeof(kPalette[0]))], role, std::move(sink)};
    participants_.emplace(pid, std::move(p));
  }
  // The state is built on the session's worker so it is consistent with the edit order.
  post(pid, json{{"type", "_state"}});
  return pid;
}

void Session::leave(int participant) {
  json dragging;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    const auto it = participants_.find(participant);
    if (it == participants_.end()) return;
    // An interrupted drag has no handle left, and its target's number may now be another's drag.
    if (!it->second.dragInterrupted && it->second.dragEpoch == dragInterruptions_.load()) dragging = it->second.dragging;
    participants_.erase(it);
  }
  // A participant that leaves in the middle of a drag releases it: its temporary handle must not
  // keep pulling the point for everyone else (nor keep the session from being snapshotted).
  // (Presence first: queued behind the release it would interrupt its solve.)
  post(0, json{{"type", "_presence"}});
  if (!dragging.is_null()) post(0, json{{"type", "_release"}, {"target", dragging}});
}

void Session::post(int participant, json message) {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (counters_) ++counters_->messages;
    bool coalesced = false;
    const std::string type = message.value("type", "");
    if (type == "drag" || type == "fold") {
      // Latest wins per target (per participant for the fold slider): replace a queued,
      // unprocessed message of the same gesture.
      for (auto& w : queue_) {
        if (w->message.value("type", "") == type && w->participant == participant &&
            (type == "fold" || w->message["target"] == message["target"])) {
          w->coalescedOps.push_back(w->message.value("op", json()));
          w->message = std::move(message);
          coalesced = true;
          break;
        }
      }
    }
    if (!coalesced) queue_.push_back(std::make_shared<Work>(Work{participant, std::move(message), {}}));
    if (scheduled_) return;
    scheduled_ = true;
  }
  schedule_([self = shared_from_this()]() { self->drain(); });
}

bool Session::hasQueuedWork() const {
  // Only work that changes the model interrupts a solve: a ping, a selection or a newcomer's
  // state waits for it (else another participant's click would cancel a release's `solved`).
  std::lock_guard<std::mutex> lock(mutex_);
  return std::any_of(queue_.begin(), queue_.end(), [](const std::shared_ptr<Work>& w) {
    const std::string type = w->message.value("type", "");
    return type != "ping" && type != "presence" && type != "_state" && type != "_presence" && type != "_links";
  });
}

void Session::drain() {
  for (;;) {
    std::shared_ptr<Work> work;
    {
      std::lock_guard<std::mutex> lock(mutex_);
      if (queue_.empty()) {
        // Idle: a release or solve that newer work interrupted is finished now, unless a drag is
        // still on (its own release will end with `solved`).
        if (!settlePending_ || !dragHandles_.empty()) {
          scheduled_ = false;
          return;
        }
      } else {
        work = queue_.front();
        queue_.pop_front();
      }
    }
    try {
      if (work)
        handle(*work);
      else
        settle();
    } catch (const std::exception& e) {
      // Never let one message take the session down: back to what a restart would restore (the
      // last checkpoint and the edits acknowledged since), and shown as such. A scene the model
      // refused on the way (a drag's first contact rebuilds; the session's time budget) is the
      // sender's error by its own code, not an internal one (hostile client, 20 000 messages).
      if (work) {
        const auto* scene = dynamic_cast<const proto::SceneError*>(&e);
        const auto* journal = dynamic_cast<const JournalError*>(&e);
        error(work->participant, work->message.value("op", json()),
              scene ? codeOf(*scene) : journal ? journal->code() : "internal", e.what(),
              scene ? scene->path() : std::string());
      }
      try {
        recover();
      } catch (const std::exception& again) {
        spdlog::error("session {}: cannot recover after \"{}\": {}", id_, e.what(), again.what());
      }
    }
  }
}

void Session::send(int participant, const json& message, Delivery d, const std::string& key) {
  MessageSink sink;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    auto it = participants_.find(participant);
    if (it == participants_.end()) return;
    sink = it->second.sink;
  }
  sink(proto::wireText(message), d, key);
}

void Session::broadcast(const json& message, Delivery d, const std::string& key) {
  const std::string text = proto::wireText(message);
  std::vector<MessageSink> sinks;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    for (auto& [id, p] : participants_)
      if (p.ready) sinks.push_back(p.sink);
  }
  for (auto& s : sinks) s(text, d, key);
}

void Session::error(int participant, const json& op, const std::string& code,
                    const std::string& message, const std::string& path) {
  json e{{"type", "error"}, {"code", code}, {"message", message}};
  if (!op.is_null()) e["op"] = op;
  if (!path.empty()) e["path"] = path;
  if (counters_) counters_->recordError(code);
  send(participant, e);
}

json Session::participantsJson() const {
  json list = json::array();
  for (const auto& [id, p] : participants_)
    list.push_back({{"id", id}, {"name", p.name}, {"color", p.color},
                    {"role", p.role == Role::Edit ? "edit" : "view"},
                    {"selection", p.selection},
                    {"dragging", p.dragInterrupted || p.dragEpoch != dragInterruptions_.load() ? json() : p.dragging}});
  return list;
}

json Session::presenceMessage() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return {{"type", "presence"}, {"participants", participantsJson()}};
}

json Session::stateMessage(int participant) const {
  const json constraints = constraintsJson();
  const json geometry = geometryJson();
  // The verdict of the state shown, as `solved` and `update` carry it: a page that opens a design
  // missing its thresholds says so at once (on the session's worker, as broadcastUpdate).
  const json quality = solver_->quality().toJson();
  std::lock_guard<std::mutex> lock(mutex_);
  const auto it = participants_.find(participant);
  return {{"type", "state"},
          {"session", id_},
          {"seq", seq_.load()},
          {"revision", cachedRevision_},
          {"you", participant},
          {"role", it != participants_.end() && it->second.role == Role::Edit ? "edit" : "view"},
          {"scene", cachedScene_},
          {"metrics", cachedMetrics_},
          {"geometry", geometry},
          {"quality", quality},
          {"constraints", constraints},
          {"participants", participantsJson()},
          {"settings", {{"drag_iterations", settings_.dragIterations},
                        {"release_iterations", settings_.releaseIterations}}},
          {"undo", undoCountsJson()}};
}

void Session::dropDragHandles() {
  dragHandles_.clear();
  releasedHandles_.clear();
}

bool Session::anyDrag() const {
  std::lock_guard<std::mutex> lock(mutex_);
  for (const auto& [id, p] : participants_)
    if (!p.dragging.is_null()) return true;
  return false;
}

bool Session::endInterruptedDrag(int participant, const std::string& type, const json& op,
                                 const std::vector<json>& coalescedOps) {
  bool tell = false, ended = false;
  std::string by;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    const auto it = participants_.find(participant);
    if (it == participants_.end()) return false;
    Participant& p = it->second;
    if (p.dragging.is_null() || (!p.dragInterrupted && p.dragEpoch == dragInterruptions_.load())) return false;
    tell = !p.dragInterrupted;
    p.dragInterrupted = true;
    if (type == "drag_end") {
      p.dragging = nullptr;
      p.dragInterrupted = false;
      ended = true;
    }
    if (interruptedBy_ == participant) {
      by = "your own " + interruptingEdit_;
    } else {
      const auto other = participants_.find(interruptedBy_);
      by = (other != participants_.end() && !other->second.name.empty() ? other->second.name + "'s "
                                                                         : std::string("another participant's ")) +
           interruptingEdit_;
    }
  }
  if (tell) {
    // One error for the gesture, on the first message that finds it over: the target's numbers may
    // now name another point (a vertex removed renumbers those after it), so nothing is applied.
    error(participant, op, "conflict",
          type + ": " + by + " changed the design while you dragged (its points may have other numbers now); "
                             "the drag is over — grab the point again",
          "target");
  }
  std::vector<json> acked = coalescedOps;
  if (!tell) acked.push_back(op);
  for (const json& o : acked) {
    json ack{{"type", "ack"}, {"seq", seq_.load()}};
    if (!o.is_null()) ack["op"] = o;
    send(participant, ack);
  }
  if (tell || ended) broadcast(presenceMessage());
  return true;
}

bool Session::gestureApplied(int participant, const std::string& letGo) const {
  std::lock_guard<std::mutex> lock(mutex_);
  const auto p = participants_.find(participant);
  if (p == participants_.end()) return true;  // the session's own let-go (_release)
  return letGo == "fold_end" ? p->second.folding : !p->second.dragging.is_null();
}

json Session::undoCountsJson() const { return {{"available", undo_.size()}, {"redo_available", redo_.size()}}; }

void Session::broadcastUpdate() {
  // The quality verdict of the state shown: after an undo the last `solved`'s verdict no longer
  // applies (a tryout's status line kept a fold-angle miss the undo had taken back).
  broadcast({{"type", "update"}, {"seq", seq_.load()}, {"revision", revision_}, {"scene", sceneJson()},
             {"metrics", metricsJson()}, {"geometry", geometryJson()}, {"quality", solver_->quality().toJson()},
             {"undo", undoCountsJson()}});
}

void Session::pushUndo() { pushUndo(persistentScene()); }

void Session::pushUndo(const proto::Scene& before) {
  undo_.push_back(before);
  if (static_cast<int>(undo_.size()) > settings_.undoDepth) undo_.pop_front();
  redo_.clear();
}

void Session::commit(int participant, const json& edit, const std::vector<json>& ops, const json& result) {
  const std::int64_t seq = seq_.load() + 1;
  json logged = edit;
  logged.erase("op");
  json entry = logged;
  if (!result.is_null()) entry["result"] = result;
  if (journal_) journal_->appendEdit(id_, seq, entry);  // durable before the ack (a failure leaves seq as it was)
  seq_ = seq;
  unshownEdits_.emplace_back(seq, std::move(entry));  // until a checkpoint holds its effect
  for (const json& op : ops) {
    json ack{{"type", "ack"}, {"seq", seq}};
    if (!op.is_null()) ack["op"] = op;
    send(participant, ack);
  }
  json notice{{"type", "edit"}, {"seq", seq}, {"by", participant}, {"edit", logged}};
  std::vector<MessageSink> others;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    for (auto& [id, p] : participants_)
      if (id != participant && p.ready) others.push_back(p.sink);
  }
  const std::string text = proto::wireText(notice);
  for (auto& s : others) s(text, Delivery::Reliable, "");
}

void Session::handle(const Work& work) {
  const json& m = work.message;
  const std::string type = m.value("type", "");
  const json op = m.value("op", json());
  const int pid = work.participant;

  if (type == "_links") {  // the daemon's note for an editor, after its state (Daemon: join)
    send(pid, json{{"type", "links"}, {"view_token", m.at("view_token")}});
    return;
  }
  if (type == "_state") {
    // What the newcomer is shown is durable like everything else shown. When the store cannot
    // take the current state, the session goes back to what a restart would restore (the last
    // checkpoint and the journalled edits since: durable by construction).
    if (!showState()) recover();
    send(pid, stateMessage(pid));  // first message the participant sees …
    {
      std::lock_guard<std::mutex> lock(mutex_);
      const auto it = participants_.find(pid);
      if (it != participants_.end()) it->second.ready = true;  // … then everything after it
    }
    broadcast(presenceMessage());
    return;
  }
  if (type == "_presence") {
    broadcast(presenceMessage());
    return;
  }
  if (type == "_release") {
    // The drag_end the departed participant did not send, journalled like one (a replay then
    // releases the handle too) — if its drag is still on.
    std::string path, message;
    const json canonical = canonicalTarget(m["target"], path, message);
    if (canonical.is_null() || std::find(dragHandles_.begin(), dragHandles_.end(), canonical) == dragHandles_.end())
      return;
    const json end{{"type", "drag_end"}, {"target", m["target"]}};
    if (!apply(0, end, false)) return;
    commit(0, end, {});
    release(m["target"], settings_.releaseIterations);
    return;
  }
  if (type == "ping") {
    json pong{{"type", "pong"}, {"seq", seq_.load()}};
    if (!op.is_null()) pong["op"] = op;
    send(pid, pong);
    return;
  }
  Role role = Role::None;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    const auto it = participants_.find(pid);
    if (it == participants_.end()) return;  // left meanwhile
    role = it->second.role;
    if (type == "presence") {
      if (m.contains("selection")) it->second.selection = m["selection"];
      if (m.contains("name")) it->second.name = m["name"];
    }
  }
  if (type == "presence") {
    broadcast(presenceMessage());
    return;
  }
  if (isEdit(type) && role != Role::Edit) {
    error(pid, op, "forbidden", "this connection joined with a view-only token", "type");
    return;
  }
  if ((type == "drag" || type == "drag_end") && endInterruptedDrag(pid, type, op, work.coalescedOps)) return;
  if ((type == "drag_end" || type == "fold_end") && !gestureApplied(pid, type)) {
    // The let-go of a gesture the session refused whole — a typed position too far away, a first
    // fold with nothing to fold: acknowledged without an edit. Nothing is solved or journalled;
    // its release would otherwise move a design no edit changed.
    json ack{{"type", "ack"}, {"seq", seq_.load()}};
    if (!op.is_null()) ack["op"] = op;
    send(pid, ack);
    return;
  }
  // An edit that renumbers the points (a vertex removed, a crease drawn), or undo, redo or reset,
  // ends the drags in progress: their targets may name other points now, or their start is gone.
  const bool watchDrags = type != "drag" && type != "drag_end" && type != "fold" && type != "fold_end" &&
                          type != "solve" && anyDrag();
  const std::string numberingBefore = watchDrags ? numberingKey(solver_->currentScene()) : std::string();
  if (!apply(pid, m, false)) return;
  if (watchDrags && (type == "undo" || type == "redo" || type == "reset" ||
                     numberingKey(solver_->currentScene()) != numberingBefore)) {
    ++dragInterruptions_;
    interruptedBy_ = pid;
    interruptingEdit_ = type;
    broadcast(presenceMessage());  // the interrupted drags are over for everyone's eyes at once
  }
  std::vector<json> ops = work.coalescedOps;
  ops.push_back(op);
  // Undo and redo restore a scene from a history that is not persisted: the journal keeps the
  // scene they produced, so a restart between the ack and the checkpoint still has it.
  const json result = type == "undo" || type == "redo" ? proto::sceneToJson(persistentScene()) : json();
  commit(pid, m, ops, result);

  if (type == "drag") {
    bool started = false;  // first drag message of this target by this participant
    {
      std::lock_guard<std::mutex> lock(mutex_);
      auto it = participants_.find(pid);
      started = it != participants_.end() && it->second.dragging != m["target"];
      if (it != participants_.end()) {
        it->second.dragging = m["target"];
        if (started) it->second.dragEpoch = dragInterruptions_.load();
      }
    }
    if (started) broadcast(presenceMessage());
    SolveLimits frame;
    frame.iterations = settings_.dragIterations;
    frame.timeBudgetMs = settings_.dragTimeBudgetMs;
    runSolver(pointDragLimits(frame), false);
  } else if (type == "fold") {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      auto it = participants_.find(pid);
      if (it != participants_.end()) it->second.folding = true;
    }
    if (foldTargetsCaptured_ && showState()) {
      // The first fold took the design's folds as targets and let go of its handles: every
      // client gets the scene without them and the undo step (the iterations carry geometry only).
      broadcastUpdate();
    }
    foldTargetsCaptured_ = false;
    SolveLimits frame;
    frame.iterations = settings_.dragIterations;
    frame.timeBudgetMs = settings_.dragTimeBudgetMs;
    runSolver(foldLimits(frame), false);
  } else if (type == "fold_end") {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      auto it = participants_.find(pid);
      if (it != participants_.end()) it->second.folding = false;
    }
    releaseFold(std::min(m.value("iterations", settings_.releaseIterations), settings_.maxIterationsPerRequest));
  } else if (type == "drag_end") {
    const int iterations = std::min(m.value("iterations", settings_.releaseIterations), settings_.maxIterationsPerRequest);
    {
      // Before the release: a participant that leaves once it has `solved` has no drag left to end.
      std::lock_guard<std::mutex> lock(mutex_);
      auto it = participants_.find(pid);
      if (it != participants_.end()) it->second.dragging = nullptr;
    }
    release(m["target"], iterations);
    broadcast(presenceMessage());
  } else if (type == "solve" || type == "rotate_points" || type == "remove_control_point" || type == "merge_faces" ||
             type == "remove_vertex" ||
             (type == "relabel_edge" && m.value("label", "") == "R")) {
    // A structural edit that then solves: its scene first (the solve's messages carry geometry
    // and metrics only, and a client keeps editing by the scene's indices).
    if (type != "solve" && showState())
      broadcastUpdate();
    SolveLimits limits;
    limits.iterations = std::min(m.value("iterations", settings_.releaseIterations), settings_.maxIterationsPerRequest);
    limits.timeBudgetMs = settings_.releaseTimeBudgetMs;
    limits.hardTolerance = settings_.releaseHardTolerance;
    runSolver(limits, true);
  } else if (showState()) {
    broadcastUpdate();
  }
}

}  // namespace devsurf::server
