#!/usr/bin/env bash
# Banks through the real binary (spec/FORMAT.md section 10): pack, list, unpack, LIB:NAME read
# by every command that reads a .kanim, and the refusals. Values are checked against the clips'
# own files, which keyanim encode writes independently of the bank.
# bank_test.sh KEYANIM DATA_DIR CASE; each case exits non-zero on the first surprise.
set -uo pipefail
. "$(dirname "${BASH_SOURCE[0]}")/common.sh" "$@"
json() { python3 -c "import json,sys; d=json.load(sys.stdin); print($1)"; }
mkdir -p lib/cmu
cp "$WALK" lib/cmu/walk.bvh
cp "$HOP" lib/hop.bvh

case "$CASE" in
pack)
  expect_rc 0 "$K" pack lib -o lib.kbank
  "$K" list lib.kbank --json >l.json || die "list --json"
  [ "$(json '[c["name"] for c in d["clips"]]' <l.json)" = "['cmu/walk', 'hop']" ] || die "names: $(cat l.json)"
  [ "$(json 'd["skeletons"], d["profile"]' <l.json)" = "2 archive" ] || die "skeletons and profile: $(cat l.json)"
  [ "$(json 'd["bytes"]' <l.json)" = "$(stat -c %s lib.kbank)" ] || die "list's bytes are not the file's size"
  # Each clip as its own file: the same values and the same BVH as keyanim encode's file.
  expect_rc 0 "$K" encode lib/cmu/walk.bvh -o walk.kanim
  expect_rc 0 "$K" encode lib/hop.bvh -o hop.kanim
  for pair in "cmu/walk walk" "hop hop"; do
    set -- $pair
    expect_rc 0 "$K" decode "lib.kbank:$1" -o "b_$2.bvh"
    expect_rc 0 "$K" decode "$2.kanim" -o "f_$2.bvh"
    cmp -s "b_$2.bvh" "f_$2.bvh" || die "lib.kbank:$1 decodes to another BVH than $2.kanim"
    a=$("$K" sample "lib.kbank:$1" --frame 17.5 --json | json 'd["joints"]') || die "sample lib.kbank:$1"
    b=$("$K" sample "$2.kanim" --frame 17.5 --json | json 'd["joints"]') || die "sample $2.kanim"
    [ "$a" = "$b" ] || die "sample of lib.kbank:$1 differs from $2.kanim"
  done
  expect_rc 0 "$K" verify lib.kbank:cmu/walk --against "$WALK" --max-error 0.05%
  [ "$("$K" info lib.kbank:hop --json | json 'd["frames"]')" = 1102 ] || die "info of a bank's clip"
  # (A page of our own: a build without the viewer, as the sanitizer's, has none.)
  printf '<html><body><!-- keyanim:embed --></body></html>\n' >page.html
  KEYANIM_VIEWER_PAGE=$T/page.html DISPLAY='' WAYLAND_DISPLAY='' expect_rc 0 "$K" view lib.kbank:hop -o hop.html --no-open
  [ "$(stat -c %s hop.html)" -gt 1000 ] || die "view of a bank's clip did not embed it"
  # Default output names: beside the bank, after the clip's name.
  expect_rc 0 "$K" decode lib.kbank:cmu/walk
  [ -f walk.bvh ] || die "decode LIB:cmu/walk did not write walk.bvh beside the bank"
  # A runtime bank, and merging banks, .kanim files and BVH.
  expect_rc 0 "$K" pack lib -o r.kbank --runtime
  [ "$("$K" list r.kbank --json | json 'd["profile"]')" = runtime ] || die "pack --runtime"
  a=$("$K" sample r.kbank:hop --frame 99 --json | json 'd["joints"]') && b=$("$K" sample hop.kanim --frame 99 --json | json 'd["joints"]')
  [ "$a" = "$b" ] || die "the runtime bank's clip samples otherwise"
  expect_rc 0 "$K" pack r.kbank walk.kanim "$WALK" -o merged.kbank --dictionary on
  "$K" list merged.kbank --json >m.json
  [ "$(json 'sorted(c["name"] for c in d["clips"])' <m.json)" = "['cmu/walk', 'cmu_02_01_walk', 'hop', 'walk']" ] || die "merged names: $(cat m.json)"
  [ "$(json 'd["skeletons"], d["dictionary_bytes"] > 0' <m.json)" = "2 True" ] || die "merged: $(cat m.json)"
  printf 'lib/hop.bvh\nlib/cmu/walk.bvh\n' >list.txt
  expect_rc 0 "$K" pack --manifest list.txt -o m2.kbank
  [ "$("$K" list m2.kbank --json | json '[c["name"] for c in d["clips"]]')" = "['lib/hop', 'lib/cmu/walk']" ] || die "manifest names"
  ;;
unpack)
  expect_rc 0 "$K" pack lib -o lib.kbank
  expect_rc 0 "$K" unpack lib.kbank -o out
  [ -f out/cmu/walk.kanim ] && [ -f out/hop.kanim ] || die "unpack wrote: $(find out)"
  expect_rc 0 "$K" decode out/cmu/walk.kanim -o u.bvh
  expect_rc 0 "$K" decode lib.kbank:cmu/walk -o b.bvh
  cmp -s u.bvh b.bvh || die "the unpacked clip decodes otherwise"
  expect_rc 4 "$K" unpack lib.kbank -o out  # exists: not without -f
  expect_rc 0 "$K" -f unpack lib.kbank -o out --runtime
  [ "$("$K" info out/hop.kanim --json | json 'd["profile"]')" = runtime ] || die "unpack --runtime"
  ;;
refusals)
  expect_rc 0 "$K" pack lib -o lib.kbank
  expect_rc 2 "$K" decode lib.kbank -o x.bvh
  grep -q 'a bank of many clips: name one as lib.kbank:NAME' .stderr || die "a bank without :NAME: $(cat .stderr)"
  expect_rc 2 "$K" sample lib.kbank:nope --frame 0
  grep -q "no clip named 'nope'" .stderr || die "an unknown clip: $(cat .stderr)"
  expect_rc 2 "$K" list walk.bvh 2>/dev/null || true
  expect_rc 0 "$K" encode "$WALK" -o walk.kanim
  expect_rc 2 "$K" list walk.kanim
  grep -q 'not a bank' .stderr || die "list of a .kanim: $(cat .stderr)"
  expect_rc 4 "$K" pack lib -o lib.kbank  # exists
  expect_rc 1 "$K" pack lib -o lib.kanim  # a bank's name says .kbank
  expect_rc 4 "$K" -f pack lib.kbank -o lib.kbank  # an input is never the output
  # Two clips of one name: refused before anything is encoded, nothing written.
  cp "$WALK" lib/hop.BVH 2>/dev/null; mkdir -p other && cp "$HOP" other/hop.bvh
  expect_rc 2 "$K" pack lib/hop.bvh other/hop.bvh -o two.kbank
  grep -q "would be named 'hop'" .stderr || die "two clips of one name: $(cat .stderr)"
  [ ! -e two.kbank ] || die "a refused pack left its output"
  # A damaged clip: named; the others still read; unpack writes the others and exits 2.
  python3 - lib.kbank <<'PY'
import struct, sys
b = bytearray(open(sys.argv[1], 'rb').read())
clips, skels = struct.unpack_from('<II', b, 16)
off, size = struct.unpack_from('<QQ', b, 40 + 32 * skels + 40 * 0)  # clip 0: cmu/walk
b[off + size - 20] ^= 0x40
open('bad.kbank', 'wb').write(b)
PY
  expect_rc 2 "$K" sample bad.kbank:cmu/walk --frame 0
  grep -q 'clip cmu/walk' .stderr && grep -q checksum_mismatch .stderr || die "a damaged clip: $(cat .stderr)"
  expect_rc 0 "$K" sample bad.kbank:hop --frame 0
  expect_rc 0 "$K" list bad.kbank
  expect_rc 2 "$K" unpack bad.kbank -o part
  [ -f part/hop.kanim ] && [ ! -e part/cmu/walk.kanim ] || die "unpack of a damaged bank wrote: $(find part)"
  # A damaged index: refused with its place.
  python3 -c "import sys; b=bytearray(open('lib.kbank','rb').read()); b[50]^=1; open('badi.kbank','wb').write(b)"
  expect_rc 2 "$K" list badi.kbank
  grep -q 'badi.kbank: section skeleton table, offset 48' .stderr || die "a damaged index: $(cat .stderr)"
  ;;
manifest)
  # encode --manifest --bank: each shard one bank, clips named as the files a run without --bank
  # writes below OUTDIR (without .kanim); pack merges the shards; a failed input is reported,
  # left out, and the exit code says so.
  printf 'not a bvh\n' >lib/bad.bvh
  printf 'lib/hop.bvh\nlib/cmu/walk.bvh\nlib/bad.bvh\n' >list.txt
  expect_rc 2 "$K" encode --manifest list.txt -o s0.kbank --bank --shard 0/2 --report r.jsonl  # hop, bad
  grep -q 'lib/bad.bvh:1:1' .stderr || die "the failed input: $(cat .stderr)"
  expect_rc 0 "$K" encode --manifest list.txt -o s1.kbank --bank --shard 1/2 --report r.jsonl  # walk
  [ "$("$K" list s0.kbank --json | json '[c["name"] for c in d["clips"]]')" = "['lib/hop']" ] || die "shard 0's bank"
  [ "$(json '[(l["output"], l["status"]) for l in d]' < <(python3 -c "import json,sys; print(json.dumps([json.loads(x) for x in open('r.jsonl')]))"))" = \
    "[('s0.kbank:lib/bad', 'failed'), ('s0.kbank:lib/hop', 'ok'), ('s1.kbank:lib/cmu/walk', 'ok')]" ] || die "report: $(cat r.jsonl)"
  expect_rc 0 "$K" pack s0.kbank s1.kbank -o all.kbank
  expect_rc 2 "$K" encode --manifest list.txt -o files  # the same inputs as files (lib/bad.bvh fails)
  [ -f files/lib/hop.kanim ] && [ -f files/lib/cmu/walk.kanim ] || die "the run without --bank wrote: $(find files)"
  expect_rc 0 "$K" unpack all.kbank -o un
  for c in lib/hop lib/cmu/walk; do
    expect_rc 0 "$K" -f decode "un/$c.kanim" -o u.bvh
    expect_rc 0 "$K" -f decode "files/$c.kanim" -o f.bvh
    cmp -s u.bvh f.bvh || die "$c from the banks decodes otherwise than its file"
  done
  # Resumed with --skip-existing: a bank holding the shard's clips is kept (without the option,
  # refused); a bank short of one (shard 0 lost lib/bad) is encoded again, and replaced.
  before=$(stat -c %i s1.kbank)
  expect_rc 0 "$K" encode --manifest list.txt -o s1.kbank --bank --shard 1/2 --skip-existing
  [ "$(stat -c %i s1.kbank)" = "$before" ] || die "--skip-existing rewrote a finished shard"
  expect_rc 4 "$K" encode --manifest list.txt -o s1.kbank --bank --shard 1/2
  before=$(stat -c %i s0.kbank)
  expect_rc 2 "$K" encode --manifest list.txt -o s0.kbank --bank --shard 0/2 --skip-existing
  [ "$(stat -c %i s0.kbank)" != "$before" ] || die "--skip-existing kept a bank short of a clip"
  # A report that is a link to the bank is refused before any work, and the bank is kept.
  ln -s s1.kbank link.jsonl && cp s1.kbank s1.copy
  expect_rc 4 "$K" -f encode --manifest list.txt -o s1.kbank --bank --shard 1/2 --report link.jsonl
  grep -q 'link.jsonl: is the bank (-o) too' .stderr || die "a report linked to the bank: $(cat .stderr)"
  cmp -s s1.kbank s1.copy || die "a report linked to the bank changed it"
  expect_rc 1 "$K" encode --manifest list.txt -o s0.kanim --bank  # a bank's name says .kbank
  expect_rc 1 "$K" encode lib/hop.bvh --bank
  grep -q -- '--bank goes with --manifest' .stderr || die "--bank without --manifest: $(cat .stderr)"
  # Two entries of one clip name are refused before any work, in every shard.
  cp lib/hop.bvh lib/hop.BVH
  printf 'lib/hop.bvh\nlib/hop.BVH\n' >twice.txt
  expect_rc 2 "$K" encode --manifest twice.txt -o t.kbank --bank --shard 1/2
  grep -q "would be named 'lib/hop'" .stderr && [ ! -e t.kbank ] || die "two entries of one name: $(cat .stderr)"
  ;;
corpus)
  # The whole corpus (KEYANIM_CORPUS, from CMake) packed by the CLI: every clip listed, and
  # every clip, read as LIB:NAME, within the default tolerance of its BVH by keyanim verify's
  # forward kinematics (0.05% of the skeleton size), in both profiles; unpack writes them all.
  C=${KEYANIM_CORPUS:-}
  [ -d "$C" ] || { echo "keyanim-corpus-skip: corpus not found"; exit 77; }
  expect_rc 0 "$K" pack "$C" -o corpus.kbank
  "$K" list corpus.kbank --json >l.json || die "list --json"
  n=$(find "$C" -iname '*.bvh' | wc -l)
  [ "$(json 'len(d["clips"])' <l.json)" = "$n" ] || die "the bank holds $(json 'len(d["clips"])' <l.json) clips, the corpus $n"
  expect_rc 0 "$K" pack corpus.kbank -o runtime.kbank --runtime
  for name in $(json '"\n".join(c["name"] for c in d["clips"])' <l.json); do
    for lib in corpus.kbank runtime.kbank; do
      expect_rc 0 "$K" verify "$lib:$name" --against "$C/$name.bvh" --max-error 0.05%
    done
  done
  expect_rc 0 "$K" unpack corpus.kbank -o out
  [ "$(find out -name '*.kanim' | wc -l)" = "$n" ] || die "unpack wrote $(find out -name '*.kanim' | wc -l) files"
  ;;
*) die "unknown case $CASE" ;;
esac
