#!/usr/bin/env bash
# keyanim eval --svg and --report: eval_test.sh KEYANIM DATA_DIR CASE
# svg:    the figure parses as XML (python's parser), has one line per file (or per key mode)
#         with one point per tolerance, log axes labelled with their units;
# report: the JSON lines match eval --json, and each total's bytes per second is the files'
#         bytes over their frames x frame time, recomputed here.
# table:  the text table: names, columns, alignment and totals (recomputed from --json);
# acl:    --acl TABLE: ACL's bytes at each file's error interpolated log-log between the rows
#         that bracket it (the nearest row outside them), the ratio, and per group the median
#         and worst ratio, all recomputed here from a table written here.
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
acl)
  # Walk: three rows around any error it can reach (an unsorted table, one row at error 0 left
  # out); hop: two rows above its errors (nearest row); a file of size 0 has no usable row.
  printf 'file\tgroup\tframes\tfps\tsize\tacl_bytes\tacl_err_units\n' >t.tsv
  printf 'cmu_02_01_walk.bvh\tcmu\t344\t120\t24\t30000\t0.001\n' >>t.tsv
  printf 'cmu_02_01_walk.bvh\tcmu\t344\t120\t24\t9000\t1\n' >>t.tsv
  printf 'cmu_02_01_walk.bvh\tcmu\t344\t120\t24\t16000\t0.05\n' >>t.tsv
  printf 'cmu_02_01_walk.bvh\tcmu\t344\t120\t24\t99\t0\n' >>t.tsv
  printf 'cmu_131_03_hop.bvh\tbandai\t1102\t30\t24\t50000\t5\n' >>t.tsv
  printf 'cmu_131_03_hop.bvh\tbandai\t1102\t30\t24\t40000\t10\n' >>t.tsv
  printf 'other.bvh\tmisc\t10\t30\t0\t500\t0.1\n' >>t.tsv
  "$K" eval lib --error 0.05%,0.5% --acl t.tsv --json >acl.json || die "eval --acl --json"
  "$K" eval lib --error 0.05%,0.5% --acl t.tsv >acl.txt || die "eval --acl"
  python3 - <<'PY' || die "the comparison with ACL"
import json, math
doc = json.load(open("acl.json"))
rows = {"cmu_02_01_walk.bvh": [(0.001, 30000), (0.05, 16000), (1, 9000)], "cmu_131_03_hop.bvh": [(5, 50000), (10, 40000)]}
groups = {"cmu_02_01_walk.bvh": "cmu_120fps", "cmu_131_03_hop.bvh": "bandai_30fps"}
ratios = {}
for f in doc["files"]:
    name = f["file"].split("/")[-1]
    for r in f["results"]:
        e, a = r["error"]["max"], r["acl"]
        assert a["error"] == e and a["group"] == groups[name], a
        pts = rows[name]
        if e <= pts[0][0]: want, interp = pts[0][1], False
        elif e >= pts[-1][0]: want, interp = pts[-1][1], False
        else:
            (e0, b0), (e1, b1) = [(p, q) for p, q in zip(pts, pts[1:]) if p[0] <= e <= q[0]][0]
            want, interp = math.exp(math.log(b0) + math.log(e / e0) / math.log(e1 / e0) * math.log(b1 / b0)), True
        assert abs(a["bytes"] - want) <= 1e-9 * want and a["interpolated"] == interp, (name, e, a, want)
        assert abs(a["ratio"] - r["kanim_bytes"] / want) <= 1e-12, a
        assert abs(r["bytes_per_second"] - r["kanim_bytes"] / (f["frames"] * f["frame_time"])) <= 1e-9 * r["bytes_per_second"]
        ratios.setdefault(r["tolerance"], {})[name] = a["ratio"]
    assert groups[name] == "bandai_30fps" or all(r["acl"]["interpolated"] for r in f["results"]), name
for tol, by_file in ratios.items():
    summary = doc["acl_summary"]["error " + tol]
    assert sorted(summary) == ["bandai_30fps", "cmu_120fps"], summary
    for name, ratio in by_file.items():
        g = summary[groups[name]]
        assert g["files"] == 1 and g["median_ratio"] == ratio and g["worst_ratio"] == ratio and g["worst_file"].endswith(name), g
text = open("acl.txt").read()
assert "x ACL" in text and "against ACL, error 0.05%, cmu_120fps: 1 files, median" in text, text
PY
  expect_rc 2 "$K" eval lib --acl missing.tsv
  printf 'a\tb\n1\t2\n' >bad.tsv
  expect_rc 2 "$K" eval lib --acl bad.tsv
  ;;
table)
  # The table (issue 28, item 14): names relative to the inputs' directory, whole (not cut);
  # with several key modes a mode column, the setting column holding settings only, every row
  # aligned; a total row per setting, its figures recomputed here from --json.
  mkdir -p lib/sub; cp "$WALK" lib/sub/a_long_name_for_a_clip_of_someone_walking_slowly_in_a_lab.bvh
  opts=(--error 0.5% --keys error+uniform:10+curvature -j 2)
  "$K" eval lib "${opts[@]}" >table.txt 2>/dev/null || die "eval"
  "$K" eval lib "${opts[@]}" --json >eval.json 2>/dev/null || die "eval --json"
  python3 - <<'PY' || die "the table: $(cat table.txt)"
import json
lines = open("table.txt").read().splitlines()
files = json.load(open("eval.json"))["files"]
head, rows = lines[0], lines[1:]
assert head.startswith("file, below lib/ "), head
assert len({len(l) for l in lines}) == 1, "rows of different lengths:\n" + "\n".join(lines)
col = {name: head.index(name) for name in ("keys mode", "--error")}
names = sorted(f["file"][len("lib/"):] for f in files)
assert "sub/a_long_name_for_a_clip_of_someone_walking_slowly_in_a_lab.bvh" in names, names
body, totals = rows[:-3], rows[-3:]
assert len(body) == 3 * len(files), rows
for line in body:
    name = line[:col["keys mode"]].strip()
    assert name in names, (name, names)
    mode = line[col["keys mode"]:].split()[0]
    assert mode in ("error", "uniform:10", "curvature"), line
    setting = line[col["keys mode"] + len(mode):].split()[0]
    assert setting == "0.5%", line
for line, mode in zip(totals, ("error", "uniform:10", "curvature")):
    assert line.startswith("total (3 files) "), line
    w = line[col["keys mode"]:].split()
    assert w[0] == mode and w[1] == "0.5%", line
    rs = [r for f in files for r in f["results"] if r["key_mode"] == mode]
    keys, size = sum(r["keys"] for r in rs), sum(r["kanim_bytes"] for r in rs)
    raw = sum(f["raw_f32_bytes"] for f in files)
    assert int(w[2]) == keys and int(w[3]) == size, (line, keys, size)
    assert abs(float(w[4]) - raw / size) <= 0.005, (line, raw / size)
    assert float(w[7]) == float("%.4g" % max(r["error"]["max"] for r in rs)), line
    samples = [f["frames"] * f["nodes"] for f in files]
    rms = (sum(r["error"]["rms"] ** 2 * n for r, n in zip(rs, samples)) / sum(samples)) ** 0.5
    assert float(w[8]) == float("%.4g" % rms), (line, rms)
PY
  # One file: no total row, and the tolerance heading in error mode.
  "$K" eval "$WALK" --error 1% >one.txt 2>/dev/null || die "eval one file"
  [ "$(wc -l <one.txt)" = 2 ] && head -n1 one.txt | grep -q ' tolerance ' || die "one file's table: $(cat one.txt)"
  ;;
*) die "unknown case $CASE" ;;
esac
echo "ok: eval $CASE"
