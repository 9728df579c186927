#!/usr/bin/env bash
# Runs every test: installs and builds what is stale, then CTest (GoogleTest suites, CLI tests,
# end-to-end and browser tests) in the Release tree, then the sanitizer pass: a clang tree with
# AddressSanitizer + UndefinedBehaviorSanitizer and libFuzzer (the `fuzz` preset, build-fuzz/:
# the libraries, the harnesses and the `devsurf` daemon only), whose CTest entries run each
# harness for a short while and the concurrent hostile client against that daemon.
# DEVSURF_FUZZ_PASS=0 skips the sanitizer pass.
set -euo pipefail
cd "$(dirname "$0")/.."
SECONDS=0
BUILD_DIR="${DEVSURF_BUILD_DIR:-build}"
JOBS="${DEVSURF_JOBS:-$(nproc)}"
FUZZ="${DEVSURF_FUZZ_PASS:-1}"
# The packages first; then the sanitizer tree builds at the lowest priority from the start, on the
# CPU the rest leaves idle: npm and Vite (one core), the Release build's links, the Release tests
# waiting on daemons and browsers. It takes nothing from them. Its output goes to
# build-fuzz/build.log.
scripts/setup.sh --packages

# The sanitizer tree's two unity batches with the most source (by bytes: models' and the daemon's
# services', ~100 s and ~90 s of its ~460 CPU-seconds), as ninja targets. Started first, so that
# they are not what is left to compile when the Release tests end: at stop 59 they started last
# and made the run's last 194 s. Prints nothing when the tree has no unity batches.
largest_unity_batches() {
  local dir="$1" unit inc bytes
  for unit in "$dir"/*/CMakeFiles/*.dir/Unity/unity_*_cxx.cxx; do
    [ -f "$unit" ] || continue
    bytes=0
    for inc in $(sed -n 's/^#include "\(.*\)"$/\1/p' "$unit"); do
      [ -f "$inc" ] && bytes=$((bytes + $(stat -c %s "$inc")))
    done
    printf '%s %s.o\n' "$bytes" "${unit#"$dir"/}"
  done | sort -rn | head -n 2 | cut -d' ' -f2
}

fuzz_build=""
if [ "$FUZZ" != 0 ]; then
  [ -f build-fuzz/build.ninja ] || cmake --preset fuzz >/dev/null
  first_units=$(largest_unity_batches build-fuzz || true)
  (
    # shellcheck disable=SC2086  # ninja targets, one word each
    [ -z "$first_units" ] || nice -n 19 cmake --build build-fuzz -j "$JOBS" --target $first_units || true
    nice -n 19 cmake --build build-fuzz -j "$JOBS"
  ) > build-fuzz/build.log 2>&1 &
  fuzz_build=$!
  trap '[ -z "$fuzz_build" ] || kill -- "$fuzz_build" 2>/dev/null || true' EXIT
fi
# No test runs the benchmark programs: not compiled here unless asked (DEVSURF_BENCHES=1).
DEVSURF_BENCHES="${DEVSURF_BENCHES:-0}" scripts/setup.sh
echo "test.sh: setup and Release build ${SECONDS} s"
release=0
ctest --test-dir "$BUILD_DIR" --output-on-failure -j "$JOBS" || release=$?
echo "test.sh: Release tests done at ${SECONDS} s"
if [ "$release" != 0 ]; then
  [ -z "$fuzz_build" ] || kill -- "$fuzz_build" 2>/dev/null || true
  exit "$release"
fi
if [ -n "$fuzz_build" ]; then
  fuzz_status=0
  wait "$fuzz_build" || fuzz_status=$?
  if [ "$fuzz_status" != 0 ]; then
    tail -n 60 build-fuzz/build.log >&2
    echo "test.sh: the sanitizer build failed (build-fuzz/build.log)" >&2
    exit "$fuzz_status"
  fi
  echo "test.sh: sanitizer build done at ${SECONDS} s"
  ctest --test-dir build-fuzz --output-on-failure -j "$JOBS"
  echo "test.sh: sanitizer pass done at ${SECONDS} s"
fi
