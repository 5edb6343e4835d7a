#!/usr/bin/env bash
# The CLI under faults, through the real binary: fault_test.sh KEYANIM DATA_DIR CASE
# Damaged inputs, outputs that cannot be written, a full disk, inputs vanishing and interrupts
# during directory runs. Each case prints what it checks and exits non-zero on the first
# surprise; a case whose setup this machine does not allow (mount, mknod) says so and passes.
set -uo pipefail
. "$(dirname "${BASH_SOURCE[0]}")/common.sh" "$@"
MOUNTS=()
before_cleanup() {  # unmount what a case mounted before the scratch directory goes
  local m
  for m in "${MOUNTS[@]+"${MOUNTS[@]}"}"; do umount "$m" 2>/dev/null; done
}
skip() { echo "skipped: $CASE: $*"; exit 0; }
no_temps() {  # no_temps DIR: no temporary output left anywhere below DIR
  local left
  left=$(find "$1" -name '*.tmp.*' 2>/dev/null)
  [ -z "$left" ] || die "temporary files left behind: $left"
}
# A byte of FILE at OFFSET replaced by its bitwise complement.
flip_byte() {
  python3 - "$1" "$2" <<'EOF'
import sys
path, at = sys.argv[1], int(sys.argv[2])
b = bytearray(open(path, "rb").read())
b[at] ^= 0xFF
open(path, "wb").write(b)
EOF
}
# try_mount_tmpfs DIR SIZE [ro]: a small tmpfs at DIR (root only); false if not allowed here.
try_mount_tmpfs() {
  mkdir -p "$1"
  local opts="size=$2"
  [ "${3:-}" = ro ] && opts="$opts,ro"
  mount -t tmpfs -o "$opts" tmpfs "$1" 2>/dev/null || return 1
  MOUNTS+=("$1")
}

case "$CASE" in
damaged_kanim)
  # Every kind of damage is exit 2 (3 for a newer major version) and leaves no output. (Bytes
  # 8-9 are Major_Version: a flip there is exit 3, checked last.)
  "$K" -q encode "$WALK" -o ok.kanim || die "encode"
  size=$(stat -c %s ok.kanim)
  for at in 0 3 10 12 16 20 24 30 40 47 48 60 100 $((size / 3)) $((size / 2)) $((size - 5)) $((size - 4)) $((size - 1)); do
    cp ok.kanim bad.kanim; flip_byte bad.kanim "$at"
    expect_rc 2 "$K" decode bad.kanim -o bad.bvh
    [ ! -e bad.bvh ] || die "a failed decode (byte $at flipped) left an output"
    grep -q 'bad.kanim' "$T/.stderr" || die "the error does not name the file: $(cat "$T/.stderr")"
  done
  for n in 0 7 8 23 24 50 $((size / 2)) $((size - 1)); do
    head -c "$n" ok.kanim >cut.kanim
    expect_rc 2 "$K" decode cut.kanim -o cut.bvh
    [ ! -e cut.bvh ] || die "a failed decode (cut at $n) left an output"
  done
  grep -q 'truncated' "$T/.stderr" || die "a truncated file is not called truncated: $(cat "$T/.stderr")"
  { cat ok.kanim; printf 'garbage'; } >long.kanim
  expect_rc 2 "$K" decode long.kanim -o long.bvh
  grep -q 'trailing_bytes' "$T/.stderr" || die "appended bytes are not reported: $(cat "$T/.stderr")"
  [ ! -e long.bvh ] || die "a failed decode left an output"
  cp ok.kanim v9.kanim; printf '\x09' | dd of=v9.kanim bs=1 seek=8 conv=notrunc 2>/dev/null
  expect_rc 3 "$K" decode v9.kanim -o v9.bvh
  [ ! -e v9.bvh ] || die "an unsupported version left an output"
  expect_rc 2 "$K" verify bad.kanim
  no_temps .
  ;;
damaged_bvh)
  # A BVH cut at every 7th line of the hierarchy and at some motion lines: exit 2 naming
  # file:line:column, no output.
  lines=$(wc -l <"$HOP") || die "cannot read $HOP"
  for n in $(seq 1 7 190) 300 $((lines / 2)) $((lines - 1)); do
    head -n "$n" "$HOP" >cut.bvh
    "$K" -q encode cut.bvh -o cut.kanim 2>err; rc=$?
    if [ "$rc" -eq 0 ]; then die "a BVH cut after line $n was accepted"; fi
    [ "$rc" -eq 2 ] || die "a BVH cut after line $n: exit $rc, expected 2"
    grep -Eq 'cut\.bvh:[0-9]+:[0-9]+: expected' err || die "line $n: no file:line:column: $(cat err)"
    [ ! -e cut.kanim ] || die "a failed encode left an output"
  done
  # Frame Time 0 with two frames reads as BVH but cannot be stored (spec 4.1): exit 2, no
  # output (it once gave exit 0 and an empty .kanim).
  printf 'HIERARCHY\nROOT r\n{\n OFFSET 5 0 0\n CHANNELS 1 Xposition\n End Site\n {\n  OFFSET 1 0 0\n }\n}\nMOTION\nFrames: 2\nFrame Time: 0\n1\n2\n' >t0.bvh
  expect_rc 2 "$K" encode t0.bvh -o t0.kanim
  [ ! -e t0.kanim ] || die "an encode that failed left an output"
  # A value beyond 2^53 quantization steps, with keys that the error check does not revisit.
  printf 'HIERARCHY\nROOT r\n{\n OFFSET 5 0 0\n CHANNELS 1 Xposition\n End Site\n {\n  OFFSET 1 0 0\n }\n}\nMOTION\nFrames: 2\nFrame Time: 0.1\n3.3e47\n2\n' >huge.bvh
  expect_rc 2 "$K" encode huge.bvh -o huge.kanim --keys uniform:1
  [ ! -e huge.kanim ] || die "an encode that failed left an output"
  no_temps .
  ;;
unwritable)
  # Outputs that cannot be created: exit 4, nothing left behind, even as root.
  echo "a file" >file
  expect_rc 4 "$K" encode "$WALK" -o file/x.kanim
  [ "$(cat file)" = "a file" ] || die "the file in the way was modified"
  expect_rc 4 "$K" encode "$WALK" -o missing-dir/x.kanim
  [ ! -e missing-dir ] || die "a directory was created for a single output"
  expect_rc 4 "$K" -f encode "$WALK" -o /proc/keyanim-fault-test.kanim
  # Directory mode with OUTDIR an existing file: every input fails with 4.
  mkdir in; cp "$WALK" in/a.bvh; cp "$HOP" in/b.bvh
  expect_rc 4 "$K" encode in -o file -j 1
  [ "$(cat file)" = "a file" ] || die "the file in the way was modified"
  no_temps .
  if try_mount_tmpfs ro 64k ro; then
    expect_rc 4 "$K" encode "$WALK" -o ro/x.kanim
    [ -z "$(ls -A ro)" ] || die "something was written to a read-only file system"
  else
    echo "note: cannot mount a read-only tmpfs here; that part skipped"
  fi
  ;;
disk_full)
  # The output does not fit: exit 4, and neither the output nor a temporary file remains.
  "$K" -q encode "$WALK" -o w.kanim || die "encode"
  # /dev/full exists: without -f it is not replaced, and nothing is created in /dev.
  expect_rc 4 "$K" decode w.kanim -o /dev/full
  [ -c /dev/full ] || die "/dev/full is no longer a character device"
  [ -z "$(ls -a /dev | grep '\.full\.tmp\.')" ] || die "a temporary file was left in /dev"
  try_mount_tmpfs small 64k || skip "cannot mount a small tmpfs here (needs root)"
  expect_rc 4 "$K" decode w.kanim -o small/w.bvh   # a BVH of about 300 kB
  grep -qi 'space' "$T/.stderr" || die "the error does not say the disk is full: $(cat "$T/.stderr")"
  [ -z "$(ls -A small)" ] || die "left in the full file system: $(ls -A small)"
  # Directory mode: the first outputs fit, later ones do not; each failure is reported.
  mkdir in; for i in 1 2 3 4 5 6; do cp "$WALK" "in/w$i.bvh"; done
  expect_rc 4 "$K" encode in -o small/out -j 1 --level 1
  no_temps small
  for f in small/out/*.kanim; do
    [ -e "$f" ] || continue
    "$K" info "$f" >/dev/null 2>&1 || die "$f is not a complete .kanim"
  done
  ;;
device_output)
  # -f onto an existing character device must write to the device (or refuse), never replace
  # the device node by a regular file: as root, '-f -o /dev/null' would otherwise destroy
  # /dev/null. Checked on a private device node (mknod needs root).
  "$K" -q encode "$WALK" -o w.kanim || die "encode"
  mknod full c 1 7 2>/dev/null || skip "cannot create a device node here (needs root)"
  mknod null c 1 3 2>/dev/null || skip "cannot create a device node here"
  "$K" -f decode w.kanim -o null >/dev/null 2>&1
  [ -c null ] || die "'-f -o DEVICE' replaced the device node by a regular file"
  expect_rc 4 "$K" -f decode w.kanim -o full
  [ -c full ] || die "'-f -o DEVICE' replaced the device node by a regular file"
  no_temps .
  ;;
vanishing_input)
  # An input deleted during a directory run: reported, and the others are still encoded.
  mkdir in
  for i in 0 1 2 3 4 5 6 7; do cp "$WALK" "in/w$i.bvh"; done
  "$K" encode in -o out -j 1 >out.log 2>err.log &
  pid=$!
  for _ in $(seq 1 600); do [ -e out/w0.kanim ] && break; sleep 0.05; done
  [ -e out/w0.kanim ] || { kill "$pid"; die "the first output did not appear"; }
  rm in/w7.bvh
  wait "$pid"; rc=$?
  [ "$rc" -eq 2 ] || die "exit $rc, expected 2 (an input could not be read)"
  grep -q 'w7.bvh' err.log || die "the vanished input is not named: $(cat err.log)"
  grep -q '1 of 8 inputs failed' err.log || die "no summary of failures: $(cat err.log)"
  for i in 0 1 2 3 4 5 6; do
    "$K" info "out/w$i.kanim" >/dev/null 2>&1 || die "out/w$i.kanim missing or broken"
  done
  [ ! -e out/w7.kanim ] || die "an output for the vanished input"
  no_temps out
  ;;
interrupt)
  # SIGINT, then SIGTERM, during a directory run: the process dies of the signal, leaves no
  # temporary file, every output it left is complete, and the inputs are untouched.
  mkdir in
  for i in 0 1 2 3 4 5 6 7 8 9; do cp "$WALK" "in/w$i.bvh"; cp "$HOP" "in/h$i.bvh"; done
  (cd in && sha256sum -- *.bvh) >sums
  for sig in INT TERM; do
    rm -rf out
    "$K" encode in -o out -j 1 >/dev/null 2>err.log &
    pid=$!
    for _ in $(seq 1 600); do [ -n "$(ls out 2>/dev/null)" ] && break; sleep 0.02; done
    sleep 0.1
    kill -s "$sig" "$pid"
    wait "$pid"; rc=$?
    [ "$rc" -ne 0 ] || die "SIG$sig: the run finished with exit 0 before or despite the signal"
    [ "$rc" -gt 128 ] || die "SIG$sig: exit $rc, expected death by the signal"
    no_temps out
    n=0
    for f in out/*.kanim; do
      [ -e "$f" ] || continue
      "$K" info "$f" >/dev/null 2>&1 || die "SIG$sig: $f is incomplete"
      n=$((n + 1))
    done
    [ "$n" -lt 20 ] || die "SIG$sig: all 20 outputs were written: the signal came too late to test anything"
    (cd in && sha256sum --quiet -c ../sums) || die "SIG$sig: the inputs changed"
    echo "SIG$sig: exit $rc after $n complete outputs"
  done
  ;;
*) die "unknown case $CASE" ;;
esac
echo "ok: $CASE"
