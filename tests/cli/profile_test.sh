#!/usr/bin/env bash
# The two profiles of the format through the real binary (spec/FORMAT.md section 9): encode
# --runtime, convert --runtime/--archive, and every command reading a runtime-profile file.
# profile_test.sh KEYANIM DATA_DIR CASE; each case exits non-zero on the first surprise.
set -uo pipefail
. "$(dirname "${BASH_SOURCE[0]}")/common.sh" "$@"
json() { python3 -c "import json,sys; d=json.load(sys.stdin); print($1)"; }
# The first 4 bytes after the signature: major, minor (u16 each), then Header_Flags' low byte.
header() { python3 -c "import struct,sys; b=open(sys.argv[1],'rb').read(16); print(*struct.unpack('<HHI', b[8:16]))" "$1"; }

case "$CASE" in
convert)
  expect_rc 0 "$K" encode "$WALK" -o walk.kanim
  expect_rc 0 "$K" convert walk.kanim --runtime
  [ -f walk.runtime.kanim ] || die "convert --runtime did not write walk.runtime.kanim (its default name)"
  [ "$(header walk.kanim)" = "5 0 0" ] || die "the archive file is not version 5.0, flags 0: $(header walk.kanim)"
  [ "$(header walk.runtime.kanim)" = "5 0 1" ] || die "the runtime file is not version 5.0 with Runtime set: $(header walk.runtime.kanim)"
  [ "$("$K" info walk.runtime.kanim --json | json 'd["profile"], d["version"]')" = "runtime 5.0" ] || die "info of the runtime file"
  [ "$("$K" info walk.kanim --json | json 'd["profile"]')" = "archive" ] || die "info of the archive file"
  # Same keys and values: every command reads both alike.
  for f in 0 17.25 100.5 343; do
    a=$("$K" sample walk.kanim --frame $f --json | json 'd["joints"]') || die "sample at $f"
    b=$("$K" sample walk.runtime.kanim --frame $f --json | json 'd["joints"]') || die "sample at $f"
    [ "$a" = "$b" ] || die "sample at frame $f differs between the profiles"
  done
  expect_rc 0 "$K" decode walk.kanim -o a.bvh
  expect_rc 0 "$K" decode walk.runtime.kanim -o r.bvh
  cmp -s a.bvh r.bvh || die "the BVH decoded from the runtime file differs"
  expect_rc 0 "$K" verify walk.runtime.kanim --against "$WALK" --max-error 0.05%
  # Back to the archive profile: the same values again.
  expect_rc 0 "$K" convert walk.runtime.kanim --archive -o back.kanim
  expect_rc 0 "$K" decode back.kanim -o b.bvh
  cmp -s a.bvh b.bvh || die "the BVH decoded after converting back differs"
  [ "$(header back.kanim)" = "5 0 0" ] || die "convert --archive did not write version 5.0"
  # Euler rotations: versions 3.0 and 4.0, which older decoders read.
  expect_rc 0 "$K" encode "$WALK" -o euler.kanim --rotations euler
  expect_rc 0 "$K" convert euler.kanim --runtime -o euler.runtime.kanim
  [ "$(header euler.kanim)" = "3 0 0" ] || die "--rotations euler did not write version 3.0: $(header euler.kanim)"
  [ "$(header euler.runtime.kanim)" = "4 0 1" ] || die "its runtime file is not version 4.0: $(header euler.runtime.kanim)"
  expect_rc 1 "$K" encode "$WALK" -o bad.kanim --rotations both
  grep -q -- '--rotations: expected quaternion or euler' .stderr || die "a bad --rotations: $(cat .stderr)"
  ;;
encode)
  expect_rc 0 "$K" encode "$HOP" -o hop.kanim
  expect_rc 0 "$K" encode "$HOP" -o hop.r.kanim --runtime
  expect_rc 0 "$K" convert hop.kanim --runtime -o hop.c.kanim
  cmp -s hop.r.kanim hop.c.kanim || die "encode --runtime differs from encode, then convert --runtime"
  "$K" encode "$HOP" -o hop.j.kanim --runtime --json >e.json || die "encode --runtime --json"
  [ "$(json 'd["kanim_bytes"]' <e.json)" = "$(stat -c %s hop.j.kanim)" ] || die "kanim_bytes is not the runtime file's size"
  ;;
refusals)
  expect_rc 0 "$K" encode "$HOP" -o hop.kanim
  expect_rc 1 "$K" convert hop.kanim
  grep -q -- '--runtime or --archive' .stderr || die "convert without a profile: $(cat .stderr)"
  expect_rc 1 "$K" convert hop.kanim --runtime --archive
  expect_rc 0 "$K" convert hop.kanim --runtime -o r.kanim
  expect_rc 4 "$K" convert hop.kanim --runtime -o r.kanim  # exists: not without -f
  expect_rc 0 "$K" -f convert hop.kanim --runtime -o r.kanim
  expect_rc 4 "$K" -f convert r.kanim --archive -o r.kanim  # an input is never an output
  # A damaged runtime file: refused with the section and offset, nothing written.
  python3 - r.kanim <<'PY'
import sys
p = sys.argv[1]; b = bytearray(open(p, 'rb').read()); b[200] ^= 0x10; open('bad.kanim', 'wb').write(b)
PY
  expect_rc 2 "$K" convert bad.kanim --archive -o out.kanim
  grep -q 'checksum_mismatch' .stderr || die "a damaged runtime file: $(cat .stderr)"
  [ ! -e out.kanim ] || die "a refused input left an output"
  ;;
*) die "unknown case $CASE" ;;
esac
echo "ok: $CASE"
