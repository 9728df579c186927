#!/usr/bin/env bash
# Installs what devsurf needs on Debian 12 (idempotent) and builds what is stale.
# Usage: scripts/setup.sh            (dependencies + Release build in ./build)
#        scripts/setup.sh --packages (the Debian packages only)
# Environment: DEVSURF_BUILD_DIR (default build), DEVSURF_JOBS (default: number of cores).
set -euo pipefail
cd "$(dirname "$0")/.."

APT_PACKAGES=(
  build-essential cmake ninja-build pkg-config
  libeigen3-dev nlohmann-json3-dev libspdlog-dev libopenmesh-dev
  libgtest-dev libgmock-dev libbenchmark-dev
  libcpp-httplib-dev libboost-dev libsqlite3-dev libsuitesparse-dev
  libocct-data-exchange-dev libtbb-dev liblbfgs-dev libssl-dev libcgal-dev libnanoflann-dev libcgal-demo
  libopenblas0-pthread libpq-dev postgresql haproxy libdxflib-dev libpugixml-dev libpng-dev libbrotli-dev zlib1g-dev
  python3 python3-websockets python3-ezdxf
  clang libclang-rt-dev
  chromium fonts-liberation fonts-dejavu-core
)

# Node.js and npm for the web app: the machine image has Node 20; Debian's otherwise.
command -v npm >/dev/null 2>&1 || APT_PACKAGES+=(nodejs npm)

SUDO=""
if [ "$(id -u)" -ne 0 ]; then SUDO="sudo"; fi
missing=()
for p in "${APT_PACKAGES[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if ((${#missing[@]})); then
  echo "setup: installing ${missing[*]}"
  export DEBIAN_FRONTEND=noninteractive
  $SUDO apt-get update -q
  $SUDO apt-get install -y -q --no-install-recommends "${missing[@]}"
fi
# The BLAS under CHOLMOD: OpenBLAS's pthreads build, which locks its shared buffers (the engine
# tells it to run each call on the calling thread). A serial OpenBLAS has no locks: two sessions
# factorizing at once corrupted each other's results. Switch away from one left selected.
MULTIARCH="$(gcc -print-multiarch 2>/dev/null || echo x86_64-linux-gnu)"
for lib in libblas.so.3 liblapack.so.3 libopenblas.so.0; do
  target="/usr/lib/$MULTIARCH/openblas-pthread/$lib"
  link="/etc/alternatives/$lib-$MULTIARCH"
  if [ -e "$target" ] && [ "$(readlink -f "$link")" != "$(readlink -f "$target")" ]; then
    $SUDO update-alternatives --quiet --set "$lib-$MULTIARCH" "$target"
  fi
done
if [ "${1:-}" = "--packages" ]; then exit 0; fi

# The web app: npm packages when the lock file changed, a Vite build when a source is newer.
if [ -f web/package.json ]; then
  if [ ! -d web/node_modules ] || [ web/package-lock.json -nt web/node_modules/.package-lock.json ]; then
    (cd web && npm ci --no-audit --no-fund)
  fi
  if [ ! -f web/dist/index.html ] || [ -n "$(find web/src web/index.html web/vite.config.js web/package.json examples \
        -newer web/dist/index.html -print -quit 2>/dev/null)" ]; then
    (cd web && npm run build)
  fi
fi

BUILD_DIR="${DEVSURF_BUILD_DIR:-build}"
JOBS="${DEVSURF_JOBS:-$(nproc)}"
if [ ! -f "$BUILD_DIR/build.ninja" ]; then
  cmake -S . -B "$BUILD_DIR" -G Ninja -DCMAKE_BUILD_TYPE=Release
fi
# Ninja rebuilds only what is stale (and re-runs CMake when a CMakeLists or globbed folder changed).
cmake --build "$BUILD_DIR" -j "$JOBS"
# The Google Benchmark programs (bench/), unless DEVSURF_BENCHES=0 (scripts/test.sh: no test runs
# them).
if [ "${DEVSURF_BENCHES:-1}" != 0 ] && grep -q "^build benches:" "$BUILD_DIR/build.ninja"; then
  cmake --build "$BUILD_DIR" -j "$JOBS" --target benches
fi
