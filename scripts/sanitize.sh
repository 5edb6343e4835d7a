#!/usr/bin/env bash
# The test suite under AddressSanitizer + UndefinedBehaviorSanitizer, then a short bounded run of
# every fuzz target (fuzz/README.md) from its committed corpus. One build, build-asan: with clang
# and libFuzzer it holds the tests and the fuzz targets; without them, a GCC build of the tests
# only (the fuzz step is then skipped, with a message).
#
# Environment:
#   KEYANIM_FUZZ_SECONDS   seconds per fuzz target (default 30; 0 skips fuzzing)
#   KEYANIM_ASAN_EXCLUDE   ctest -E regex of tests left out of the sanitizer run (default: the glTF
#                          exports of the whole corpus and Blender, about 390 s under ASan, and the
#                          checks that docs/figures.md and the README's glTF table match the corpus,
#                          about 90 s, and the two 65,535- and 8,000-joint chain exports (a
#                          complexity guard with a 90 s timeout, which -O1 and ASan would blur;
#                          gltf_deep runs the same fit on a 300-joint chain), whose library code the glTF unit, CLI, fixture and corpus
#                          round-trip tests already run; the
#                          heaviest left is the codec round trip of the whole shared corpus, about
#                          80 s under ASan: "round-trips through .kanim"; set it empty to run all).
#                          Also left out: cli_bank_corpus (100 s: the whole corpus packed by the
#                          CLI, whose bank writer and reader the codec round trip runs over the
#                          same clips, and bank_test and cli_bank_* on damaged and small banks)
#                          cli_manifest_parallel (56 s: GNU parallel's recipe killed and
#                          resumed, around the encode that cli_manifest and cli_bank_manifest run)
#                          and cli_progress (58 s: progress on a pseudo-terminal while a clip
#                          encodes; the encoder's progress calls run in progress_test.cpp here)
# A fuzz finding fails the script; the input is kept in build-asan/findings/<target>/ (see
# fuzz/README.md for turning it into a committed seed).
set -euo pipefail
cd "$(dirname "$0")/.."
JOBS=$(nproc)
FUZZ_SECONDS=${KEYANIM_FUZZ_SECONDS:-30}
EXCLUDE=${KEYANIM_ASAN_EXCLUDE-^(gltf_(corpus|blender)|docs_figures_corpus|readme_gltf_table_corpus|cli_hostile_gltf_(depth|rounds)|cli_bank_corpus|cli_manifest_parallel|cli_progress)}
B=build-asan

CXX_FOR_ASAN=g++
CC_FOR_ASAN=gcc  # the C API's C programs (examples/c, tests/capi): the same compiler family
FUZZ=OFF
if command -v clang++ >/dev/null &&
   echo 'extern "C" int LLVMFuzzerTestOneInput(const char*, unsigned long) { return 0; }' |
     clang++ -x c++ -fsanitize=fuzzer,address,undefined - -o /dev/null 2>/dev/null; then
  CXX_FOR_ASAN=clang++
  CC_FOR_ASAN=clang
  FUZZ=ON
else
  echo "sanitize: clang++ with libFuzzer not found (install clang and libclang-rt-14-dev): GCC, no fuzzing"
fi
# A build directory made with the other compiler cannot be reconfigured: start it anew. (The
# compiler is noted in a file of ours: a -D variable the project does not use makes CMake warn.)
if [ -f "$B/CMakeCache.txt" ] && [ "$(cat "$B/keyanim-compiler" 2>/dev/null)" != "$CXX_FOR_ASAN" ]; then
  rm -rf "$B"
fi

start=$(date +%s)
# -O1: fast enough to run everything, while keeping stack traces readable.
# With clang, this is also the build that keeps clang's warnings out of the library, the tools and
# the tests (KEYANIM_WERROR, as build/ does for GCC).
scripts/configure.sh "$B" -DCMAKE_CXX_COMPILER="$CXX_FOR_ASAN" -DCMAKE_C_COMPILER="$CC_FOR_ASAN" \
  -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O1 -g" \
  -DKEYANIM_SANITIZE=address,undefined -DKEYANIM_BUILD_FUZZ=$FUZZ -DKEYANIM_BUILD_BENCH=OFF \
  -DKEYANIM_BUILD_VIEWER=OFF -DKEYANIM_BUILD_PYTHON=OFF  # JavaScript and Python: tested in build/
# (No benchmarks: no test runs them, and compiling them here took about 2 minutes; build/
# compiles them with GCC's warnings as errors.)
echo "$CXX_FOR_ASAN" >"$B/keyanim-compiler"
cmake --build "$B" -j"$JOBS"
echo "sanitize: build took $(( $(date +%s) - start )) s"
start=$(date +%s)
export ASAN_OPTIONS=${ASAN_OPTIONS:-detect_leaks=1:abort_on_error=1}
export UBSAN_OPTIONS=${UBSAN_OPTIONS:-print_stacktrace=1:halt_on_error=1}
ctest --test-dir "$B" -j"$JOBS" --output-on-failure ${EXCLUDE:+-E "$EXCLUDE"}
echo "sanitize: test suite under ASan+UBSan took $(( $(date +%s) - start )) s"

if [ "$FUZZ" = OFF ] || [ "$FUZZ_SECONDS" -le 0 ]; then
  echo "sanitize: no fuzzing"
  exit 0
fi
start=$(date +%s)
# fuzz TARGET: FUZZ_SECONDS of libFuzzer on a scratch copy of the corpus (the committed seeds
# stay as they are); prints the final status line.
fuzz() {
  local t=$1 work=$B/fuzz-work/$1 found=$B/findings/$1 log=$B/fuzz_$1.log
  rm -rf "$work"; mkdir -p "$work" "$found"
  cp fuzz/corpus/"$t"/* "$work"/
  [ "$t" != c_api ] || cp fuzz/corpus/sample/* "$work"/  # fuzz_c_api reads fuzz_sample's inputs too
  local dict=()
  case $t in bvh|roundtrip) dict=(-dict=fuzz/bvh.dict) ;; esac
  # A fixed seed keeps CI reproducible; long exploratory runs are local (fuzz/README.md).
  if ! "$B"/fuzz/fuzz_"$t" "$work" "${dict[@]}" -seed=1 -max_total_time="$FUZZ_SECONDS" -rss_limit_mb=2048 \
       -malloc_limit_mb=1024 -timeout=20 -max_len=65536 -artifact_prefix="$found"/ >"$log" 2>&1; then
    tail -n 40 "$log"
    echo "sanitize: fuzz_$t FOUND A PROBLEM; input kept in $found/"
    return 1
  fi
  echo "sanitize: fuzz_$t: $(grep -E '^#[0-9]+' "$log" | tail -n 1)"
}
# Rounds of one target per core, but for the first: fuzz_bank joins the two lightest targets
# (small inputs, cheap runs), three on two cores, so that it adds no time to the rounds.
status=0
for round in "bvh load bank" "sample roundtrip" "c_api view"; do
  pids=()
  for t in $round; do fuzz "$t" & pids+=($!); done
  for p in "${pids[@]}"; do wait "$p" || status=1; done
done
echo "sanitize: fuzzing took $(( $(date +%s) - start )) s"
exit $status
