#!/usr/bin/env bash
# First run for a new user: install dependencies, build, and put a real CMU walk through the
# whole loop (BVH -> .kanim -> BVH), printing size and error.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/install-deps.sh
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build build -j"$(nproc)" --target keyanim-cli
mkdir -p out
K=build/tools/keyanim
$K info data/cmu_02_01_walk.bvh
$K encode -f data/cmu_02_01_walk.bvh -o out/walk.kanim
$K decode -f out/walk.kanim -o out/walk.bvh
$K info out/walk.kanim
