#pragma once

#include <atomic>
#include <chrono>
#include <cstdint>
#include <deque>
#include <functional>
#include <iterator>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "devsurf/engine/ThreadCpuClock.h"
#include "devsurf/proto/Scene.h"
#include "devsurf/server/SceneSolver.h"

namespace devsurf::server {

/// How a message to a participant may be treated by a slow connection.
enum class Delivery {
  Reliable,  ///< in order, never dropped
  Latest,    ///< may be replaced by a newer message with the same key (iterates)
};

/// Where a session's messages to one participant go (a WebSocket connection, a test).
using MessageSink = std::function<void(std::string text, Delivery delivery, const std::string& key)>;

/// A state of a session as participants are shown it: the scene (temporary drag handles left
/// out), the session's own settings, the seq of the last edit applied and the revision, which
/// grows by one with every state shown.
struct SessionCheckpoint {
  std::int64_t seq = 0;
  std::int64_t revision = 0;
  nlohmann::json scene;
  nlohmann::json state;  ///< {"drag_iterations", "release_iterations"}
};

/// A journal that could not store (the store is unreachable, or another daemon holds the session
/// now): nothing was stored, so nothing is acknowledged or shown. Participants get an error with
/// code(): "store_unavailable" or "session_moved".
class JournalError : public std::runtime_error {
 public:
  JournalError(std::string code, const std::string& message) : std::runtime_error(message), code_(std::move(code)) {}
  const std::string& code() const noexcept { return code_; }

 private:
  std::string code_;
};

/// What a session writes so that a restarted daemon can restore it.
class SessionJournal {
 public:
  virtual ~SessionJournal() = default;
  /// Durable on return: only then is the edit acknowledged.
  virtual void appendEdit(const std::string& session, std::int64_t seq, const nlohmann::json& edit) = 0;
  /// Durable on return: only then is the state shown to anyone (streamed, sent, served by REST).
  virtual void saveCheckpoint(const std::string& session, const SessionCheckpoint& checkpoint) = 0;
};

enum class Role { None, View, Edit };

/// Settings of a session (limits and interaction defaults).
struct SessionSettings {
  /// Iterations per drag message at most: as many as fit in dragTimeBudgetMs run (at least one),
  /// and a newer message interrupts them (000_… §4.1 runs one round per mouse move).
  int dragIterations = 20;
  /// Per drag message (a frame at 40 frames/s). This and releaseTimeBudgetMs count the CPU time
  /// of the session's solving thread (engine::BudgetClock::ThreadCpu), not wall time: a busy
  /// machine delays a result rather than cutting it short, and newer work interrupts a solve.
  double dragTimeBudgetMs = 25.0;
  /// A solve on the thread's CPU clock also ends after this many times its budget of wall time
  /// (engine::SolverOptions::budgetWallCapMs): a starved machine gets a shorter result rather
  /// than a session held for minutes.
  double budgetWallCap = 10.0;
  /// Step control band of every streamed iterate (engine::StepControlOptions::hardBand): no hard
  /// row of what a participant sees is above it.
  double dragHardBand = 1e-3;
  /// The band of a drag of points on a composite that keeps a development (its isometry rows
  /// compare short sample edges of the flat sheet): a tenth, so that the drag stretches the sheet
  /// a tenth as much… (The fold slider keeps dragHardBand: its steps follow fold-angle targets.)
  double developedDragHardBand = 1e-4;
  /// … 3e-4 when the crease rows hold the faces' ruling normals (CompositeModel::rulingCreases):
  /// they have no normals to share a row's error with, and at 1e-4 a drawn sheet's drag stalled
  /// with a crease row near its end just above the band (corner 49.4 mm; at 3e-4 53.7 mm, its
  /// lengths 0.23 %; free normals at 1e-4: 58.1 mm, 0.12 %).
  double developedDragHardBandRulingCreases = 3e-4;
  /// … and the correction steps after each of its steps (engine::SolverOptions::correctionSteps)
  /// that let the drag still follow the pointer within that band: without them each linear step
  /// leaves a second-order stretch above it, and the drag stalls. The fold slider's frames and
  /// fold_end's catch-up take them too, at dragHardBand (foldLimits). Other models take none (each
  /// costs two residual evaluations and a solve: a 10 000-unknown composite's drag iterates 35 %
  /// slower with two).
  int developedCorrectionSteps = 2;
  /// After drag_end: iterations at most in each of the two release phases — with the drag's
  /// handle (it catches up with the pointer as far as the hard rows allow), then without it until
  /// every hard row is within releaseHardTolerance ("runs to quality, not to a count") — within
  /// releaseTimeBudgetMs in all. Solve uses the second phase alone.
  int releaseIterations = 200;
  double releaseTimeBudgetMs = 2000.0;
  /// Share of releaseTimeBudgetMs the first phase may take. A handle pulled beyond what the sheet
  /// allows never arrives, so the first phase often uses all of its share; the projections of
  /// the second are what make the result exact (drag stress suite: with half of 1.5 s, 6 of the 45
  /// drags of the folded annulus and the cylinder crease ran out of time outside the thresholds).
  double releaseHandleShare = 0.25;
  /// The second phase's goal: every hard row within this. The dense metrics need it tighter than
  /// the rows alone suggest: a strip bent hard near a curve end kept a max warp of 0.17° between
  /// its collocation points at 1e-5 and 0.001° at 1e-7 (strip lifted corner, corner pulled 40%).
  double releaseHardTolerance = 1e-7;
  /// ε_reg of the second release phase. Without targets the steps are projections, and a scene's
  /// larger ε_reg (0.01; the folded annulus 0.1) damps the correction of ill-conditioned rows to a
  /// slow linear convergence. Measured on the drag stress suite (folded annulus and cylinder
  /// crease, 45 drags): at 3e-3 6 ended outside the thresholds, at 1e-3 2; after one
  /// 40% drag of the annulus, development error 1.9e-4 at 3e-3, 3.0e-5 at 1e-3, 1.3e-3 at 3e-4
  /// (the time budget ran out: the smaller damping overshoots and steps are shortened).
  double polishRegularization = 1e-3;
  /// Iterates are streamed at most this often (the first and the last of every solve always):
  /// ~30 frames/s;
  /// and at most every 2× what streaming the last one cost, so that building the geometry never
  /// takes more than a third of a solve (folded annulus: 50 ms per iterate's geometry, 12 ms per
  /// iteration).
  double streamIntervalMs = 30.0;
  int maxIterationsPerRequest = 1000;
  int maxParticipants = 32;
  int undoDepth = 100;
  int surfaceSamples = 96;          ///< u samples of the streamed surface (strips)
  int compositeSamplesPerSpan = 12; ///< samples per spline span of the streamed composite faces
  /// What the session's scene may ask for (control points, iterations, estimated memory): every
  /// structural edit (set_params, set_solver, …) is checked before its model is built; one over
  /// a limit is refused with code `limit`, naming the field.
  proto::ResourceLimits resources;
  /// Time budget of building the session's model after a structural edit, and for quasi_strip
  /// and conical_strip of solving it whole (`--session-time-budget-ms`): an edit over it is refused
  /// with code `time_budget`, nothing applied and nothing journalled (engine::Deadline).
  double rebuildTimeBudgetMs = 5000.0;
};

/// Counters the daemon exports on /api/metrics.
struct SessionCounters {
  std::atomic<std::uint64_t> iterations{0};
  std::atomic<std::uint64_t> messages{0};
  /// Counts an error answered to a client (WebSocket `error` or REST 4xx/5xx) by its code.
  void recordError(const std::string& code) {
    std::lock_guard<std::mutex> lock(errorsMutex_);
    ++errors_[code];
  }
  /// Errors answered so far, by code.
  std::map<std::string, std::uint64_t> errorsByCode() const {
    std::lock_guard<std::mutex> lock(errorsMutex_);
    return errors_;
  }
  /// Histogram of the wall time of session solver iterations (milliseconds, cumulative buckets
  /// are formed when exported).
  static constexpr double kBucketsMs[] = {1, 2, 5, 10, 20, 50, 100, 200, 500, 1000};
  std::atomic<std::uint64_t> iterationBuckets[std::size(kBucketsMs) + 1] = {};
  std::atomic<std::uint64_t> iterationMicros{0};  ///< sum, for the histogram's _sum
  void recordIteration(double ms) {
    std::size_t b = 0;
    while (b < std::size(kBucketsMs) && ms > kBucketsMs[b]) ++b;
    ++iterationBuckets[b];
    iterationMicros += static_cast<std::uint64_t>(ms * 1000.0);
    ++iterations;
  }

 private:
  mutable std::mutex errorsMutex_;
  std::map<std::string, std::uint64_t> errors_;
};

/// One editing session: a scene, its model ("strip", "composite", "quasi_strip" or
/// "conical_strip") and solver, its participants and its edit history.
///
/// Points are addressed as the scene does: strips {"curve": "a"|"b", "index": i}; composites
/// {"vertex": i} or {"edge": e, "index": k} (S edges; index 0 and n−1 are the edge's vertices and
/// are read as those vertices); quasi_strip {"curve": "c1"|"c2", "index": i}; conical_strip
/// {"curve": "p"|"q", "index": i}. Internally every target is kept in that canonical form.
///
/// quasi_strip and conical_strip keep their input curves: a drag moves the control point itself
/// (no handles), then the model is rebuilt and solved whole (SceneSolver::solve); a solve that
/// fails or diverges is rejected (`diverged` / `solve_failed`) and the session keeps its last good
/// state. Their parameters change with the structural edit "set_params".
///
/// Threading: `post()` and `join()`/`leave()` may be called from any thread. Work runs on the
/// session's own executor (a strand: one worker at a time), which the owner supplies as
/// `schedule`. Drags that arrive while the solver is busy replace the queued drag of the same
/// target (latest wins); any queued work interrupts a running solve between iterations.
/// A whole solve of a quasi_strip or conical_strip session failed (`code`: "diverged" or
/// "solve_failed"); the session kept its previous state.
class SolveFailed : public std::runtime_error {
 public:
  SolveFailed(std::string code, const std::string& message) : std::runtime_error(message), code_(std::move(code)) {}
  const std::string& code() const { return code_; }

 private:
  std::string code_;
};

class Session : public std::enable_shared_from_this<Session> {
 public:
  /// Hashes (Tokens.h: tokenHash, SHA-256 hex) of the session's capability tokens (the tokens
  /// themselves are only ever shown to the creator).
  struct Tokens {
    std::string editHash;
    std::string viewHash;
  };
  using Scheduler = std::function<void(std::function<void()>)>;

  /// @throws proto::SceneError when the scene's model cannot be built
  Session(std::string id, proto::Scene scene, Tokens tokens, SessionSettings settings,
          Scheduler schedule, SessionJournal* journal, SessionCounters* counters,
          bool demo = false);

  /// Restores a session built from its last checkpoint's scene (or the initial scene): the
  /// checkpoint's session state and revision, then every journalled edit after it, applied
  /// without solving (the solves that had shown nothing yet when the daemon stopped), so the
  /// session is exactly in the last state it showed, plus the edits acknowledged since. A
  /// temporary drag handle does not survive a restart (its participant is gone).
  /// @param[in] state     SessionCheckpoint::state, or null
  /// @param[in] revision  SessionCheckpoint::revision (0 without a checkpoint)
  /// @param[in] edits     (seq, edit) after the checkpoint, in order
  /// @param[in] lastSeq   seq of the last acknowledged edit
  void restore(const nlohmann::json& state, std::int64_t revision,
               const std::vector<std::pair<std::int64_t, nlohmann::json>>& edits, std::int64_t lastSeq);

  const std::string& id() const { return id_; }
  bool demo() const { return demo_; }
  const std::string& name() const { return name_; }
  /// The role a token grants (constant-time comparisons).
  Role authenticate(const std::string& token) const;
  /// The role a token grants against stored token hashes (Tokens.h: hashMatches).
  static Role roleOf(const Tokens& tokens, const std::string& token);
  /// Replaces the token hashes (demo sessions: their public tokens are derived anew at start).
  void setTokens(Tokens tokens);
  /// The token hashes the session authenticates against.
  Tokens tokens() const;
  /// The scene `reset` returns to (the one the session was created with; a restored session is
  /// built from its last checkpoint and told this separately). Before the session is shared.
  void setInitialScene(proto::Scene scene);
  /// SessionSettings::rebuildTimeBudgetMs from now on (a restore builds without one: what was
  /// built and shown before must come back, even on a machine slower at the moment).
  void setRebuildTimeBudget(double ms);

  /// The last state shown, read at once: its seq (edits acknowledged since, not yet shown, are
  /// not in it), revision, scene and metrics — what REST readers get and a restart restores.
  struct Shown {
    std::int64_t seq = 0;
    std::int64_t revision = 0;
    nlohmann::json scene;
    nlohmann::json metrics;
  };
  Shown shown() const;

  /// Adds a participant; sends it the full state and tells everyone who is there.
  /// @returns the participant id, or −1 when the session is full (an error is sent)
  int join(Role role, const std::string& name, MessageSink sink);
  void leave(int participant);
  int participantCount() const;

  /// Queues a schema-valid client message from a participant for the session's worker.
  void post(int participant, nlohmann::json message);

  /// Current scene (with handles the user placed; temporary drag handles left out).
  nlohmann::json sceneJson() const;
  nlohmann::json metricsJson() const;
  /// The current design exported (SceneSolver::exportAs: obj, and fold/svg for composites with a
  /// development), built from the current scene so it never waits for the session's worker.
  /// @throws ExportUnavailable when the format does not apply
  ExportedFile exportAs(const std::string& format) const;
  /// A picture of the current surface (exportAs "png", 320 × 240), rendered once per revision
  /// and kept: the start page asks for every demo's on each load.
  ExportedFile thumbnail() const;
  std::int64_t seq() const { return seq_.load(); }
  /// The revision of the state REST readers get (sceneJson, metricsJson): the last one shown.
  std::int64_t revision() const;

 private:
  struct Participant {
    int id;
    std::string name, color;
    Role role;
    MessageSink sink;
    nlohmann::json selection;  // null or a target
    nlohmann::json dragging;   // null or a target
    std::uint64_t dragEpoch = 0;   // dragInterruptions_ when this drag began
    bool dragInterrupted = false;  // an edit dropped the drag handles meanwhile: the gesture is over
    bool folding = false;      // moving the fold slider (between its first fold and fold_end)
    bool ready = false;        // got its state: from then on it receives broadcasts
  };
  struct Work {
    int participant;
    nlohmann::json message;
    std::vector<nlohmann::json> coalescedOps;  // ops of drags this one replaced
  };

  void drain();
  void handle(const Work& work);
  void send(int participant, const nlohmann::json& message, Delivery d = Delivery::Reliable, const std::string& key = {});
  void broadcast(const nlohmann::json& message, Delivery d = Delivery::Reliable, const std::string& key = {});
  void error(int participant, const nlohmann::json& op, const std::string& code, const std::string& message, const std::string& path = "");
  nlohmann::json stateMessage(int participant) const;
  nlohmann::json presenceMessage() const;
  nlohmann::json participantsJson() const;

  /// Applies an edit to the model; returns false (after sending an error) if it is rejected.
  bool apply(int participant, const nlohmann::json& edit, bool replaying);
  /// Records an applied edit: seq, journal (durable, with `result` when not null), ack to the
  /// sender, edit to the others.
  void commit(int participant, const nlohmann::json& edit, const std::vector<nlohmann::json>& ops,
              const nlohmann::json& result = nullptr);
  /// Runs iterations within the limits (the session's band applied), streaming iterates; when
  /// `final`, ends with `solved` (the metrics and the quality verdict). Returns false if
  /// interrupted by queued work.
  /// Makes the current state durable (SessionJournal::saveCheckpoint) and the one REST readers
  /// get, as the next revision — before any message shows it. Checks it first: a state with a
  /// non-finite coordinate or metric is never stored or shown; then it returns false and says
  /// why in `failure` (the caller rolls back once it is safe: not inside a solve). When the
  /// journal throws it returns false with `failure` empty: the state stays, unshown, and
  /// participants get `internal`.
  bool checkpoint(std::string* failure);
  /// checkpoint() if the state changed since the last one, else nothing; on a failure rolls back
  /// and returns false. Call before a message shows the state.
  bool showState();
  /// The session's own settings that a checkpoint keeps beside the scene.
  nlohmann::json sessionStateJson() const;
  /// Back to the last checkpointed scene (temporary handles dropped), telling everyone why.
  void rollBack(const std::string& why);
  /// Applies journalled edits without solving them (restore(), recover()), then drops temporary
  /// handles. An edit that no longer applies is logged and skipped.
  void applyUnsolved(const std::vector<std::pair<std::int64_t, nlohmann::json>>& edits);
  /// After an exception in the middle of an edit: the state a restart would restore (the last
  /// checkpoint and the edits acknowledged since, applied), shown as such.
  void recover();
  bool runSolver(SolveLimits limits, bool final);
  /// `limits` for the iterations of a drag of points (its frames and the release's catch-up, not
  /// the fold slider or a polish): a composite that keeps a development holds
  /// developedDragHardBand with developedCorrectionSteps.
  SolveLimits pointDragLimits(SolveLimits limits) const;
  /// `limits` for the fold slider's iterations (its frames and fold_end's catch-up): a composite
  /// that keeps a development takes developedCorrectionSteps at dragHardBand. Without them a
  /// folding sheet's plain steps leave the band beyond ~0.5° and are shortened, and a slow machine's
  /// catch-up ran out of time at 60° of an imported column's 93°.
  SolveLimits foldLimits(SolveLimits limits) const;
  /// fold_end: iterations with the fold-angle targets, then the release's polish.
  void releaseFold(int iterations);
  /// The second phase of a release (drag_end, fold_end): projection steps until every hard row is
  /// within the tolerance, within what is left of the release time budget since `start`.
  /// Projection steps to the hard tolerance; `holdFoldTargets` keeps the fold slider's targets (a
  /// fold gesture's release), otherwise every relaxable term drops out (a drag's release).
  void polishRelease(engine::ThreadCpuClock::time_point start, int iterations, bool holdFoldTargets = false);
  /// The two release phases after drag_end (see SessionSettings::releaseIterations).
  void release(const nlohmann::json& target, int iterations);
  /// Finishes a release or solve that newer work interrupted (settlePending_): the projection
  /// phase, then `solved`. drain() calls it once the queue is empty and no drag is on, so every
  /// drag_end and solve is answered by a `solved` (another participant's drag or edit may come
  /// first).
  void settle();
  /// Builds the scene's model (and, for quasi_strip/conical_strip, solves it whole) and installs
  /// it; on any failure the current model stays.
  /// @throws proto::SceneError (a design the model rejects), SolveFailed (a failed/diverged solve)
  void rebuild(const proto::Scene& scene);
  /// quasi_strip / conical_strip: the iterate (geometry, metrics) of the last whole solve and,
  /// when `final`, `solved`.
  void publishSolve(bool final);
  /// Applies an edit to a quasi_strip/conical_strip session (drag moves a control point).
  bool applyCurveEdit(int participant, const nlohmann::json& edit, bool replaying, const nlohmann::json& target);
  /// The fold slider's "fold" (composite sessions): the first one of a design without fold-angle
  /// targets takes its current fold angles as 100 % (a rebuild); after that only the amount moves.
  bool applyFold(int participant, const nlohmann::json& edit, bool replaying);
  /// Layout edits of a composite drawn on a sheet (draw_crease, erase_crease, relabel_crease,
  /// reshape_crease; SessionDrawing.cpp): the drawing changes and the composite is rebuilt from it,
  /// flat. Refused edits change nothing.
  bool applyDrawingEdit(int participant, const nlohmann::json& edit, bool replaying);
  /// Refuses an edit: an `error` to its sender ("TYPE: message", code, path; nothing while
  /// replaying the journal). Returns false, what apply() returns for a refused edit.
  bool refuse(int participant, const nlohmann::json& edit, bool replaying, const std::string& code,
              const std::string& message, const std::string& path);
  /// refuse() bound to one edit: `reject(code, message, path)`.
  auto refuser(int participant, const nlohmann::json& edit, bool replaying) {
    return [this, participant, &edit, replaying](const std::string& code, const std::string& message, const std::string& path) {
      return refuse(participant, edit, replaying, code, message, path);
    };
  }
  /// The end of a structural edit built outside the scene document: `next` read back (the schema,
  /// the model's checks, the limits) and rebuilt, `before` one undo step, temporary handles
  /// dropped. A refused rebuild changes nothing and is refused naming the scene's path (a failed
  /// solve: `solvePath`).
  bool rebuildForEdit(int participant, const nlohmann::json& edit, bool replaying, const proto::Scene& before,
                      const proto::Scene& next, const std::string& solvePath);
  static bool isDrawingEdit(const std::string& type);
  /// "rotate_points" (SessionGroupRotation.cpp): turns the targets of a composite rigidly about an
  /// axis (one rebuild, one undo step); handle() then solves as for "solve".
  bool applyGroupRotation(int participant, const nlohmann::json& edit, bool replaying);
  /// "add_control_point" / "remove_control_point" (SessionControlPoints.cpp): a knot inserted into
  /// (exact) or removed from (least squares) every S edge sharing the edge's spline space; one
  /// rebuild, one undo step; removal then solves as for "solve".
  bool applyControlPointEdit(int participant, const nlohmann::json& edit, bool replaying);
  /// "relabel_edge" / "split_face" / "merge_faces" (SessionLabelledMesh.cpp): the labelled mesh of
  /// a composite without a drawing edited (edges R ↔ S, a new ruling between two corners of a
  /// face, the two faces of an edge joined); one rebuild, one undo step; relabel and merge then
  /// solve as for "solve". The composite's checks decide; a refusal quotes them.
  bool applyLabelledMeshEdit(int participant, const nlohmann::json& edit, bool replaying);
  /// Refuses an edit of another session kind than composite ("type"); true when refused.
  bool refusedUnlessComposite(int participant, const nlohmann::json& edit, bool replaying);
  bool keepsInput() const { return solver_->keepsInputGeometry(); }
  proto::Scene persistentScene() const;
  void pushUndo();
  void pushUndo(const proto::Scene& before);
  bool hasQueuedWork() const;
  bool isComposite() const { return solver_->isComposite(); }
  /// A composite whose fold-angle targets fold it (foldAmount > 0): releases hold them.
  bool holdsFoldTargets() const;
  /// Whether the session's composite has fold-angle targets (model.fold_angles), at any amount.
  bool hasFoldAngles() const;
  /// The canonical form of a client's target in this session's model, or null with `path` and
  /// `message` saying what is wrong (wrong addressing for the model kind, index out of range).
  nlohmann::json canonicalTarget(const nlohmann::json& target, std::string& path, std::string& message) const;
  /// Canonical target of an entry of the scene's "fixed"/"handles" lists (same addressing keys).
  nlohmann::json pointKey(const proto::Scene& current, const nlohmann::json& entry) const;
  /// Index of the model's handle on that (canonical) target, or −1.
  int handleIndex(const proto::Scene& current, const nlohmann::json& target) const;
  /// A temporary handle of a drag, active or released (both are left out of the scene).
  bool isDragHandle(const nlohmann::json& target) const;
  /// A temporary handle whose drag ended: still in the model, at weight 0.
  bool isReleasedHandle(const nlohmann::json& target) const;
  /// The scene without handles of weight 0 (released temporary handles).
  static proto::Scene withoutZeroWeightHandles(proto::Scene s);
  proto::Scene withoutReleasedHandles(proto::Scene scene) const;
  void setHandleWeight(int handle, double weight);
  void setHandleTarget(int handle, const Eigen::Vector3d& position);
  /// {"fixed": [target…], "handles": [{"target","position","weight","temporary"}…]}.
  nlohmann::json constraintsJson() const;
  /// The streamed geometry (proto::stripGeometryJson or proto::compositeGeometryJson) and the
  /// metrics an iterate carries.
  nlohmann::json geometryJson(nlohmann::json* iterateMetrics = nullptr) const;
  /// {"available", "redo_available"}: the undo and redo steps the session holds.
  nlohmann::json undoCountsJson() const;
  /// An `update` to every participant: seq, revision, scene, metrics, geometry and undo counts.
  void broadcastUpdate();
  /// Whether `participant`'s gesture that `letGo` ("drag_end" or "fold_end") ends applied a drag
  /// or a fold (true for the session's own let-go, participant 0).
  bool gestureApplied(int participant, const std::string& letGo) const;
  /// Forgets the temporary handles of drags (the model was rebuilt without them).
  void dropDragHandles();
  /// Whether some participant is dragging.
  bool anyDrag() const;
  /// A drag or drag_end of a gesture an edit interrupted: the first is answered with an error
  /// that says so, the rest with acks; drag_end ends the gesture. False for any other message.
  bool endInterruptedDrag(int participant, const std::string& type, const nlohmann::json& op,
                          const std::vector<nlohmann::json>& coalescedOps);
  /// Releases the temporary handle of a drag on `target` (rebuilds the model) if there is one.
  void releaseDragHandle(const nlohmann::json& target);
  const engine::Problem& problem() const;

  std::string id_, name_;
  Tokens tokens_;
  SessionSettings settings_;
  Scheduler schedule_;
  SessionJournal* journal_;
  SessionCounters* counters_;
  bool demo_;

  proto::Scene initialScene_;
  std::unique_ptr<SceneSolver> solver_;
  engine::SolveSummary lastSummary_;  // of the last whole solve (quasi_strip, conical_strip)
  std::vector<nlohmann::json> dragHandles_;  // canonical targets of the temporary handles of active drags
  std::chrono::steady_clock::time_point lastStreamed_{};  // when the last iterate went out
  double lastStreamMs_ = 0.0;  // what building and sending it cost
  int scheduleIteration_ = 0;  // iterations of the current interaction (drag, solve): the fairness schedule resumes there
  /// A release (or its settle) took the drag's folds as targets: the next `solved` is preceded by
  /// an `update` with the scene (worker thread).
  bool foldTargetsChangedUnsent_ = false;
  bool foldTargetsCaptured_ = false;  // the fold just applied took the design's folds as targets (worker thread)
  std::vector<nlohmann::json> releasedHandles_;  // … of ended drags (weight 0 in the model until a rebuild)
  /// Counts the edits that ended the drags in progress — those that renumbered the points
  /// (numberingKey) and undo, redo and reset: a drag begun under another count was interrupted
  /// (worker thread).
  std::atomic<std::uint64_t> dragInterruptions_{0};  // read by leave() on a transport thread
  int interruptedBy_ = 0;         ///< the participant whose edit last interrupted the drags
  std::string interruptingEdit_;  ///< … and that edit's type
  std::deque<proto::Scene> undo_, redo_;
  std::atomic<std::int64_t> seq_{0};
  std::int64_t revision_ = 0;  // of the last checkpoint (worker only; cachedRevision_ for readers)
  bool changed_ = false;       // the model's state differs from the last checkpoint
  bool settlePending_ = false; // a release or solve was interrupted before its `solved`
  bool settleAfterDrag_ = false;  // the pending settle ends a drag's release (it may capture at 0 %)
  /// Edits acknowledged (journalled) since the last checkpoint, as journalled: what a restart
  /// would apply on top of it (recover() does the same).
  std::vector<std::pair<std::int64_t, nlohmann::json>> unshownEdits_;

  mutable std::mutex thumbnailMutex_;  // guards the two below; held while one is rendered
  mutable std::int64_t thumbnailRevision_ = -1;
  mutable ExportedFile thumbnail_;
  mutable std::mutex mutex_;  // guards participants_, queue_, scheduled_, cached json
  std::map<int, Participant> participants_;
  int nextParticipant_ = 1;
  std::deque<std::shared_ptr<Work>> queue_;
  bool scheduled_ = false;
  nlohmann::json cachedScene_, cachedMetrics_;
  std::int64_t cachedRevision_ = 0;
  std::int64_t shownSeq_ = 0;
};

}  // namespace devsurf::server
