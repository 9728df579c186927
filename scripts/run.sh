#!/usr/bin/env bash
# The main job: installs and builds what is stale, then starts the daemon with the demo sessions
# of examples/ on http://localhost:8080 (Ctrl-C or SIGTERM stops it gracefully).
# Environment: DEVSURF_PORT (8080), DEVSURF_BIND (127.0.0.1), DEVSURF_DATA (./var),
#              DEVSURF_API_KEY (unset: anyone may create sessions and jobs).
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/setup.sh
BUILD_DIR="${DEVSURF_BUILD_DIR:-build}"
args=(serve --port "${DEVSURF_PORT:-8080}" --bind "${DEVSURF_BIND:-127.0.0.1}" --data "${DEVSURF_DATA:-./var}")
for scene in examples/*.json; do args+=(--demo "$scene"); done
if [ -d web/dist ]; then args+=(--web web/dist); fi
if [ -n "${DEVSURF_API_KEY:-}" ]; then args+=(--api-key "$DEVSURF_API_KEY"); fi
echo "demo sessions: GET http://localhost:${DEVSURF_PORT:-8080}/api/sessions"
exec "$BUILD_DIR/server/devsurf" "${args[@]}"
