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
scripts/setup.sh
echo "test.sh: setup and Release build ${SECONDS} s"
BUILD_DIR="${DEVSURF_BUILD_DIR:-build}"
JOBS="${DEVSURF_JOBS:-$(nproc)}"
ctest --test-dir "$BUILD_DIR" --output-on-failure -j "$JOBS"
echo "test.sh: Release tests done at ${SECONDS} s"
if [ "${DEVSURF_FUZZ_PASS:-1}" != 0 ]; then
  [ -f build-fuzz/build.ninja ] || cmake --preset fuzz >/dev/null
  cmake --build build-fuzz -j "$JOBS"
  echo "test.sh: sanitizer build done at ${SECONDS} s"
  ctest --test-dir build-fuzz --output-on-failure -j "$JOBS"
  echo "test.sh: sanitizer pass done at ${SECONDS} s"
fi
