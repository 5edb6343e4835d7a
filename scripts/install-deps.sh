#!/usr/bin/env bash
# Installs what keyanim needs to build and test, from Debian/Ubuntu packages.
set -euo pipefail
SUDO=""
if [ "$(id -u)" -ne 0 ]; then SUDO="sudo"; fi
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -qq
$SUDO apt-get install -y -qq --no-install-recommends \
  g++ cmake make pkg-config libzstd-dev zlib1g-dev nlohmann-json3-dev doctest-dev python3 >/dev/null
# GNU parallel: the batch-conversion test (tests/cli/manifest_test.sh) runs the README's recipe
# (and kills it midway: ps lists the processes).
$SUDO apt-get install -y -qq --no-install-recommends parallel procps >/dev/null
# For scripts/sanitize.sh's fuzz step: clang with libFuzzer (optional; skipped if unavailable).
$SUDO apt-get install -y -qq --no-install-recommends clang libclang-rt-14-dev >/dev/null 2>&1 ||
  $SUDO apt-get install -y -qq --no-install-recommends clang libclang-rt-dev >/dev/null 2>&1 ||
  echo "keyanim: clang/libFuzzer not installed; the fuzz step of scripts/sanitize.sh will be skipped"
# For the browser viewer (viewer/): node and npm to build it, chromium for its browser tests
# (driven by puppeteer-core from npm, which never downloads a browser of its own). A machine
# that already has node and npm (e.g. from another package source) keeps them.
if ! command -v node >/dev/null || ! command -v npm >/dev/null; then
  $SUDO apt-get install -y -qq --no-install-recommends nodejs npm >/dev/null
fi
$SUDO apt-get install -y -qq --no-install-recommends chromium >/dev/null
echo "keyanim: build dependencies installed"
