// Crash durability: a child process appends edits and reports every acknowledged seq through a
// pipe; the parent SIGKILLs it at a random moment, reopens the store and checks that every
// acknowledged edit survived and the log has no gaps. Repeated on the same directory, so later
// trials also exercise WAL recovery of a database left behind by a killed writer.

#include "devsurf/server/store/SqliteStore.h"

#include <gtest/gtest.h>

#include "support/TempDir.h"
#include <poll.h>
#include <signal.h>
#include <sqlite3.h>
#include <stdlib.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <random>
#include <set>

namespace fs = std::filesystem;
using nlohmann::json;
using namespace devsurf::server::store;

namespace {

/// A fresh directory per test.
class CrashTempDir : public devsurf::testing::TempDir {
 public:
  CrashTempDir() : devsurf::testing::TempDir("devsurf-crash") {}
};

const char* const kSession = "crash";

bool writeAll(int fd, const void* data, std::size_t n) {
  auto p = static_cast<const char*>(data);
  while (n > 0) {
    ssize_t w = ::write(fd, p, n);
    if (w < 0 && errno == EINTR) continue;
    if (w <= 0) return false;
    p += w;
    n -= static_cast<std::size_t>(w);
  }
  return true;
}

/// The child: appends forever (until killed), acknowledging each durable seq on `fd`.
[[noreturn]] void childMain(const std::string& dir, int fd, Durability durability,
                            bool snapshots) {
  try {
    SqliteStore store(dir, durability);
    if (!store.loadSession(kSession)) {
      SessionRecord s;
      s.id = kSession;
      s.name = "crash test";
      s.initialScene = json{{"through", 0}};
      s.createdMs = 1;
      store.createSession(s);
    }
    std::int64_t seq = store.lastSeq(kSession);
    std::mt19937 rng(static_cast<unsigned>(getpid()));
    auto edit = [&](std::int64_t n) {
      return json{{"seq", n}, {"pad", std::string(rng() % 3000, 'p')}};
    };
    for (;;) {
      std::int64_t first = seq + 1;
      if (rng() % 4 == 0) {
        std::vector<EditRecord> batch;
        for (unsigned i = 0, n = 1 + rng() % 5; i < n; ++i) {
          batch.push_back(EditRecord{seq + 1, edit(seq + 1), wallClockMs()});
          ++seq;
        }
        store.appendEdits(kSession, batch);
      } else {
        ++seq;
        store.appendEdit(kSession, seq, edit(seq));
      }
      for (std::int64_t s = first; s <= seq; ++s) {  // acknowledged only now
        if (!writeAll(fd, &s, sizeof s)) _exit(4);
      }
      if (snapshots && rng() % 40 == 0) store.saveSnapshot(kSession, seq, json{{"through", seq}});
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "crash child failed: %s\n", e.what());
    _exit(3);
  }
}

struct Trial {
  std::vector<std::int64_t> acked;
};

/// Forks a child, lets it run for `runFor`, SIGKILLs it and returns what it acknowledged. With
/// `fromFirstAck` the time counts from the child's first acknowledgement rather than from the
/// fork, so the kill lands mid-append however long opening the store took on a loaded machine.
Trial runAndKill(const std::string& dir, Durability durability, bool snapshots,
                 std::chrono::microseconds runFor, bool fromFirstAck) {
  int fds[2];
  if (pipe(fds) != 0) throw std::runtime_error("pipe failed");
  pid_t pid = fork();
  if (pid < 0) throw std::runtime_error("fork failed");
  if (pid == 0) {
    close(fds[0]);
    childMain(dir, fds[1], durability, snapshots);
  }
  close(fds[1]);

  std::string bytes;
  char buf[65536];
  auto readAvailable = [&](int timeoutMs) {
    pollfd p{fds[0], POLLIN, 0};
    if (poll(&p, 1, timeoutMs) > 0) {
      ssize_t n = read(fds[0], buf, sizeof buf);
      if (n > 0) bytes.append(buf, static_cast<std::size_t>(n));
      return n != 0;
    }
    return true;
  };
  if (fromFirstAck) {
    // Up to 10 s for the first acknowledgement (16 such trials stay within CTest's 300 s); a
    // child that never gets there fails below.
    auto openDeadline = std::chrono::steady_clock::now() + std::chrono::seconds(10);
    while (bytes.size() < sizeof(std::int64_t) && std::chrono::steady_clock::now() < openDeadline) {
      if (!readAvailable(100)) break;
    }
  }
  auto deadline = std::chrono::steady_clock::now() + runFor;
  while (std::chrono::steady_clock::now() < deadline) {
    auto left = std::chrono::duration_cast<std::chrono::milliseconds>(
        deadline - std::chrono::steady_clock::now());
    if (!readAvailable(static_cast<int>(std::max<std::int64_t>(0, left.count())))) break;
  }
  kill(pid, SIGKILL);
  int status = 0;
  waitpid(pid, &status, 0);
  while (readAvailable(-1)) {  // drain to EOF: acks written before the kill
  }
  close(fds[0]);

  EXPECT_TRUE(WIFSIGNALED(status) && WTERMSIG(status) == SIGKILL)
      << "child ended on its own (exit status " << (WIFEXITED(status) ? WEXITSTATUS(status) : -1)
      << ")";
  Trial t;
  for (std::size_t i = 0; i + sizeof(std::int64_t) <= bytes.size(); i += sizeof(std::int64_t)) {
    std::int64_t s;
    std::memcpy(&s, bytes.data() + i, sizeof s);
    t.acked.push_back(s);
  }
  return t;
}

void runCrashTrials(Durability durabilityA, Durability durabilityB, bool snapshots) {
  CrashTempDir tmp;
  constexpr int kTrials = 24;
  std::mt19937 rng(12345);
  std::int64_t totalAcked = 0, previousLast = 0;
  for (int trial = 0; trial < kTrials; ++trial) {
    // 0–40 ms. Every third trial counts from the fork, so its kill may land in opening, creation
    // or WAL recovery; the others count from the first acknowledgement and kill mid-append.
    std::chrono::microseconds runFor(rng() % 40000);
    Durability durability = trial % 2 ? durabilityB : durabilityA;
    bool fromFirstAck = trial % 3 != 0;
    Trial t = runAndKill(tmp.str(), durability, snapshots, runFor, fromFirstAck);
    if (fromFirstAck) {
      EXPECT_FALSE(t.acked.empty()) << "trial " << trial << ": the child acknowledged nothing";
    }
    totalAcked += static_cast<std::int64_t>(t.acked.size());

    SqliteStore store(tmp.str());
    auto r = store.loadSession(kSession);
    if (t.acked.empty() && !r) continue;  // killed before creating the session
    ASSERT_TRUE(r) << "trial " << trial;

    // Acks arrive in order and continue where the previous trial's log ended.
    for (std::size_t i = 0; i < t.acked.size(); ++i) {
      ASSERT_EQ(t.acked[i], previousLast + 1 + static_cast<std::int64_t>(i)) << "trial " << trial;
    }
    std::int64_t maxAcked = t.acked.empty() ? 0 : t.acked.back();
    ASSERT_GE(r->lastSeq, maxAcked) << "trial " << trial << ": acknowledged edit lost";
    ASSERT_GE(r->lastSeq, previousLast) << "trial " << trial;

    // Contiguous chain: snapshot (if any) then every later seq exactly once, with its payload.
    std::int64_t base = r->snapshot ? r->snapshot->seq : 0;
    if (r->snapshot) {
      ASSERT_EQ(r->snapshot->scene["through"], base);
    }
    std::int64_t expected = base + 1;
    for (const EditRecord& e : r->editsAfterSnapshot) {
      ASSERT_EQ(e.seq, expected) << "trial " << trial << ": gap in the edit log";
      ASSERT_EQ(e.edit["seq"], e.seq);
      ++expected;
    }
    ASSERT_EQ(expected - 1, r->lastSeq) << "trial " << trial;
    // Every acknowledged seq is present: as an edit row, or folded into the snapshot.
    std::set<std::int64_t> present;
    for (const EditRecord& e : r->editsAfterSnapshot) present.insert(e.seq);
    for (std::int64_t s : t.acked) {
      ASSERT_TRUE(s <= base || present.count(s)) << "trial " << trial << ": seq " << s << " lost";
    }
    if (!snapshots) {
      ASSERT_EQ(base, 0);
    }
    previousLast = r->lastSeq;
  }
  // Every trial that waited for an acknowledgement got one (checked above): those kills hit a
  // writing child. Over all trials the children acknowledged this many edits.
  std::printf("%d trials, %lld edits acknowledged\n", kTrials, static_cast<long long>(totalAcked));
}

}  // namespace

TEST(StoreCrash, AcknowledgedEditsSurviveSigkill) {
  runCrashTrials(Durability::Process, Durability::Process, false);
}

TEST(StoreCrash, AcknowledgedEditsSurviveSigkillWithSnapshotsAndBothDurabilities) {
  runCrashTrials(Durability::Process, Durability::Power, true);
}
