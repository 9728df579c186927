// Session: its state for a checkpoint, rolling back a failed solve, restoring a stored state and
// recovering after a restart.
#include "devsurf/server/Session.h"

#include <spdlog/spdlog.h>

#include "SessionPointRefs.h"

namespace devsurf::server {
namespace {

using nlohmann::json;

}  // namespace

using detail::nonFiniteMetric;

json Session::sessionStateJson() const {
  return {{"drag_iterations", settings_.dragIterations}, {"release_iterations", settings_.releaseIterations}};
}

bool Session::checkpoint(std::string* failure) {
  json scene = proto::sceneToJson(persistentScene());
  json metrics = json(solver_->metrics());
  std::string bad;
  if (const std::string path = proto::nonFinitePath(scene); !path.empty()) bad = "number at " + path;
  else if (const std::string m = nonFiniteMetric(metrics); !m.empty()) bad = m;
  if (!bad.empty()) {
    if (failure) *failure = "the solve gave a non-finite " + bad;
    return false;
  }
  json state = sessionStateJson();
  state["metrics"] = metrics;  // as measured now: a model rebuilt from the scene measures from itself
  SessionCheckpoint c{seq_.load(), revision_ + 1, std::move(scene), std::move(state)};
  if (journal_) {
    try {
      journal_->saveCheckpoint(id_, c);  // durable before anyone is shown it
    } catch (const std::exception& e) {
      // The store failed (disk full …): the state stays in the model, unshown, until a later
      // checkpoint succeeds; REST readers keep the last stored one. Nothing is rolled back.
      if (counters_) counters_->recordError("internal");
      broadcast({{"type", "error"}, {"code", "internal"}, {"seq", seq_.load()},
                 {"message", std::string("the session's state could not be stored (") + e.what() +
                                 "); it is shown once it is"}});
      return false;
    }
  }
  revision_ = c.revision;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    cachedScene_ = std::move(c.scene);
    cachedMetrics_ = std::move(metrics);
    cachedRevision_ = revision_;
    shownSeq_ = c.seq;
  }
  unshownEdits_.clear();
  changed_ = false;
  return true;
}

bool Session::showState() {
  // A new seq is a new state even when the geometry did not move (a drag_end of a quasi strip).
  if (!changed_) {
    std::lock_guard<std::mutex> lock(mutex_);
    if (shownSeq_ == seq_.load()) return true;
  }
  std::string failure;
  if (checkpoint(&failure)) return true;
  if (!failure.empty()) rollBack(failure);  // empty: the store failed, the state waits unshown
  return false;
}

void Session::rollBack(const std::string& why) {
  if (counters_) counters_->recordError("diverged");
  rebuild(proto::sceneFromJson(sceneJson(), settings_.resources));  // the last checkpoint: what everyone was last shown
  dropDragHandles();
  unshownEdits_.clear();  // their effect went with the state: the checkpoint below takes their seq
  // Checkpointed again at the current seq, so a restart does not re-apply the edits that led here.
  checkpoint(nullptr);
  broadcast({{"type", "error"}, {"code", "diverged"}, {"seq", seq_.load()}, {"revision", revision_},
             {"message", why + "; the session went back to its last good state"}});
}

void Session::restore(const json& state, std::int64_t revision,
                      const std::vector<std::pair<std::int64_t, json>>& edits, std::int64_t lastSeq) {
  if (state.is_object()) {
    settings_.dragIterations = state.value("drag_iterations", settings_.dragIterations);
    settings_.releaseIterations = state.value("release_iterations", settings_.releaseIterations);
  }
  revision_ = revision;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    cachedRevision_ = revision;
    shownSeq_ = edits.empty() ? lastSeq : edits.front().first - 1;
    // The metrics as they were shown (a model built from the scene measures from that scene:
    // displacements and ruling ratios would start over).
    if (state.is_object() && state.contains("metrics")) cachedMetrics_ = state["metrics"];
  }
  applyUnsolved(edits);
  seq_ = lastSeq;
  unshownEdits_ = edits;
  if (!edits.empty()) {
    changed_ = true;  // a new revision at the last seq, even when the edits changed nothing (drag_end)
    showState();
  }
}

void Session::applyUnsolved(const std::vector<std::pair<std::int64_t, json>>& edits) {
  // The edits acknowledged after the last checkpoint had shown nothing yet: they are applied,
  // not solved (a solve under a time budget would not give back what the daemon computed, and
  // nobody saw it). Undo and redo carry the scene they produced.
  for (const auto& [seq, edit] : edits) {
    const std::string type = edit.value("type", "");
    if ((type == "undo" || type == "redo") && edit.contains("result")) {
      rebuild(proto::sceneFromJson(edit["result"], settings_.resources));
      dropDragHandles();
    } else if (type == "drag_end") {
      releaseDragHandle(edit["target"]);
    } else if (!apply(0, edit, true)) {
      spdlog::warn("session {}: journalled edit {} ({}) no longer applies; skipped", id_, seq, type);
    }
  }
  if (!dragHandles_.empty() || !releasedHandles_.empty()) {
    // Temporary handles end with their participants (after a restart there are none).
    const proto::Scene scene = persistentScene();
    rebuild(scene);
    dropDragHandles();
  }
}

void Session::recover() {
  rebuild(proto::sceneFromJson(sceneJson(), settings_.resources));  // the last checkpoint
  dropDragHandles();
  const auto edits = unshownEdits_;
  applyUnsolved(edits);
  changed_ = true;
  showState();
}

}  // namespace devsurf::server
