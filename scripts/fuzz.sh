#!/usr/bin/env bash
# Builds the `fuzz` preset (clang, ASan + UBSan, libFuzzer; build-fuzz/: the libraries with coverage,
# the harnesses and the devsurf daemon) and runs the fuzzers and the concurrent hostile client.
#   scripts/fuzz.sh [SECONDS]      every harness for SECONDS (default 60), as CI's pass does
#   scripts/fuzz.sh long           the long run: every harness to 10^6 executions, then the hostile
#                                  client for 20 000 messages against the ASan daemon
#   scripts/fuzz.sh client [N]     the hostile client alone, N messages (default 2000)
# Environment: FUZZ_RUNS (executions per harness in the long run, default 1000000), FUZZ_JOBS
# (fuzzing processes per harness, default 1; 2 only when nothing else needs the cores),
# HOSTILE_MESSAGES (default 20000), HOSTILE_SEED (default 1).
# Crash inputs go to build-fuzz/crashes/<harness>/; a crash, a sanitizer report or a client
# finding fails the script. Repeat a crash: build-fuzz/fuzz/<harness> build-fuzz/crashes/<harness>/crash-…
set -euo pipefail
cd "$(dirname "$0")/.."
mode="${1:-60}"
if ! command -v clang++ >/dev/null || ! ls /usr/lib/llvm-*/lib/clang/*/lib/linux/libclang_rt.fuzzer-x86_64.a >/dev/null 2>&1; then
  scripts/setup.sh  # clang and libclang-rt-dev are in its package list
fi
[ -f build-fuzz/build.ninja ] || cmake --preset fuzz >/dev/null
cmake --build build-fuzz -j "${DEVSURF_JOBS:-$(nproc)}"

client() {
  /usr/bin/python3 tests/server/e2e/hostile_client.py --bin build-fuzz/server/devsurf --seed "${HOSTILE_SEED:-1}" \
    --messages "$1" --seconds "${HOSTILE_SECONDS:-14400}" --keep
}

status=0
case "$mode" in
  long)
    for h in fuzz_scene fuzz_ws_message; do
      echo "== $h: ${FUZZ_RUNS:-1000000} executions"
      fuzz/run_harness.sh build-fuzz "$h" 0 "${FUZZ_RUNS:-1000000}" "${FUZZ_JOBS:-1}" || status=1
    done
    echo "== hostile client: ${HOSTILE_MESSAGES:-20000} messages"
    client "${HOSTILE_MESSAGES:-20000}" || status=1
    ;;
  client)
    client "${2:-2000}" || status=1
    ;;
  *)
    for h in fuzz_scene fuzz_ws_message; do
      echo "== $h: $mode s"
      fuzz/run_harness.sh build-fuzz "$h" "$mode" 0 "${FUZZ_JOBS:-1}" || status=1
    done
    ;;
esac
exit $status
