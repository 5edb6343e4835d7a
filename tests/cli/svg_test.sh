#!/usr/bin/env bash
# The SVG commands through the real binary: svg_test.sh KEYANIM DATA_DIR CASE
# CASE plot|render: the figure is well-formed XML with its axes, labels, series and markers.
# CASE exit_codes: usage errors, unreadable inputs and existing outputs.
set -uo pipefail
. "$(dirname "${BASH_SOURCE[0]}")/common.sh" "$@"
# Well-formed XML whose root is <svg> with a viewBox (python3 if present, else xmllint).
well_formed() {
  if command -v python3 >/dev/null; then
    python3 -c 'import sys, xml.dom.minidom as m
d = m.parse(sys.argv[1]).documentElement
sys.exit(0 if d.tagName == "svg" and d.getAttribute("viewBox") else 1)' "$1" || die "$1 is not a well-formed SVG"
  elif command -v xmllint >/dev/null; then
    xmllint --noout "$1" || die "$1 is not well-formed XML"
  else
    echo "note: no XML parser here; structure checked by grep only" >&2
  fi
  grep -q '^<svg xmlns="http://www.w3.org/2000/svg"' "$1" || die "$1: no <svg> root"
}
n() { grep -o "$1" "$2" | wc -l; }

case "$CASE" in
plot)
  expect_rc 0 "$K" plot "$WALK" --channel RightArm:Zrotation --keys curvature -o curve.svg
  well_formed curve.svg
  [ "$(n 'class="axis ' curve.svg)" -eq 2 ] || die "plot: expected 2 axes"
  [ "$(n 'class="series original"' curve.svg)" -eq 1 ] || die "plot: one original series"
  [ "$(n 'class="series reconstructed"' curve.svg)" -eq 1 ] || die "plot: one reconstructed series"
  grep -q '>frame</text>' curve.svg || die "plot: no x label"
  grep -q '>Zrotation (degrees)</text>' curve.svg || die "plot: no y label with unit"
  keys=$(n 'class="key"' curve.svg)
  [ "$keys" -ge 2 ] || die "plot: fewer than 2 key markers"
  grep -q ">reconstructed ($keys keys)</text>" curve.svg || die "plot: legend does not count the $keys markers"
  # Default output name beside the input (copied here so as not to write into the source tree).
  cp "$WALK" walk.bvh
  expect_rc 0 "$K" plot walk.bvh --channel Hips:Yposition
  [ -s walk-Hips-Yposition.svg ] || die "plot: default output walk-Hips-Yposition.svg missing"
  grep -q '>Yposition (file units)</text>' walk-Hips-Yposition.svg || die "plot: position unit"
  # Standard output, and a frame range.
  "$K" plot walk.bvh --channel Hips:Yposition --frames 10:40 -o - >range.svg || die "plot -o -"
  well_formed range.svg
  ;;
render)
  expect_rc 0 "$K" render "$WALK" --frame 100 -o frame.svg
  well_formed frame.svg
  [ "$(n 'class="axis ' frame.svg)" -eq 4 ] || die "render: expected 2 axes in each of 2 views"
  # 31 joints + 7 End Sites: 37 bones and 38 dots per pose, 2 poses, 2 views.
  [ "$(n 'class="bone"' frame.svg)" -eq 148 ] || die "render: expected 148 bones"
  [ "$(n 'class="joint"' frame.svg)" -eq 152 ] || die "render: expected 152 joint dots"
  [ "$(n 'class="worst"' frame.svg)" -eq 2 ] || die "render: worst joint not circled in both views"
  grep -q '>original</text>' frame.svg || die "render: legend"
  grep -q '>x (file units)</text>' frame.svg && grep -q '>z (file units)</text>' frame.svg || die "render: axis labels"
  # Against a decoded .kanim, and a .kanim alone.
  expect_rc 0 "$K" encode "$WALK" -o walk.kanim --keys uniform:10
  expect_rc 0 "$K" render "$WALK" --against walk.kanim --frame 5 -o against.svg
  well_formed against.svg
  grep -q '>walk.kanim</text>' against.svg || die "render --against: legend names the file"
  expect_rc 0 "$K" render walk.kanim -o alone.svg
  well_formed alone.svg
  [ "$(n 'class="bone"' alone.svg)" -eq 74 ] || die "render of a .kanim alone: one pose"
  # Issue 28, item 9: the up axis. A y-up file says nothing about it; its z-up twin (every
  # OFFSET turned +90 degrees about x) is detected, drawn x-z and y-z, and render says so;
  # --up y overrides (no note), --up x is refused.
  expect_rc 0 "$K" render "$WALK" --frame 0 -o y.svg
  if grep -q 'up axis' "$T/.stderr"; then die "render of a y-up file talks about its up axis"; fi
  grep -q '>front view (x-y)</text>' y.svg || die "render: y-up front view"
  awk '$1 == "OFFSET" { printf "OFFSET %s %s %s\n", $2, ($4 == 0 ? 0 : -$4), $3; next } { print }' "$WALK" >zup.bvh
  expect_rc 0 "$K" render zup.bvh --frame 0 -o z.svg
  grep -q '^zup.bvh: up axis z, detected: the rest pose spans .* along z and .* along y (--up y to override)$' "$T/.stderr" ||
    { cat "$T/.stderr" >&2; die "render: no note of the detected up axis"; }
  grep -q '>front view (x-z)</text>' z.svg && grep -q '>side view (y-z)</text>' z.svg || die "render: z-up views"
  expect_rc 0 "$K" render zup.bvh --frame 0 --up y -o zy.svg
  if grep -q 'up axis' "$T/.stderr"; then die "render --up y still notes the axis"; fi
  grep -q '>front view (x-y)</text>' zy.svg || die "render --up y: x-y view"
  expect_rc 0 "$K" -q render zup.bvh --frame 0 -o zq.svg
  [ ! -s "$T/.stderr" ] || die "render -q printed: $(cat "$T/.stderr")"
  expect_rc 1 "$K" render zup.bvh --up x -o zx.svg
  grep -q "\-\-up expects y, z or auto, got 'x'" "$T/.stderr" || die "render --up x: no clear error"
  # The reading: position channels below the root holding deltas (MakeHuman's way) are read as
  # replace by default, and render says that their bones keep their lengths under add.
  printf 'HIERARCHY\nROOT r\n{\n OFFSET 0 0 0\n CHANNELS 3 Xposition Yposition Zposition\n JOINT a\n {\n  OFFSET 0 10 0\n  CHANNELS 3 Xposition Yposition Zposition\n  End Site\n  {\n   OFFSET 0 10 0\n  }\n }\n}\nMOTION\nFrames: 1\nFrame Time: 0.1\n0 0 0 0 0.01 0\n' >deltas.bvh
  expect_rc 0 "$K" render deltas.bvh -o d.svg
  grep -q '^deltas.bvh: position channels below the root read as replace (.*); its bones keep their lengths under add .*--position-channels add$' "$T/.stderr" ||
    { cat "$T/.stderr" >&2; die "render: no note of the reading"; }
  expect_rc 0 "$K" render deltas.bvh --position-channels add -o da.svg
  if grep -q 'read as' "$T/.stderr"; then die "render --position-channels add still notes the reading"; fi
  ;;
exit_codes)
  expect_rc 0 "$K" plot --help
  expect_rc 0 "$K" render --help
  expect_rc 1 "$K" plot "$WALK" --channel RightArm:Wrotation -o a.svg
  expect_rc 1 "$K" plot "$WALK" --channel Nobody:Xrotation -o a.svg
  expect_rc 1 "$K" plot "$WALK" --channel RightArm:Xposition -o a.svg
  expect_rc 1 "$K" plot "$WALK" -o a.svg
  expect_rc 1 "$K" plot "$WALK" --channel RightArm:Zrotation --frames 400:500 -o a.svg
  expect_rc 1 "$K" render "$WALK" --frame 344 -o a.svg
  expect_rc 1 "$K" render "$WALK" --no-such-option
  [ ! -e a.svg ] || die "a refused command left an output"
  expect_rc 2 "$K" plot does-not-exist.bvh --channel RightArm:Zrotation -o a.svg
  expect_rc 2 "$K" render does-not-exist.bvh -o a.svg
  expect_rc 2 "$K" render "$WALK" --against does-not-exist.kanim -o a.svg
  printf 'HIERARCHY\nROOT a\n{\n OFFSET 0 0 0\n CHANNELS 1 Xposition\n}\nMOTION\nFrames: 1\nFrame Time: 0.1\n1\n' >other.bvh
  expect_rc 2 "$K" render "$WALK" --against other.bvh -o a.svg
  grep -q 'not the same skeleton' "$T/.stderr" || die "skeleton mismatch not named"
  echo old >exists.svg
  expect_rc 4 "$K" plot "$WALK" --channel RightArm:Zrotation -o exists.svg
  expect_rc 4 "$K" render "$WALK" -o exists.svg
  [ "$(cat exists.svg)" = old ] || die "an existing output was replaced without -f"
  expect_rc 0 "$K" -f render "$WALK" -o exists.svg
  grep -q '<svg' exists.svg || die "-f did not replace the output"
  ;;
*) die "unknown case $CASE" ;;
esac
echo "ok: $CASE"
