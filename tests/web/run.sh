#!/usr/bin/env bash
# Browser end-to-end tests of the web app (playwright-core driving Debian's chromium, run by
# node's built-in test runner), and the FOLD/SVG crease-pattern exports read back with FOLD's
# reference library (npm fold) and rasterized by chromium. CTest-friendly: run from anywhere;
# exits 77 when a prerequisite (chromium, the built web app, the daemon) is missing.
#   DEVSURF_BIN  daemon binary   (default build/server/devsurf)
#   DEVSURF_WEB  built web app   (default web/dist)
#   DEVSURF_STEP_PROBE  OpenCascade STEP reader (default build/tests/step_probe)
set -euo pipefail
HERE="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
ROOT="$(cd "$HERE/../.." && pwd)"
BIN="${DEVSURF_BIN:-$ROOT/build/server/devsurf}"
WEB="${DEVSURF_WEB:-$ROOT/web/dist}"
CHROMIUM="${DEVSURF_CHROMIUM:-/usr/bin/chromium}"
STEP_PROBE="${DEVSURF_STEP_PROBE:-$(dirname "$(dirname "$BIN")")/tests/step_probe}"

missing=0
[ -x "$CHROMIUM" ] || { echo "run.sh: $CHROMIUM not found (apt-get install chromium)" >&2; missing=1; }
[ -f "$WEB/index.html" ] || { echo "run.sh: $WEB/index.html not found (build the web app: npm --prefix web ci && npm --prefix web run build)" >&2; missing=1; }
[ -x "$BIN" ] || { echo "run.sh: $BIN not found (build the daemon)" >&2; missing=1; }
[ -x "$STEP_PROBE" ] || { echo "run.sh: $STEP_PROBE not found (build the tests: cmake --build build)" >&2; missing=1; }
command -v node >/dev/null || { echo "run.sh: node not found" >&2; missing=1; }
[ "$missing" = 0 ] || exit 77

if [ ! -d "$HERE/node_modules/playwright-core" ] || [ ! -d "$HERE/node_modules/fold" ] \
    || [ "$HERE/package-lock.json" -nt "$HERE/node_modules" ]; then
  npm ci --prefix "$HERE" --no-audit --no-fund
  touch "$HERE/node_modules"
fi

mkdir -p "$ROOT/test-artifacts/web"
cd "$ROOT"
export DEVSURF_BIN="$BIN" DEVSURF_WEB="$WEB" DEVSURF_CHROMIUM="$CHROMIUM" DEVSURF_STEP_PROBE="$STEP_PROBE"
exec node --test --test-concurrency=1 tests/web/
