#!/usr/bin/env bash
# Installs what keyanim needs to build and test, from Debian/Ubuntu packages.
set -euo pipefail
SUDO=""
if [ "$(id -u)" -ne 0 ]; then SUDO="sudo"; fi
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -qq
$SUDO apt-get install -y -qq --no-install-recommends \
  g++ cmake make pkg-config libzstd-dev zlib1g-dev nlohmann-json3-dev doctest-dev >/dev/null
echo "keyanim: build dependencies installed"
