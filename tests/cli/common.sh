# Shared by the CLI test scripts, sourced first as `. common.sh KEYANIM DATA_DIR CASE`: sets K,
# DATA (absolute), CASE, the shipped clips WALK and HOP, makes a scratch directory T removed on
# exit (after the script's own `before_cleanup`, if it defines one) and cd's into it.
K=$(realpath "$1"); DATA=$(realpath "$2"); CASE="$3"
[ -x "$K" ] || { echo "FAIL: $K is not an executable" >&2; exit 1; }
WALK="$DATA/cmu_02_01_walk.bvh"
HOP="$DATA/cmu_131_03_hop.bvh"
T=$(mktemp -d)
cleanup() {
  if declare -F before_cleanup >/dev/null; then before_cleanup; fi
  rm -rf "$T"
}
trap cleanup EXIT
cd "$T" || exit 1

# Failing, and running a command that must exit with a given code.
die() { echo "FAIL: $*" >&2; exit 1; }
expect_rc() {  # expect_rc CODE command...
  local want=$1; shift
  "$@" >"$T/.stdout" 2>"$T/.stderr"; local rc=$?
  [ "$rc" -eq "$want" ] || { cat "$T/.stderr" >&2; die "'$*' exited $rc, expected $want"; }
}
