#!/usr/bin/env bash
# The main job. Until the daemon lands (issue 3) it installs, builds and solves the demo scenes
# in examples/, printing a summary line and the full report of each.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/setup.sh
BUILD_DIR="${DEVSURF_BUILD_DIR:-build}"
mkdir -p "$BUILD_DIR/reports"
for scene in examples/*.json; do
  name="$(basename "$scene" .json)"
  report="$BUILD_DIR/reports/$name.report.json"
  "$BUILD_DIR/server/devsurf" solve "$scene" --out "$report" --export "obj:$BUILD_DIR/reports/$name.obj"
  python3 - "$scene" "$report" <<'PY'
import json, sys
r = json.load(open(sys.argv[2]))
m = r["metrics"]
print(f"{sys.argv[1]}: {r['iterations']} iterations, {r['termination']}, {r['time_ms']:.1f} ms, "
      f"warp max {m['warp_angle_max_deg']:.2e} deg, mean {m['warp_angle_mean_deg']:.2e} deg, "
      f"developability residual {m['developability_residual_max']:.1e}")
PY
done
echo "reports and OBJ surfaces in $BUILD_DIR/reports/"
