#!/usr/bin/env bash
# Setup (packages + build), then every test ctest knows.
set -euo pipefail
cd "$(dirname "$0")/.."
tools/setup.sh
BUILD_DIR=${STEWART_BUILD_DIR:-build}
# Tests that start processes over LCM need a multicast route on loopback
# when the machine has none; they use ttl=0 private URLs either way.
if ! ip route get 239.255.76.67 >/dev/null 2>&1; then
  if [[ $(id -u) -eq 0 ]]; then ip route add 224.0.0.0/4 dev lo 2>/dev/null || true; fi
fi
cd "$BUILD_DIR"
ctest --output-on-failure -j "${STEWART_TEST_JOBS:-2}" --timeout 600 "$@"
