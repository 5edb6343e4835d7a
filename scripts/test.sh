#!/usr/bin/env bash
# The whole test suite: build, then every test through CTest. Corpus tests use ../shared/corpus
# when it exists beside the checkout and are skipped (with a message) otherwise. Then the same
# suite under ASan + UBSan and a short run of every fuzz target (scripts/sanitize.sh; set
# KEYANIM_SKIP_SANITIZE=1 to leave that out locally).
set -euo pipefail
cd "$(dirname "$0")/.."
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build build -j"$(nproc)"
ctest --test-dir build -j"$(nproc)" --output-on-failure
if [ ! -d ../shared/corpus ]; then
  echo "keyanim: ../shared/corpus not found beside the checkout: the corpus tests listed as Skipped above did not run"
fi
if [ "${KEYANIM_SKIP_SANITIZE:-0}" != 1 ]; then
  scripts/sanitize.sh
fi
