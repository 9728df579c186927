#!/usr/bin/env bash
# Builds the libFuzzer harnesses (clang, ASan + UBSan, coverage on every library) and runs each for
# SECONDS seconds (default 60) on a corpus seeded with the examples and valid WebSocket messages.
#   scripts/fuzz.sh [SECONDS]          a pass of every harness
#   FUZZ_JOBS=2 scripts/fuzz.sh 3600   the long run (one process per core)
# Crashes are written to build-fuzz/crashes/<harness>/; the script fails if there is one.
set -euo pipefail
cd "$(dirname "$0")/.."
SECONDS_EACH="${1:-60}"
if ! command -v clang++ >/dev/null || ! ls /usr/lib/llvm-*/lib/clang/*/lib/linux/libclang_rt.fuzzer-x86_64.a >/dev/null 2>&1; then
  if [ "$(id -u)" = 0 ]; then
    DEBIAN_FRONTEND=noninteractive apt-get install -y -q clang libclang-rt-dev >/dev/null
  else
    sudo DEBIAN_FRONTEND=noninteractive apt-get install -y -q clang libclang-rt-dev >/dev/null
  fi
fi
cmake --preset fuzz >/dev/null
cmake --build build-fuzz --target fuzz_scene fuzz_ws_message
out=build-fuzz/fuzz-corpus
mkdir -p "$out/scene" "$out/ws" build-fuzz/crashes/fuzz_scene build-fuzz/crashes/fuzz_ws_message
cp examples/*.json "$out/scene/"
i=0
for m in '{"type":"ping","op":1}' \
         '{"type":"drag","op":2,"target":{"curve":"b","index":6},"position":[6,1,0.5]}' \
         '{"type":"drag_end","op":3,"target":{"curve":"b","index":6}}' \
         '{"type":"solve","op":4}' '{"type":"undo"}' '{"type":"redo"}' '{"type":"reset"}' \
         '{"type":"add_handle","op":5,"target":{"curve":"a","index":3},"position":[3,0,0.2],"weight":2}' \
         '{"type":"set_fixed","op":6,"target":{"curve":"a","index":2},"fixed":true}' \
         '{"type":"set_solver","op":7,"solver":{"fairness":0.02,"iterations":5},"drag_iterations":3}' \
         '{"type":"presence","selection":{"curve":"a","index":1},"name":"x"}'; do
  i=$((i + 1)); printf '%s' "$m" > "$out/ws/seed$i.json"
done
status=0
parallel=()
[ "${FUZZ_JOBS:-1}" -gt 1 ] && parallel=(-jobs="$FUZZ_JOBS" -workers="$FUZZ_JOBS")
for h in fuzz_scene fuzz_ws_message; do
  corpus="$out/scene"; [ "$h" = fuzz_ws_message ] && corpus="$out/ws"
  echo "== $h: ${SECONDS_EACH} s"
  if ! build-fuzz/fuzz/$h "$corpus" -max_total_time="$SECONDS_EACH" -max_len=65536 -timeout=20 -rss_limit_mb=4096 \
       "${parallel[@]}" -artifact_prefix="build-fuzz/crashes/$h/" -print_final_stats=1 \
       2> "build-fuzz/$h.log"; then
    status=1
  fi
  grep -E "stat::number_of_executed_units|stat::new_units_added|ERROR|SUMMARY" "build-fuzz/$h.log" | tail -5 || true
done
exit $status
