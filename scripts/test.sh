#!/usr/bin/env bash
# Runs every test: installs and builds what is stale, then CTest (GoogleTest suites, CLI tests).
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/setup.sh
BUILD_DIR="${DEVSURF_BUILD_DIR:-build}"
ctest --test-dir "$BUILD_DIR" --output-on-failure -j "${DEVSURF_JOBS:-$(nproc)}"
