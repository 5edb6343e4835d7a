#!/usr/bin/env bash
# keyanim eval --svg and --report: eval_test.sh KEYANIM DATA_DIR CASE
# svg:    the figure parses as XML (python's parser), has one line per file (or per key mode)
#         with one point per tolerance, log axes labelled with their units;
# report: the JSON lines match eval --json, and each total's bytes per second is the files'
#         bytes over their frames x frame time, recomputed here.
set -uo pipefail
. "$(dirname "${BASH_SOURCE[0]}")/common.sh" "$@"
mkdir lib && cp "$WALK" "$HOP" lib/

case "$CASE" in
svg)
  expect_rc 0 "$K" eval lib --error 0.05%,0.2%,1% --svg rd.svg
  python3 - <<'PY' || die "the RD figure (one line per file)"
import xml.etree.ElementTree as ET
ns = {"s": "http://www.w3.org/2000/svg"}
root = ET.parse("rd.svg").getroot()
groups = root.findall(".//s:g[@class='series-group']", ns)
assert [g.get("data-label") for g in groups] == ["cmu_02_01_walk.bvh", "cmu_131_03_hop.bvh"], [g.get("data-label") for g in groups]
for g in groups:
    assert len(g.findall("s:path[@class='series rd']", ns)) == 1
    pts = [(float(c.get("cx")), float(c.get("cy"))) for c in g.findall("s:circle[@class='point']", ns)]
    assert len(pts) == 3, pts
    # more error, more compression: right and up (SVG y grows downwards)
    assert pts[0][0] < pts[1][0] < pts[2][0] and pts[0][1] > pts[1][1] > pts[2][1], pts
labels = [t.text for t in root.iter("{http://www.w3.org/2000/svg}text") if (t.get("class") or "").startswith("label")]
assert any("% of the skeleton size" in l and "log" in l for l in labels), labels
assert any("compression ratio" in l and "log" in l for l in labels), labels
ticks = [t.text for t in root.findall(".//s:g[@class='tick-labels']/s:text", ns)]
assert "0.1" in ticks and "1" in ticks and "10" in ticks, ticks
PY
  expect_rc 0 "$K" eval lib --error 0.05%,0.5% --keys error+uniform:8 --svg modes.svg
  python3 - <<'PY' || die "the RD figure (one line per key mode)"
import xml.etree.ElementTree as ET
ns = {"s": "http://www.w3.org/2000/svg"}
root = ET.parse("modes.svg").getroot()
groups = root.findall(".//s:g[@class='series-group']", ns)
assert [g.get("data-label") for g in groups] == ["keys error", "keys uniform:8"], [g.get("data-label") for g in groups]
assert all(len(g.findall("s:circle[@class='point']", ns)) == 2 for g in groups)
PY
  expect_rc 4 "$K" eval lib --svg rd.svg   # no clobbering without -f
  expect_rc 1 "$K" eval lib --keys error+sometimes --svg x.svg
  ;;
report)
  "$K" eval lib --error 0.05%,0.5% --json >eval.json || die "eval --json"
  expect_rc 0 "$K" eval lib --error 0.05%,0.5% --report r.jsonl
  python3 - <<'PY' || die "the JSON lines"
import json
files = json.load(open("eval.json"))["files"]
lines = [json.loads(l) for l in open("r.jsonl")]
per_file = [l for l in lines if not l.get("total")]
totals = [l for l in lines if l.get("total")]
assert len(per_file) == 4 and len(totals) == 2, (len(per_file), len(totals))
for f in files:
    for r in f["results"]:
        [l] = [l for l in per_file if l["file"] == f["file"] and l["tolerance"] == r["tolerance"]]
        assert l["kanim_bytes"] == r["kanim_bytes"] and l["keys"] == r["keys"], l
        assert l["max_error"] == r["error"]["max"] and l["ratio_raw_f32"] == r["ratio_raw_f32"], l
        assert abs(l["max_error_percent"] - 100 * r["error"]["max"] / f["size"]) < 1e-12, l
        seconds = f["frames"] * f["frame_time"]
        assert abs(l["bytes_per_second"] - r["kanim_bytes"] / seconds) < 1e-9 * l["bytes_per_second"], l
for t in totals:
    mine = [l for l in per_file if l["tolerance"] == t["tolerance"]]
    bytes_ = sum(l["kanim_bytes"] for l in mine)
    seconds = sum(l["frames"] * l["frame_time"] for l in mine)
    assert t["files"] == 2 and t["kanim_bytes"] == bytes_, t
    assert abs(t["bytes_per_second"] - bytes_ / seconds) < 1e-9 * t["bytes_per_second"], t
    assert abs(t["ratio_raw_f32"] - sum(l["raw_f32_bytes"] for l in mine) / bytes_) < 1e-12, t
    assert t["max_error_percent"] == max(l["max_error_percent"] for l in mine), t
PY
  ;;
*) die "unknown case $CASE" ;;
esac
echo "ok: eval $CASE"
