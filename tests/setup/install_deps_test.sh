#!/usr/bin/env bash
# scripts/install-deps.sh against stand-ins for apt-get, dpkg-query, id and sudo on a PATH of its
# own: install_deps_test.sh SCRIPT CASE. Checks that nothing is installed when nothing is missing,
# and that each way installing can fail gives keyanim's message and the documented exit code.
set -uo pipefail
SCRIPT=$(realpath "$1"); CASE=$2
T=$(mktemp -d); trap 'rm -rf "$T"' EXIT
die() { echo "FAIL: $*" >&2; [ -f "$T/err" ] && sed 's/^/  stderr: /' "$T/err" >&2; exit 1; }
mkdir "$T/bin"
for tool in mktemp rm grep sed tail sleep cat; do ln -s "$(command -v $tool)" "$T/bin/$tool"; done
# stub NAME BODY: a command on the test's PATH that logs its arguments to calls.log.
stub() { printf '#!%s\necho "%s $*" >>"%s/calls.log"\n%s\n' "$(command -v bash)" "$1" "$T" "$2" >"$T/bin/$1"; chmod +x "$T/bin/$1"; }
# Every package is installed except those listed in $T/absent.
touch "$T/absent"
stub dpkg-query 'grep -qx "${@: -1}" '"$T"'/absent && exit 1; printf "install ok installed"'
stub id 'echo 0'
stub node ':'; stub npm ':'
stub apt-get 'exit 0'
BASH_BIN=$(command -v bash)
run() { PATH="$T/bin" KEYANIM_APT_WAIT=0 "$BASH_BIN" "$SCRIPT" >"$T/out" 2>"$T/err"; echo $?; }
apt_calls() { grep -c '^apt-get' "$T/calls.log" 2>/dev/null || true; }

case "$CASE" in
installed)
  [ "$(run)" = 0 ] || die "exit code"
  [ "$(apt_calls)" = 0 ] || die "apt-get ran although every package is installed"
  grep -q 'already installed' "$T/err" || die "no word that everything is installed"
  ;;
installs)  # root, one package missing: update, then install of exactly that package
  echo help2man >"$T/absent"
  [ "$(run)" = 0 ] || die "exit code"
  grep -q '^apt-get .* update' "$T/calls.log" || die "no apt-get update"
  grep -q '^apt-get .* install .*help2man' "$T/calls.log" || die "help2man not installed"
  grep '^apt-get .* install' "$T/calls.log" | grep -q cmake && die "installed a package that was there"
  ;;
csharp)  # the C# example's compiler and runtime (tests/capi) are among the test packages
  printf 'mono-mcs\nmono-runtime\n' >"$T/absent"
  [ "$(run)" = 0 ] || die "exit code"
  grep -q '^apt-get .* install .*mono-mcs mono-runtime' "$T/calls.log" || die "mono-mcs and mono-runtime not installed"
  ;;
blender)  # the Blender add-on's checks (tests/blender) need Debian's blender
  echo blender >"$T/absent"
  [ "$(run)" = 0 ] || die "exit code"
  grep -q '^apt-get .* install .*blender' "$T/calls.log" || die "blender not installed"
  ;;
sudo)  # not root, sudo available: apt-get through sudo
  echo help2man >"$T/absent"
  stub id 'echo 1000'
  stub sudo '[ "$1" = -v ] || "$@"'
  [ "$(run)" = 0 ] || die "exit code"
  grep -q '^sudo apt-get .* install .*help2man' "$T/calls.log" || die "apt-get not run through sudo"
  ;;
sudo_refused)  # not root, and sudo says no (not in sudoers, or no password given)
  echo help2man >"$T/absent"
  stub id 'echo 1000'
  stub sudo 'echo "user is not in the sudoers file." >&2; exit 1'
  [ "$(run)" = 2 ] || die "exit code, expected 2"
  [ "$(apt_calls)" = 0 ] || die "apt-get ran without root"
  grep -q 'sudo refused' "$T/err" || die "no reason given"
  ;;
no_root)
  echo help2man >"$T/absent"
  stub id 'echo 1000'
  [ "$(run)" = 2 ] || die "exit code, expected 2"
  [ "$(apt_calls)" = 0 ] || die "apt-get ran without root"
  grep -q 'not root and has no sudo' "$T/err" || die "no reason given"
  grep -q 'apt-get install --no-install-recommends help2man' "$T/err" || die "no command to run instead"
  ;;
lock)
  echo help2man >"$T/absent"
  stub apt-get 'echo "E: Could not get lock /var/lib/apt/lists/lock. It is held by process 4242 (apt-get)"; echo "E: Unable to lock directory /var/lib/apt/lists/"; exit 100'
  [ "$(run)" = 3 ] || die "exit code, expected 3"
  grep -q "apt's lock is still held by process 4242 (apt-get)" "$T/err" || die "no reason, or the holder is not named"
  grep -q '^E:' "$T/err" && die "apt's raw message shown"
  ;;
network)  # apt-get update only warns; the install then finds no package
  echo help2man >"$T/absent"
  stub apt-get 'case "$*" in *update*) echo "W: Failed to fetch http://deb.debian.org/debian/dists/bookworm/InRelease  Temporary failure resolving '"'"'deb.debian.org'"'"'"; exit 0;; esac
echo "E: Unable to locate package help2man"; exit 100'
  [ "$(run)" = 4 ] || die "exit code, expected 4"
  grep -q 'could not download packages' "$T/err" || die "no reason given"
  grep -q 'help2man' "$T/err" || die "the missing package is not named"
  ;;
*) die "unknown case $CASE" ;;
esac
echo "ok: $CASE"
