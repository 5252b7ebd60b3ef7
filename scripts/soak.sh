#!/usr/bin/env bash
# The soak test for longer than the test command's minute: sessions ending at random points
# (finished, cancelled, abandoned, with a bad frame) against a real server; every session freed
# and the server's resident memory flat. Needs a build with tests (scripts/build.sh
# -DNIDEVO_BUILD_TESTS=ON). Usage: scripts/soak.sh [SECONDS (default 600)]
set -euo pipefail
cd "$(dirname "$0")/.."
seconds="${1:-600}"
case "$seconds" in '' | *[!0-9]*) echo "soak.sh: SECONDS must be a whole number, got '$seconds'" >&2; exit 2 ;; esac
[ -x build/bin/nidevo_integration_tests ] || { echo "soak.sh: build the tests first" >&2; exit 2; }
NIDEVO_SOAK_SECONDS="$seconds" build/bin/nidevo_integration_tests --gtest_filter='Soak.*'
