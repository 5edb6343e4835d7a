#!/usr/bin/env bash
# The whole test suite: build (warnings are errors: scripts/configure.sh), then every test through
# CTest. Corpus tests use ../shared/corpus when it exists beside the checkout and are reported as
# skipped, with the reason, otherwise. Then the same suite under ASan + UBSan, built with clang
# (whose warnings are errors too), and a short run of every fuzz target (scripts/sanitize.sh;
# KEYANIM_SKIP_SANITIZE=1 leaves that out: the quick variant).
set -euo pipefail
cd "$(dirname "$0")/.."
# ccache (scripts/configure.sh) names sources relative to the checkout, so that two clones (CI's,
# then scripts/newcomer.sh's fresh one) share what the first compiled.
export CCACHE_BASEDIR=$PWD
start=$SECONDS
scripts/configure.sh build -DCMAKE_BUILD_TYPE=Release -DKEYANIM_BUILD_TESTS=ON -DKEYANIM_BUILD_BENCH=ON
cmake --build build -j"$(nproc)"
# build/ctest-results.xml: each test's status and output (JUnit). A test that passed without
# checking anything (a doctest name CTest cut at a ';', a skip reported as a pass) fails the run.
ctest --test-dir build -j"$(nproc)" --output-on-failure --output-junit ctest-results.xml
python3 tests/ctest_report.py build/ctest-results.xml
if [ ! -d ../shared/corpus ]; then
  echo "keyanim: ../shared/corpus not found beside the checkout: the corpus tests listed as Skipped above did not run"
fi
echo "keyanim: build and tests took $((SECONDS - start)) s"
if [ "${KEYANIM_SKIP_SANITIZE:-0}" != 1 ]; then
  scripts/sanitize.sh
  echo "keyanim: scripts/test.sh took $((SECONDS - start)) s in all"
fi
