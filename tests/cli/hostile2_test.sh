#!/usr/bin/env bash
# What a careless or hostile user does, round 2 (issue 23), through the real binary, one case
# per class of failure: hostile2_test.sh KEYANIM DATA_DIR CASE
#   outputs     an output that destroys something or lands where the user did not say: reports
#               that are inputs, manifest collisions, devices and links as outputs, symlinked
#               inputs in a directory run
#   lost_work   success reported for work that was lost: a full standard output, SIGXFSZ and
#               SIGQUIT
#   endless     reads that never end: FIFOs and /dev/zero where a command reads back
#   report_names  a name that is not UTF-8 in a report keeps its line (and its bytes)
set -uo pipefail
. "$(dirname "${BASH_SOURCE[0]}")/common.sh" "$@"
PY=/usr/bin/python3; [ -x "$PY" ] || PY=python3

sums() { sha256sum "$@" 2>/dev/null; }
no_temps() {
  local left; left=$(find "${1:-.}" -name '*.tmp.*' 2>/dev/null)
  [ -z "$left" ] || die "temporary files left behind: $left"
}
valid_kanim() { "$K" info "$1" >/dev/null 2>&1 || die "$1 is not a valid .kanim"; }

case "$CASE" in
outputs)
  # A directory run over a symlinked input: the output is named after the path as given and
  # stays below OUTDIR, never after the link's target.
  mkdir -p library subset; cp "$WALK" library/clip.bvh; ln -s ../library/clip.bvh subset/mine.bvh
  cp "$HOP" subset/own.bvh
  expect_rc 0 "$K" encode subset -o out
  [ ! -e library/clip.kanim ] || die "a symlinked input's output landed beside the link's target"
  valid_kanim out/mine.kanim; valid_kanim out/own.kanim
  [ -z "$(find . -name '*.kanim' ! -path './out/*')" ] || die "outputs outside OUTDIR: $(find . -name '*.kanim' ! -path './out/*')"
  # The same through a symlinked subdirectory given as the input itself, and a trailing slash.
  ln -s subset linked
  expect_rc 0 "$K" encode linked/ -o out2
  valid_kanim out2/mine.kanim
  [ -z "$(find . -name '*.kanim' ! -path './out*')" ] || die "outputs outside OUTDIR (linked dir)"

  # --report is an output like the others: never an input (the list, or a BVH it lists).
  mkdir in; cp "$WALK" in/w.bvh; cp "$HOP" in/h.bvh; printf 'in/w.bvh\nin/h.bvh\n' >list.txt
  ln in/h.bvh hardh.jsonl
  before=$(sums in/w.bvh in/h.bvh list.txt)
  for force in "" -f; do
    for r in in/w.bvh list.txt hardh.jsonl ./in/../list.txt; do
      # shellcheck disable=SC2086
      expect_rc 4 "$K" $force encode --manifest list.txt -o mout --report "$r"
      grep -q 'is an input' "$T/.stderr" || die "--report $r: the refusal does not say why: $(cat "$T/.stderr")"
      [ ! -e mout ] || die "--report $r: work was done before refusing"
    done
    # shellcheck disable=SC2086
    expect_rc 4 "$K" $force eval in/w.bvh --report in/w.bvh
  done
  [ "$(sums in/w.bvh in/h.bvh list.txt)" = "$before" ] || die "an input changed"

  # Manifest mode catches two inputs with one output, before any work, as directory mode does.
  mkdir -p m/sub; cp "$WALK" m/sub/a.bvh; cp "$HOP" m/sub/a.BVH
  printf 'm/sub/a.bvh\nm/sub/a.BVH\n' >clash.txt
  for force in "" -f; do
    # shellcheck disable=SC2086
    expect_rc 4 "$K" $force encode --manifest clash.txt -o cout
    grep -q 'm/sub/a.bvh and m/sub/a.BVH would both be written to cout/m/sub/a.kanim' "$T/.stderr" \
      || die "a manifest collision does not name both inputs: $(cat "$T/.stderr")"
    [ ! -e cout ] || die "a manifest collision: outputs were written first"
  done
  # Across shards too: each shard refuses the list, not only the shard holding both.
  expect_rc 4 "$K" encode --manifest clash.txt -o cout --shard 1/2
  printf 'm/sub/a.bvh\nm/sub/A.bvh\n' >clash2.txt; cp "$HOP" m/sub/A.bvh
  expect_rc 4 "$K" encode --manifest clash2.txt -o cout
  grep -q 'where case is ignored' "$T/.stderr" || die "a case-only manifest collision: $(cat "$T/.stderr")"
  # The same input listed twice is one input, encoded once (not a collision).
  printf 'in/w.bvh\nin/w.bvh\nin/h.bvh\n' >twice.txt
  expect_rc 0 "$K" encode --manifest twice.txt -o tout --report tout.jsonl
  [ "$(grep -c '"status":"ok"' tout.jsonl)" = 2 ] || die "an input listed twice: $(cat tout.jsonl)"

  # Devices, FIFOs and links to them are written through or refused, never renamed over.
  "$K" -q encode "$WALK" -o w.kanim || die "encode"
  # (/dev/stdout is such a link, to /proc/self/fd/1; private links are used so that a failure
  # here cannot replace the system's.)
  ln -s /proc/self/fd/1 out1.kanim; ln -s /proc/self/fd/2 out2.bvh
  "$K" -f encode "$WALK" -o out1.kanim >stdout.kanim 2>err || die "-o /proc/self/fd/1: $(cat err)"
  [ -L out1.kanim ] || die "a link to standard output was replaced"
  cmp -s stdout.kanim w.kanim || die "-o /proc/self/fd/1 to a file: the file does not hold the output"
  "$K" -f encode "$WALK" -o out1.kanim 2>err | cat >piped.kanim || die "-o /proc/self/fd/1 to a pipe: $(cat err)"
  cmp -s piped.kanim w.kanim || die "-o /proc/self/fd/1 to a pipe"
  "$K" -q -f decode w.kanim -o out2.bvh 2>stderr.bvh >/dev/null || die "-o /proc/self/fd/2"
  [ -L out2.bvh ] || die "a link to standard error was replaced"
  head -1 stderr.bvh | grep -q HIERARCHY || die "-o /proc/self/fd/2 to a file: $(head -c 200 stderr.bvh)"
  ln -s /dev/null tonull.kanim
  expect_rc 0 "$K" -f encode "$WALK" -o tonull.kanim
  [ -L tonull.kanim ] && [ -c /dev/null ] || die "a link to a device was replaced"
  mkfifo fifo.bvh
  cat fifo.bvh >fromfifo.bvh & reader=$!
  expect_rc 0 "$K" -f decode w.kanim -o fifo.bvh
  wait "$reader"
  [ -p fifo.bvh ] || die "a FIFO output was replaced by a regular file"
  head -1 fromfifo.bvh | grep -q HIERARCHY || die "nothing came through the FIFO"
  # A link to a regular file is replaced (it stays in the directory named), its target is not.
  echo target >target.kanim; ln -s target.kanim link.kanim
  expect_rc 0 "$K" -f encode "$WALK" -o link.kanim
  [ "$(cat target.kanim)" = target ] || die "the link's target was written"
  valid_kanim link.kanim
  no_temps .
  ;;
*) die "unknown case $CASE" ;;
esac
echo "ok: $CASE"
