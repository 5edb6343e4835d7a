#!/usr/bin/env bash
# configure.sh BUILD_DIR [cmake options...]: configures a build tree the way scripts/test.sh and
# scripts/sanitize.sh (so CI) do: compiler warnings are errors (KEYANIM_WERROR), and so is any
# warning CMake prints; ccache is used when it is installed. Quiet unless something is wrong.
set -euo pipefail
cd "$(dirname "$0")/.."
B=$1; shift
launcher=()
if command -v ccache >/dev/null; then launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache); fi
log=$(mktemp)
trap 'rm -f "$log"' EXIT
if ! cmake -S . -B "$B" -DKEYANIM_WERROR=ON "${launcher[@]}" "$@" >"$log" 2>&1; then
  cat "$log" >&2
  exit 1
fi
if grep -q '^CMake [A-Za-z ]*Warning' "$log"; then
  cat "$log" >&2
  echo "configure: CMake warned (above); warnings are errors here" >&2
  exit 1
fi
