#pragma once

// Test doubles shared by the session tests: a manual executor (work runs when the test says so,
// so interleavings are explicit), an inbox collecting a participant's messages, and an in-memory
// journal.

#include <cstdint>
#include <fstream>
#include <functional>
#include <memory>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "devsurf/server/Session.h"
#include "devsurf/server/Tokens.h"

namespace devsurf::server::testing {

struct ManualExecutor {
  std::vector<std::function<void()>> tasks;
  Session::Scheduler scheduler() {
    return [this](std::function<void()> f) { tasks.push_back(std::move(f)); };
  }
  void runAll() {
    while (!tasks.empty()) {
      auto t = std::move(tasks.front());
      tasks.erase(tasks.begin());
      t();
    }
  }
};

struct Inbox {
  std::vector<nlohmann::json> messages;
  MessageSink sink() {
    return [this](std::string text, Delivery, const std::string&) { messages.push_back(nlohmann::json::parse(text)); };
  }
  std::vector<nlohmann::json> ofType(const std::string& type) const {
    std::vector<nlohmann::json> out;
    for (const nlohmann::json& m : messages)
      if (m["type"] == type) out.push_back(m);
    return out;
  }
  /// The last message of the type, or null.
  nlohmann::json last(const std::string& type) const {
    const auto all = ofType(type);
    return all.empty() ? nlohmann::json() : all.back();
  }
};

struct MemoryJournal : SessionJournal {
  std::vector<std::pair<std::int64_t, nlohmann::json>> edits;
  std::map<std::int64_t, nlohmann::json> snapshots;  ///< seq → scene of the newest checkpoint of that seq
  std::vector<SessionCheckpoint> checkpoints;         ///< every checkpoint, in order
  void appendEdit(const std::string&, std::int64_t seq, const nlohmann::json& edit) override {
    edits.emplace_back(seq, edit);
  }
  void saveCheckpoint(const std::string&, const SessionCheckpoint& c) override {
    snapshots[c.seq] = c.scene;
    checkpoints.push_back(c);
  }
  /// The edits after the newest checkpoint (what a restart applies on top of it).
  std::vector<std::pair<std::int64_t, nlohmann::json>> editsAfterLastCheckpoint() const {
    const std::int64_t after = checkpoints.empty() ? 0 : checkpoints.back().seq;
    std::vector<std::pair<std::int64_t, nlohmann::json>> out;
    for (const auto& e : edits)
      if (e.first > after) out.push_back(e);
    return out;
  }
};

/// An example scene from examples/NAME.json, as shipped.
inline nlohmann::json exampleJson(const std::string& name) {
  std::ifstream file(std::string(DEVSURF_SOURCE_DIR) + "/examples/" + name + ".json");
  return nlohmann::json::parse(file);
}
inline proto::Scene exampleScene(const std::string& name) { return proto::sceneFromJson(exampleJson(name)); }

/// A session on an example with one joined editor whose state has arrived; its edits run at once.
struct ExampleEditor {
  explicit ExampleEditor(const std::string& example, SessionSettings settings = {})
      : ExampleEditor(exampleScene(example), settings) {}
  /// A session on any scene (an import, a scene built by the test).
  explicit ExampleEditor(proto::Scene scene, SessionSettings settings = {})
      : session(std::make_shared<Session>("e1", std::move(scene),
                                          Session::Tokens{tokenHash("edit-token"), tokenHash("view-token")},
                                          settings, ex.scheduler(), &journal, nullptr)) {
    pid = session->join(Role::Edit, "", inbox.sink());
    ex.runAll();
  }
  void send(const nlohmann::json& message) {
    session->post(pid, message);
    ex.runAll();
  }
  ManualExecutor ex;
  MemoryJournal journal;
  std::shared_ptr<Session> session;
  Inbox inbox;
  int pid = -1;
};

}  // namespace devsurf::server::testing
