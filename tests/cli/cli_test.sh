#!/usr/bin/env bash
# CLI behaviour through the real binary: cli_test.sh KEYANIM DATA_DIR CASE
# Each case prints what it checks and exits non-zero on the first surprise.
set -uo pipefail
. "$(dirname "${BASH_SOURCE[0]}")/common.sh" "$@"
json() { python3 -c "import json,sys; d=json.load(sys.stdin); print($1)"; }

case "$CASE" in
roundtrip)
  expect_rc 0 "$K" encode "$WALK" -o walk.kanim
  expect_rc 0 "$K" decode walk.kanim -o walk.bvh
  expect_rc 0 "$K" verify walk.kanim --against "$WALK" --max-error 0.05%
  # The decoded BVH has the original's hierarchy, frame count and frame time.
  a=$("$K" info "$WALK" --json | json 'd["joints"],d["end_sites"],d["channels"],d["frames"],d["frame_time"],d["size"],d["rotation_orders"]')
  b=$("$K" info walk.bvh --json | json 'd["joints"],d["end_sites"],d["channels"],d["frames"],d["frame_time"],d["size"],d["rotation_orders"]')
  [ "$a" = "$b" ] || die "hierarchy differs: $a vs $b"
  diff <(grep -E 'ROOT|JOINT|End Site|CHANNELS' "$WALK" | tr -d '\r' | tr -s ' \t' ' ' | sed 's/ *$//') \
       <(grep -E 'ROOT|JOINT|End Site|CHANNELS' walk.bvh | tr -s ' \t' ' ' | sed 's/ *$//') >/dev/null || die "joint lines differ"
  ;;
json)
  "$K" encode "$WALK" -o w.kanim --json >enc.json || die "encode --json"
  size=$(stat -c %s w.kanim)
  [ "$(json 'd["kanim_bytes"]' <enc.json)" = "$size" ] || die "encode --json kanim_bytes is not the file size"
  [ "$(json 'd["error"]["max"] <= d["tolerance"]' <enc.json)" = "True" ] || die "encode reports an error over tolerance"
  "$K" eval "$WALK" --error 0.05%,0.5% --json >eval.json || die "eval --json"
  [ "$(json 'len(d["files"][0]["results"])' <eval.json)" = "2" ] || die "eval did not run both tolerances"
  [ "$(json 'd["files"][0]["results"][0]["kanim_bytes"]' <eval.json)" = "$size" ] || die "eval bytes differ from encode"
  [ "$(json 'd["files"][0]["frames"]' <eval.json)" = "344" ] || die "eval frames"
  "$K" info w.kanim --json | json 'd["keys"]["total"]' >keys || die "info --json"
  [ "$(cat keys)" = "$(json 'd["keys"]' <enc.json)" ] || die "info key total differs from encode"
  # sample at frame 0 gives the original first-frame values within the tolerance's angle share
  "$K" sample w.kanim --frame 0 --joint Hips --json | json 'd["joints"][0]["Xposition"]' >x || die "sample --json"
  orig=$(awk '/^MOTION/{m=1;next} m&&/Frame Time/{getline; print $1; exit}' "$WALK")
  python3 -c "import sys; sys.exit(0 if abs(float('$(cat x)')-float('$orig'))<0.02 else 1)" || die "sample frame 0 Hips X $(cat x) vs $orig"
  "$K" sample w.kanim --time 0.5 --world --json | json 'len(d["joints"])' >n || die "sample --world"
  [ "$(cat n)" = "38" ] || die "sample --world should list 31 joints + 7 End Sites, got $(cat n)"
  ;;
exit_codes)
  expect_rc 1 "$K"
  expect_rc 0 "$K" --help
  expect_rc 0 "$K" encode --help
  expect_rc 0 "$K" -V
  expect_rc 1 "$K" frobnicate
  expect_rc 1 "$K" encode "$WALK" --no-such-option
  expect_rc 1 "$K" encode "$WALK" --error -3
  expect_rc 1 "$K" encode "$WALK" --keys sometimes
  expect_rc 2 "$K" encode does-not-exist.bvh -o x.kanim
  printf 'HIERARCHY\nROOT a\n{\n OFFSET 0 0\n' >bad.bvh
  expect_rc 2 "$K" encode bad.bvh -o x.kanim
  grep -q 'bad.bvh:5:1: expected a number' "$T/.stderr" || die "malformed BVH error does not name the end of the file: $(cat "$T/.stderr")"
  [ ! -e x.kanim ] || die "a failed encode left an output"
  "$K" encode "$WALK" -o ok.kanim >/dev/null 2>&1
  # -V names the format a default encode writes (the newest): 5.0, with quaternion nodes.
  ver=$("$K" info ok.kanim --json | json 'd["version"]')
  [ "$ver" = "5.0" ] && "$K" -V | grep -qF "(format $ver)" || die "-V says $("$K" -V), a default encode writes $ver"
  head -c 100 ok.kanim >cut.kanim
  expect_rc 2 "$K" decode cut.kanim -o cut.bvh
  [ ! -e cut.bvh ] || die "a failed decode left an output"
  # A later major version: the version field follows the 8-byte signature (little-endian u16).
  cp ok.kanim v9.kanim; printf '\x09' | dd of=v9.kanim bs=1 seek=8 conv=notrunc 2>/dev/null
  expect_rc 3 "$K" info v9.kanim
  expect_rc 4 "$K" encode "$WALK" -o ok.kanim
  expect_rc 5 "$K" verify ok.kanim --against "$WALK" --max-error 0.0001%
  ;;
no_clobber)
  echo "precious" >walk.kanim
  expect_rc 4 "$K" encode "$WALK" -o walk.kanim
  [ "$(cat walk.kanim)" = "precious" ] || die "existing output was modified without -f"
  expect_rc 0 "$K" encode -f "$WALK" -o walk.kanim
  "$K" info walk.kanim >/dev/null || die "forced output is not a valid .kanim"
  cp "$WALK" w.bvh
  expect_rc 0 "$K" encode w.bvh            # default name w.kanim
  expect_rc 4 "$K" decode w.kanim          # default name w.bvh exists: the input is safe
  cmp -s w.bvh "$WALK" || die "the input BVH was modified"
  [ -z "$(ls -a | grep '\.tmp\.')" ] || die "temporary files left behind"
  ;;
pipe)
  cat "$WALK" | "$K" encode - -o - | "$K" decode - -o - >piped.bvh || die "pipe failed"
  "$K" info piped.bvh --json | json 'd["frames"]' >f
  [ "$(cat f)" = "344" ] || die "piped BVH has $(cat f) frames"
  ;;
tween)
  "$K" encode "$WALK" -o w.kanim 2>/dev/null
  expect_rc 0 "$K" decode w.kanim -o w30.bvh --fps 30
  [ "$("$K" info w30.bvh --json | json 'd["frames"]')" = "86" ] || die "30 fps decode frame count"
  expect_rc 0 "$K" decode w.kanim -o w2.bvh --inbetweens 1
  [ "$("$K" info w2.bvh --json | json 'd["frames"]')" = "687" ] || die "inbetweens frame count"
  expect_rc 0 "$K" decode w.kanim -o part.bvh --frames 10:19
  [ "$("$K" info part.bvh --json | json 'd["frames"]')" = "10" ] || die "--frames count"
  expect_rc 1 "$K" decode w.kanim -o x.bvh --fps 30 --inbetweens 2
  expect_rc 1 "$K" decode w.kanim -o x.bvh --frames 5:400
  # The walk stores Frame Time .0083333, a hair under 1/120 s: --fps 120 is the clip's own rate
  # and gives its 344 frames, the same values as the source-rate decode (MOTION lines but the
  # Frame Time); --fps 240 gives the in-betweens of --inbetweens 1, value for value.
  expect_rc 0 "$K" decode w.kanim -o w.bvh
  expect_rc 0 "$K" decode w.kanim -o w120.bvh --fps 120
  [ "$("$K" info w120.bvh --json | json 'd["frames"]')" = "344" ] || die "--fps 120 dropped a frame"
  cmp -s <(sed -n '/^MOTION/,$p' w.bvh | grep -v 'Frame Time') <(sed -n '/^MOTION/,$p' w120.bvh | grep -v 'Frame Time') ||
    die "--fps 120 values differ from the source frames"
  "$K" decode w.kanim -o one.bvh --frames 5:5 2>err || die "a one-frame decode"
  grep -q ': 1 frame at' err || die "one frame is not '1 frame': $(cat err)"
  expect_rc 0 "$K" decode w.kanim -o w240.bvh --fps 240
  cmp -s <(sed -n '/^MOTION/,$p' w2.bvh | grep -v 'Frame Time') <(sed -n '/^MOTION/,$p' w240.bvh | grep -v 'Frame Time') ||
    die "--fps 240 differs from --inbetweens 1"
  ;;
typos)
  # A mistyped command, option or joint gets the nearest names, and joints point to info.
  "$K" encod x 2>err; [ $? = 1 ] && grep -q "did you mean 'encode'" err || die "no suggestion for 'encod': $(cat err)"
  "$K" encode --eror 1 "$WALK" 2>err; [ $? = 1 ] && grep -q "did you mean '--error'" err || die "no suggestion for --eror: $(cat err)"
  "$K" encode "$WALK" -o w.kanim 2>/dev/null
  "$K" sample w.kanim --frame 1 --joint LeftHnd 2>err; [ $? = 1 ] || die "a joint the clip lacks is not exit 1"
  grep -q "did you mean 'LeftHand'" err && grep -q 'keyanim info' err || die "no suggestion for LeftHnd: $(cat err)"
  "$K" sample w.kanim --frame 1 --joint Zzzzzz 2>err
  grep -q 'did you mean' err && die "a suggestion for a name near nothing: $(cat err)"
  grep -q 'keyanim info' err || die "the joint error does not mention keyanim info: $(cat err)"
  ;;
positions)
  # A frame or time the clip does not have is exit 1 (README's exit table), as render does.
  "$K" encode "$WALK" -o w.kanim 2>/dev/null
  for bad in "--frame 1000" "--frame 344" "--frame -1" "--frame -0.5" "--time 100" "--time -0.1"; do
    expect_rc 1 "$K" sample w.kanim $bad
  done
  "$K" sample w.kanim --frame 1000 2>err >/dev/null
  grep -q 'frames 0 to 343' err || die "the refusal does not say the clip's range: $(cat err)"
  for good in "--frame 0" "--frame 343" "--frame 342.5" "--time 0" "--time 1.5"; do
    expect_rc 0 "$K" sample w.kanim $good
  done
  # The last frame's time, as info gives the duration, is in the clip.
  d=$("$K" info w.kanim --json | json '(d["frames"] - 1) * d["frame_time"]')
  expect_rc 0 "$K" sample w.kanim --time "$d"
  expect_rc 1 "$K" render w.kanim --frame 1000 -o r.svg
  # Text output lists a joint's channels in the file's order (its CHANNELS line), not sorted.
  got=$("$K" sample w.kanim --frame 0 --joint Hips | tr ' ' '\n' | sed -n 's/=.*//p' | tr '\n' ' ')
  want=$(grep -m1 CHANNELS "$WALK" | tr -d '\r' | awk '{for (i = 3; i <= NF; i++) printf "%s ", $i}')
  [ "$got" = "$want" ] || die "sample lists Hips' channels as '$got', the file as '$want'"
  ;;
directory)
  mkdir -p in/sub; cp "$WALK" in/a.bvh; cp "$WALK" in/sub/b.bvh; echo garbage >in/broken.bvh
  expect_rc 2 "$K" encode in -o out -j 2
  [ -f out/a.kanim ] && [ -f out/sub/b.kanim ] || die "good files were not encoded"
  [ ! -e out/broken.kanim ] || die "the broken file left an output"
  grep -q 'broken.bvh:1:1' "$T/.stderr" || die "the broken file is not named: $(cat "$T/.stderr")"
  [ -z "$(find out -name '*.tmp.*')" ] || die "temporary files left behind"
  expect_rc 2 "$K" eval in -j 2 --error 0.5%
  grep -q 'a.bvh' "$T/.stdout" || die "eval skipped the good files"
  ;;
output_names)
  # An output's name says what it holds (issue 28, item 12): a name whose extension is another
  # format's is refused (exit 1, naming the file and the right extension) before any work, and
  # nothing is written; --to states the format and lets any name through.
  "$K" -q encode "$WALK" -o w.kanim || die "encode"
  refused() {  # refused NAME WANT command...: exit 1, the message names NAME and WANT, no file
    local name=$1 want=$2; shift 2
    expect_rc 1 "$@"
    grep -q "$name: this writes .*name it .*$want" "$T/.stderr" || die "'$*': the refusal does not name $name and $want: $(cat "$T/.stderr")"
    [ ! -e "$name" ] || die "'$*' left $name"
    [ -z "$(ls -a | grep '\.tmp\.')" ] || die "'$*' left a temporary file"
  }
  refused walk.fbx .bvh "$K" decode w.kanim -o walk.fbx
  grep -q -- '--to bvh' "$T/.stderr" && grep -q '.glb' "$T/.stderr" || die "decode's refusal does not offer --to or glTF: $(cat "$T/.stderr")"
  refused walk.mp4 .bvh "$K" decode w.kanim -o walk.mp4 --fps 30
  refused out.bvh .kanim "$K" encode "$WALK" -o out.bvh
  grep -q -- '--to kanim' "$T/.stderr" || die "encode's refusal does not offer --to kanim: $(cat "$T/.stderr")"
  refused c.png .svg "$K" plot "$WALK" --channel Hips:Xrotation -o c.png
  refused f.png .svg "$K" render w.kanim -o f.png
  refused p.txt .html "$K" view w.kanim -o p.txt --no-open
  refused rd.png .svg "$K" eval "$WALK" --error 1% --svg rd.png
  refused r.txt .jsonl "$K" eval "$WALK" --error 1% --report r.txt
  printf '%s\n' "$WALK" >list.txt
  refused r.csv .jsonl "$K" encode --manifest list.txt -o mout --report r.csv
  [ ! -e mout ] || die "a refused manifest run encoded"
  # What is written is what the name or --to says: BVH text in walk.mp4, a .kanim in x.bin.
  expect_rc 0 "$K" decode w.kanim -o walk.mp4 --to bvh
  [ "$("$K" info walk.mp4 --json | json 'd["format"]')" = "bvh" ] || die "--to bvh did not write BVH"
  expect_rc 0 "$K" encode "$WALK" -o x.bin --to kanim
  [ "$("$K" info x.bin --json | json 'd["format"]')" = "kanim" ] || die "--to kanim did not write a .kanim"
  expect_rc 0 "$K" plot "$WALK" --channel Hips:Xrotation -o c.xml --to svg
  head -c 200 c.xml | grep -q '<svg' || die "--to svg did not write SVG"
  expect_rc 1 "$K" encode "$WALK" -o y.kanim --to bvh   # encode writes one format
  [ ! -e y.kanim ] || die "a wrong --to left an output"
  mkdir -p in; cp "$WALK" in/a.bvh
  expect_rc 1 "$K" encode in -o dout --to kanim         # outputs named by the run: no --to
  # Case does not matter, a name without an extension and a device are not checked, and an
  # input stays protected first (exit 4, not 1).
  expect_rc 0 "$K" decode w.kanim -o WALK.BVH
  expect_rc 0 "$K" decode w.kanim -o WALK.GLB
  [ "$(head -c 4 WALK.GLB)" = "glTF" ] || die "an upper-case .GLB did not get glTF"
  expect_rc 0 "$K" decode w.kanim -o noext
  expect_rc 0 "$K" -f decode w.kanim -o /dev/null
  expect_rc 4 "$K" -f encode "$WALK" -o "$WALK"
  ;;
summaries)
  # A batch run that succeeds says so in one line on standard error (issue 28, item 13):
  # inputs, bytes in and out (the files' own sizes), the worst error and the time; -q: nothing.
  mkdir -p in/sub; cp "$WALK" in/a.bvh; cp "$HOP" in/sub/b.bvh
  "$K" encode in -o out 2>err >std || die "encode DIR"
  [ ! -s std ] || die "the summary went to standard output: $(cat std)"
  [ "$(wc -l <err)" = 1 ] || die "encode DIR printed $(wc -l <err) lines, expected one: $(cat err)"
  bvh=$(( $(stat -c %s in/a.bvh) + $(stat -c %s in/sub/b.bvh) ))
  kan=$(( $(stat -c %s out/a.kanim) + $(stat -c %s out/sub/b.kanim) ))
  grep -q "^in -> out: 2 inputs, 2 encoded in [0-9.]* s; $bvh bytes of BVH -> $kan bytes of .kanim" err ||
    die "the summary does not give 2 inputs, $bvh bytes in and $kan out: $(cat err)"
  # The worst error is the input's closest to its tolerance, as its own encode reports it.
  worst=$("$K" -f encode in -o out --json | json 'max(d["files"], key=lambda f: f["error"]["max"] / f["tolerance"])["error"]["max"]')
  python3 - "$worst" "$(sed -n 's/.*worst error \([^,]*\),.*/\1/p' err)" <<'PY' || die "worst error: $(cat err), --json says $worst"
import sys; a, b = map(float, sys.argv[1:]); sys.exit(0 if abs(a - b) <= 1e-5 * a else 1)
PY
  expect_rc 0 "$K" -q -f encode in -o out
  [ ! -s "$T/.stderr" ] || die "-q printed: $(cat "$T/.stderr")"
  # A manifest: encoded, skipped and failed inputs are counted.
  echo garbage >in/bad.bvh
  printf 'in/a.bvh\nin/sub/b.bvh\nin/bad.bvh\n' >list.txt
  "$K" encode --manifest list.txt -o mout 2>err; [ $? = 2 ] || die "a manifest with a bad input: not exit 2"
  grep -q "^list.txt -> mout: 3 inputs, 2 encoded, 1 failed in" err || die "manifest summary: $(cat err)"
  "$K" encode --manifest list.txt -o mout --skip-existing 2>err
  grep -q "^list.txt -> mout: 3 inputs, 0 encoded, 2 skipped, 1 failed in [0-9.]* s$" err || die "manifest summary with skips: $(cat err)"
  printf 'in/a.bvh\n' >one.txt
  expect_rc 0 "$K" -q encode --manifest one.txt -o qout
  [ ! -s "$T/.stderr" ] || die "-q printed: $(cat "$T/.stderr")"
  ;;
mismatch)
  # Two inputs that cannot be compared are one rule, exit 2 (README's exit table): verify,
  # render and view --against alike; 5 stays for a check that ran and failed (issue 28, item 19).
  "$K" -q encode "$WALK" -o w.kanim || die "encode"
  printf 'HIERARCHY\nROOT a\n{\n OFFSET 0 0 0\n CHANNELS 3 Zrotation Xrotation Yrotation\n End Site\n {\n  OFFSET 0 1 0\n }\n}\nMOTION\nFrames: 2\nFrame Time: 0.1\n0 0 0\n1 1 1\n' >other.bvh
  expect_rc 2 "$K" verify w.kanim --against other.bvh
  grep -q 'other.bvh: not the same skeleton or frame count as w.kanim' "$T/.stderr" || die "verify's refusal: $(cat "$T/.stderr")"
  expect_rc 2 "$K" verify w.kanim --against other.bvh --max-error 1% --json
  [ ! -s "$T/.stdout" ] || die "verify printed a result for inputs it could not compare: $(cat "$T/.stdout")"
  expect_rc 2 "$K" verify w.kanim --against "$HOP"       # the same skeleton, another frame count
  expect_rc 2 "$K" render w.kanim --against other.bvh -o r.svg
  printf '<html><body><!-- keyanim:embed --></body></html>\n' >page.html
  KEYANIM_VIEWER_PAGE=$T/page.html DISPLAY='' WAYLAND_DISPLAY='' expect_rc 2 "$K" view w.kanim --against other.bvh -o v.html --no-open
  [ ! -e v.html ] && [ ! -e r.svg ] || die "a refused comparison left an output"
  # The same pair that matches: exit 0, and 5 only when the check itself fails.
  KEYANIM_VIEWER_PAGE=$T/page.html DISPLAY='' WAYLAND_DISPLAY='' expect_rc 0 "$K" view w.kanim --against "$WALK" -o v.html --no-open
  expect_rc 0 "$K" verify w.kanim --against "$WALK"
  expect_rc 5 "$K" verify w.kanim --against "$WALK" --max-error 0.0001%
  ;;
gltf_rate)
  # glTF at another rate (issue 28, item 17): --fps keys are samples, not fitted; when the
  # export is past the clip's tolerance a warning says by how much and why (keys 1/F s apart,
  # between which the worst frame falls), and none is printed within it or with -q.
  "$K" -q encode "$WALK" -o w.kanim || die "encode"
  "$K" decode w.kanim -o w30.glb --fps 30 2>err || die "decode --fps 30"
  python3 - <<'PY' || die "the warning: $(cat err)"
import re
text = open("err").read()
m = re.search(r"error max ([0-9.e+-]+) \(.*, frame (\d+)\), tolerance ([0-9.e+-]+)", text)
error, frame, tol = float(m[1]), int(m[2]), float(m[3])
assert error > 10 * tol, (error, tol)
w = re.search(r"keyanim: warning: w.kanim: with --fps 30 the export is [0-9.e+-]+ from the clip \(.*, frame (\d+)\), "
              r"(\d+)x its tolerance .*keys 1/30 s apart.*source frames ([0-9.]+) and ([0-9.]+); the clip has a frame "
              r"every .*120 fps\)\. The error is measured at every source frame", text)
assert w, text
assert int(w[1]) == frame and abs(int(w[2]) - error / tol) <= 1, (w.groups(), error / tol)
a, b = float(w[3]), float(w[4])
assert a <= frame <= b and b - a == 4, (a, b, frame)   # 120 fps / 30 fps: a key every 4 frames
PY
  "$K" -q decode w.kanim -o q30.glb --fps 30 2>err || die "decode -q --fps 30"
  [ ! -s err ] || die "-q printed: $(cat err)"
  for opts in "--fps 120" ""; do
    # shellcheck disable=SC2086
    "$K" decode w.kanim -o "x${opts// /}.glb" $opts 2>err || die "decode $opts"
    grep -q warning err && die "a warning within the tolerance ($opts): $(cat err)"
  done
  ;;
*) die "unknown case $CASE" ;;
esac
echo "ok: $CASE"
