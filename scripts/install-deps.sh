#!/usr/bin/env bash
# Installs what keyanim needs to build and test, from Debian/Ubuntu packages. Does nothing (and
# needs no root) when everything is already there; otherwise runs apt-get as root, or through
# sudo. When it cannot install, it says what to run instead and exits with:
#   0  everything is installed
#   1  apt-get failed for another reason (its last lines are shown)
#   2  packages are missing and this user cannot install them (not root, no sudo)
#   3  another package manager holds apt's lock (waited KEYANIM_APT_WAIT seconds, default 120)
#   4  packages could not be downloaded (no network, or the package sources are unreachable)
set -uo pipefail
WAIT=${KEYANIM_APT_WAIT:-120}
AGAIN=${KEYANIM_AGAIN:-scripts/install-deps.sh}  # what the user ran (quickstart.sh sets it)
say() { echo "keyanim: $*" >&2; }

# Debian packages, each group with why it is needed. A group's line is all a change needs.
REQUIRED=(
  g++ cmake make pkg-config libzstd-dev zlib1g-dev nlohmann-json3-dev  # the library and the tool
  doctest-dev python3                                                 # the test suite
  help2man man-db                                                     # the man page, and its test
  git                                                                 # the newcomer test's clone
  ccache           # scripts/configure.sh: the test builds reuse what the set-up compiled
  bash-completion  # tab completion of the installed tool (tools/completion/keyanim)
  parallel procps  # tests/cli/manifest_test.sh runs the README's GNU parallel recipe (and kills it)
  libxxhash-dev python3-xxhash  # the runtime profile's checksum, XXH64 (spec/FORMAT.md section 9)
  zstd             # the zstd program trains and applies bank dictionaries: python/tests/test_reference_bank.py, viewer/test/zstd.test.mjs
  locales          # python/tests/test_hostile.py compiles de_DE.UTF-8 (localedef) into its own directory
  # The Python module (python/): pybind11 and numpy from Debian (no pip), pytest for its tests,
  # matplotlib for examples/plot_channel.py.
  python3-dev pybind11-dev python3-pybind11 python3-numpy python3-pytest python3-matplotlib
  mono-mcs mono-runtime  # tests/capi: the C API from C# (examples/csharp/), compiled by mcs, run by mono
)
# For scripts/sanitize.sh's fuzz step and the clang build of the tests: clang with libFuzzer.
# The runtime's package name differs (Debian 12: libclang-rt-14-dev; Ubuntu 24.04:
# libclang-rt-dev); without it, no fuzzing.
FUZZ=(clang)
FUZZ_RT=(libclang-rt-14-dev libclang-rt-dev)
# The browser viewer (viewer/): node and npm build it (any source of node >= 18 will do: checked
# as commands), chromium runs its browser tests (driven by puppeteer-core, which never downloads
# a browser). viewer/test/zstd.test.mjs also uses the zstd program, which REQUIRED installs.
VIEWER=(chromium)
# Debian's blender 3.4, whose Python is the system's 3.11, so it loads the module built for
# /usr/bin/python3: the add-on's checks (tools/blender/, tests/blender) and the glTF export's
# import into one armature and action (CTest gltf_blender, gltf_blender_corpus) run headless in
# it; without it those tests are skipped (77). Large (765 MB with its libraries on Debian 12).
BLENDER=(blender)

installed() { [ "$(dpkg-query -W -f='${Status}' "$1" 2>/dev/null)" = "install ok installed" ]; }

missing=()
for p in "${REQUIRED[@]}" "${FUZZ[@]}" "${VIEWER[@]}" "${BLENDER[@]}"; do installed "$p" || missing+=("$p"); done
fuzz_rt=""
for p in "${FUZZ_RT[@]}"; do installed "$p" && fuzz_rt=$p; done
if { ! command -v node || ! command -v npm; } >/dev/null 2>&1; then missing+=(nodejs npm); fi
if [ ${#missing[@]} -eq 0 ] && [ -n "$fuzz_rt" ]; then
  say "build and test dependencies already installed"
  exit 0
fi

# What a user who cannot install should run.
[ -z "$fuzz_rt" ] && missing+=("${FUZZ_RT[0]}")
command_line="apt-get update && apt-get install --no-install-recommends ${missing[*]}"
SUDO=()
if [ "$(id -u)" -ne 0 ]; then
  why="this user is not root and has no sudo"
  if command -v sudo >/dev/null 2>&1; then
    say "missing packages: ${missing[*]}: installing them with sudo (it may ask for your password)"
    sudo -v && why=""
    [ -z "$why" ] || why="this user is not root and sudo refused"
  fi
  if [ -n "$why" ]; then
    say "missing packages: ${missing[*]}"
    say "installing them needs root, and $why. As root, run:"
    echo "  $command_line" >&2
    say "then run $AGAIN again (it installs nothing when everything is there)."
    exit 2
  fi
  SUDO=(sudo)
fi
[ ${#SUDO[@]} -gt 0 ] || say "installing ${missing[*]}"

log=$(mktemp)
trap 'rm -f "$log"' EXIT
export DEBIAN_FRONTEND=noninteractive
network_pattern='Temporary failure resolving|Could not resolve|Failed to fetch|Could not connect|Unable to connect|Network is unreachable|Connection timed out|Connection failed'
# apt ARGS...: apt-get with its output in $log; on failure, says why in keyanim's words and exits
# with the code above. dpkg's lock is waited for by apt itself (DPkg::Lock::Timeout); the lock of
# `apt-get update` is not, so it is retried here.
apt() {
  local start=$SECONDS told=0
  while :; do
    "${SUDO[@]}" apt-get -o DPkg::Lock::Timeout="$WAIT" "$@" >"$log" 2>&1 && return 0
    local rc=$?
    if grep -q 'Could not get lock\|Unable to lock\|Unable to acquire the dpkg frontend lock' "$log"; then
      if [ $((SECONDS - start)) -lt "$WAIT" ]; then
        [ $told = 1 ] || say "another package manager holds apt's lock; waiting up to ${WAIT} s for it"
        told=1
        sleep 5
        continue
      fi
      local holder
      holder=$(grep -om1 'held by process [0-9]* ([^)]*)' "$log")
      say "apt's lock is still ${holder:-held by another package manager} after ${WAIT} s."
      say "wait until it has finished (e.g. unattended-upgrades), then run $AGAIN again."
      exit 3
    fi
    if grep -Eq "$network_pattern" "$log" || { [ -n "$update_warning" ] && grep -q 'Unable to locate package\|has no installation candidate' "$log"; }; then
      say "could not download packages: no network, or the package sources are unreachable:"
      { grep -Em2 "$network_pattern" "$log" || echo "$update_warning"; } | sed 's/^/  /' >&2
      say "connect to the network (or fix /etc/apt/sources.list), then run $AGAIN again;"
      say "or install these packages another way: ${missing[*]}"
      exit 4
    fi
    say "apt-get $* failed (exit $rc):"
    tail -n 15 "$log" | sed 's/^/  /' >&2
    say "to install by hand: $command_line"
    exit 1
  done
}

# `apt-get update` may only warn when the network is down: remember it for the install's error.
update_warning=""
apt update -qq
update_warning=$(grep -Em2 "$network_pattern" "$log")
required=()
for p in "${missing[@]}"; do [[ " ${FUZZ_RT[*]} " == *" $p "* ]] || required+=("$p"); done
[ ${#required[@]} -eq 0 ] || apt install -y -qq --no-install-recommends "${required[@]}"
if [ -z "$fuzz_rt" ]; then
  for p in "${FUZZ_RT[@]}"; do
    if "${SUDO[@]}" apt-get -o DPkg::Lock::Timeout="$WAIT" install -y -qq --no-install-recommends "$p" >"$log" 2>&1; then
      fuzz_rt=$p
      break
    fi
  done
  [ -n "$fuzz_rt" ] || say "libFuzzer's runtime (${FUZZ_RT[*]}) is not available: scripts/sanitize.sh will not fuzz"
fi
say "build and test dependencies installed"
