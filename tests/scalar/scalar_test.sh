#!/usr/bin/env bash
# The runtime's scalar path equals its SSE2 path bit for bit: every spec test vector, and the
# shipped clips encoded at two tolerances, sampled every way by both builds (sample_dump.cpp),
# the SSE2 build at every CPU level this machine has (internal/cpu.h: KEYANIM_CPU).
# Usage: scalar_test.sh SIMD_DUMP SCALAR_DUMP KEYANIM REPO_DIR
set -euo pipefail
simd=$1 scalar=$2 keyanim=$3 repo=$4
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
files=("$repo"/spec/test-vectors/*.kanim)
for bvh in "$repo"/data/*.bvh; do
  for e in 0.05% 0.5%; do
    out="$tmp/$(basename "$bvh" .bvh)-${e%\%}.kanim"
    "$keyanim" -q encode "$bvh" -o "$out" --error "$e"
    files+=("$out")
  done
done
levels=(baseline popcnt)
grep -qw popcnt /proc/cpuinfo || levels=(baseline)
if grep -qw avx2 /proc/cpuinfo && grep -qw bmi1 /proc/cpuinfo && grep -qw bmi2 /proc/cpuinfo; then levels+=(v3); fi
for f in "${files[@]}"; do
  "$scalar" "$f" "$tmp/scalar.bin"
  for level in "${levels[@]}"; do
    KEYANIM_CPU=$level "$simd" "$f" "$tmp/simd.bin"
    [ -s "$tmp/simd.bin" ] || { echo "FAIL: nothing sampled from $f"; exit 1; }
    cmp "$tmp/simd.bin" "$tmp/scalar.bin" || { echo "FAIL: $f: SSE2 at level $level samples other bits than scalar"; exit 1; }
  done
  echo "$(basename "$f"): $(stat -c %s "$tmp/simd.bin") bytes of samples, identical at ${levels[*]}"
done
echo "scalar == SSE2 (${levels[*]}) on ${#files[@]} clips"
