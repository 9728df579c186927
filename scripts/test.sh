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
fuzz_build=""
if [ "$FUZZ" != 0 ]; then
  [ -f build-fuzz/build.ninja ] || cmake --preset fuzz >/dev/null
  nice -n 19 cmake --build build-fuzz -j "$JOBS" > build-fuzz/build.log 2>&1 &
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
