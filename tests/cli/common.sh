# Shared by the CLI test scripts (sourced after K, CASE and T are set and the script has cd'd
# into T): failing, and running a command that must exit with a given code.
die() { echo "FAIL: $*" >&2; exit 1; }
expect_rc() {  # expect_rc CODE command...
  local want=$1; shift
  "$@" >"$T/.stdout" 2>"$T/.stderr"; local rc=$?
  [ "$rc" -eq "$want" ] || { cat "$T/.stderr" >&2; die "'$*' exited $rc, expected $want"; }
}
