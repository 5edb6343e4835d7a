#!/usr/bin/env bash
# What `cmake --install` gives a user: install_test.sh BUILD_DIR CASE, with the build tree
# installed into a scratch prefix first.
#   man         share/man/man1/keyanim.1 renders with `man -l` (and `man keyanim` finds it with
#               the prefix's bin/ on PATH), with every command's section and the exit codes
#   completion  share/bash-completion/completions/keyanim, sourced in bash: the completion
#               function offers the commands, a command's options, option values, and file
#               names by type
set -uo pipefail
BUILD=$(realpath "$1"); CASE=$2
T=$(mktemp -d); trap 'rm -rf "$T"' EXIT
die() { echo "FAIL: $*" >&2; exit 1; }
cmake --install "$BUILD" --prefix "$T/prefix" >"$T/install.log" 2>&1 || { cat "$T/install.log"; die "cmake --install"; }
K=$T/prefix/bin/keyanim
[ -x "$K" ] || die "no bin/keyanim installed"

case "$CASE" in
man)
  page=$T/prefix/share/man/man1/keyanim.1
  [ -f "$page" ] || die "no share/man/man1/keyanim.1 installed"
  MANWIDTH=80 man -l "$page" >"$T/page.txt" 2>"$T/man.err" || die "man -l failed: $(cat "$T/man.err")"
  # (A complaint about the locale is the machine's, not the page's.)
  ! grep -v 'locale' "$T/man.err" | grep -q . || die "man -l warned: $(cat "$T/man.err")"
  for section in NAME SYNOPSIS DESCRIPTION COMMANDS; do
    grep -q "^$section" "$T/page.txt" || die "the page has no $section section"
  done
  for c in $("$K" --help | sed -n '/^commands:$/,/^$/s/^  \([a-z][a-z]*\) .*/\1/p'); do
    [ "$c" = help ] || grep -q "^   keyanim $c\$" "$T/page.txt" || die "the page has no section for $c"
  done
  grep -q 'internal error: a bug in keyanim' "$T/page.txt" || die "the page lacks the exit codes"
  grep -q -- '--keys MODE' "$T/page.txt" || die "the page lacks the encoder options"
  # Lines fit the width asked for (the commands' help is reflowed, not kept as printed).
  long=$(awk 'length > 80' "$T/page.txt" | head -n 3)
  [ -z "$long" ] || die "lines wider than 80 columns: $long"
  # man finds it by name: man-db looks in ../share/man beside every bin/ on PATH.
  PATH="$T/prefix/bin:$PATH" MANPATH= man -w keyanim 2>/dev/null | grep -q "^$page" ||
    die "'man keyanim' does not find the page with $T/prefix/bin on PATH"
  ;;
completion)
  script=$T/prefix/share/bash-completion/completions/keyanim
  [ -f "$script" ] || die "no share/bash-completion/completions/keyanim installed"
  mkdir "$T/files" "$T/files/sub" && cd "$T/files" || die "scratch"
  touch walk.bvh HOP.BVH walk.kanim notes.txt
  # complete WORDS...: what the completion offers for the last word, sorted, one line.
  offered() {
    bash -c '. "$1"; shift; COMP_WORDS=("$@"); COMP_CWORD=$(($# - 1)); _keyanim; [ ${#COMPREPLY[@]} -eq 0 ] || printf "%s\n" "${COMPREPLY[@]}" | sort | tr "\n" " "' \
      _ "$script" "$K" "$@"
  }
  expect() {  # expect "OFFERED" WORDS...
    local want=$1; shift
    local got; got=$(offered "$@")
    [ "$got" = "$want" ] || die "keyanim $*<TAB>: offered '$got', expected '$want'"
  }
  contains() {  # contains "A B C" WORDS...: each of A, B, C is offered
    local want=$1; shift
    local got; got=" $(offered "$@")"
    for w in $want; do [[ $got == *" $w "* ]] || die "keyanim $*<TAB>: '$w' not among '$got'"; done
  }
  bash -c '. "$1"; complete -p keyanim' _ "$script" | grep -q '_keyanim' || die "sourcing does not register the completion"
  commands=$("$K" --help | sed -n '/^commands:$/,/^$/s/^  \([a-z][a-z]*\) .*/\1/p' | sort | tr '\n' ' ')
  expect "$commands" ""
  expect "encode eval " e
  expect "$commands" help ""
  expect "encode " -f -q enc
  expect "encode " --max-input 1G enc
  contains "--error --keys --tension --level -j --json -o --output --force --quiet --max-input" encode -
  contains "--fps --inbetweens --frames" decode walk.kanim --
  expect "--against " verify walk.kanim --ag
  expect "curvature error manual: uniform: " encode walk.bvh --keys ""
  expect "fit " encode walk.bvh --tension ""
  expect "" encode walk.bvh --error ""
  # File names by type (any case), directories always.
  expect "HOP.BVH sub walk.bvh " encode ""
  expect "sub walk.kanim " decode ""
  expect "sub walk.kanim " encode walk.bvh -o ""
  expect "HOP.BVH sub walk.bvh walk.kanim " info ""
  expect "HOP.BVH sub walk.bvh " view walk.kanim --against ""
  expect "sub " plot walk.bvh -o ""
  expect "HOP.BVH notes.txt sub walk.bvh walk.kanim " encode --manifest ""   # LIST: any file
  touch r.jsonl
  expect "r.jsonl sub " eval walk.bvh --report ""
  expect "walk.bvh walk.kanim " --max-input 1G info w
  ;;
*) die "unknown case $CASE" ;;
esac
echo "ok: $CASE"
