#!/usr/bin/env bash
# Installs every Debian 12 package the project needs (idempotent,
# non-interactive; run as root as on CI, or with sudo available), then
# configures and builds into build/. Re-running on a built tree is fast:
# apt is skipped when every package is present, ninja rebuilds nothing.
set -euo pipefail
cd "$(dirname "$0")/.."

PACKAGES=(
  build-essential cmake ninja-build pkg-config git
  libeigen3-dev libyaml-cpp-dev libspdlog-dev libcli11-dev nlohmann-json3-dev
  libgtest-dev libgmock-dev libbenchmark-dev
  libsundials-dev
  liblcm-dev liblcm-bin liblcm-java libjchart2d-java default-jre-headless default-jdk-headless
  coinor-libclp-dev libalglib-dev
  python3-matplotlib python3-numpy python3-pandas python3-pil python3-yaml
  xvfb xauth x11-utils imagemagick
  libssl-dev
  iproute2 procps iptables
  parallel
  # stewart_viewer: the web server, three.js for the page, and the browser
  # its test drives (docs/operations.md, "The viewer").
  libcivetweb-dev libjs-three chromium
)
# node and npm drive that browser in the test (puppeteer-core); any node >= 18
# will do, so an existing one (e.g. from NodeSource) is kept.
if ! command -v node >/dev/null || ! command -v npm >/dev/null; then PACKAGES+=(nodejs npm); fi

missing=()
for pkg in "${PACKAGES[@]}"; do
  dpkg-query -W -f='${Status}' "$pkg" 2>/dev/null | grep -q "install ok installed" || missing+=("$pkg")
done
if ((${#missing[@]})); then
  echo "setup: installing ${missing[*]}"
  SUDO=""
  if [[ $(id -u) -ne 0 ]]; then SUDO="sudo"; fi
  export DEBIAN_FRONTEND=noninteractive
  $SUDO apt-get update -qq
  $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
fi

# The browser test's client, exactly as pinned in its package-lock.json
# (nothing is fetched at build or test time).
BROWSER_TEST=tests/viewer/browser
if [[ ! -f $BROWSER_TEST/node_modules/.package-lock.json ||
      $BROWSER_TEST/package-lock.json -nt $BROWSER_TEST/node_modules/.package-lock.json ]]; then
  echo "setup: npm ci in $BROWSER_TEST"
  (cd "$BROWSER_TEST" && npm ci --no-audit --no-fund --loglevel=error >/dev/null)
fi

BUILD_DIR=${STEWART_BUILD_DIR:-build}
JOBS=${STEWART_JOBS:-$(nproc)}
if [[ ! -f "$BUILD_DIR/build.ninja" ]]; then
  cmake -S . -B "$BUILD_DIR" -G Ninja -DCMAKE_BUILD_TYPE=Release >/dev/null
fi
cmake --build "$BUILD_DIR" -j "$JOBS"
