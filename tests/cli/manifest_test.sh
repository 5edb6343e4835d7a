#!/usr/bin/env bash
# encode --manifest: batch runs that survive being killed and split across machines.
#   manifest_test.sh KEYANIM DATA_DIR CASE [SLURM_SCRIPT]
# basics:   mirrored outputs, shards that add up to the list, the report, --skip-existing,
#           failures, usage errors;
# parallel: GNU parallel (-S 2/:, one shard per job) over 200 generated clips, killed midway
#           (SIGKILL to every process of the run), resumed with --joblog --resume-failed;
# slurm:    scripts/slurm_encode.sh run for every SLURM_ARRAY_TASK_ID of an array, then again.
# After parallel and slurm: every output loads and verifies against its input, and the report
# lists each input exactly once.
set -uo pipefail
SLURM_SCRIPT=${4:+$(realpath "$4")}
. "$(dirname "${BASH_SOURCE[0]}")/common.sh" "$@"

# make_library COUNT: COUNT short clips (the first 60 frames of the walk, each shifted) under
# lib/dNN/, and list.txt with their paths relative to lib/.
make_library() {
  local header frames
  header=$(awk '/^Frames:/{exit} {print}' "$WALK" | tr -d '\r')
  frames=$(awk 'f&&NR<=start+60{print} /^Frame Time/{f=1; start=NR}' "$WALK" | tr -d '\r')
  for i in $(seq 1 "$1"); do
    local d="lib/d$((i % 10))"
    mkdir -p "$d"
    { echo "$header"; echo "Frames: 60"; echo "Frame Time: 0.0083333"
      echo "$frames" | awk -v s="$i" '{$1 = $1 + s * 0.01; print}'; } >"$d/clip_$i.bvh"
  done
  (cd lib && find . -name '*.bvh' | sort) >list.txt
}

# check_done OUTDIR REPORT...: every listed input has a valid output within the tolerance, and
# the reports name each input exactly once, as ok or skipped.
check_done() {
  local out=$1; shift
  local bad=0
  while read -r p; do
    local o="$out/${p#./}"; o="${o%.bvh}.kanim"
    "$K" -q verify "$o" --against "lib/$p" --max-error 0.05% >/dev/null 2>&1 || { echo "bad output $o" >&2; bad=1; }
  done <list.txt
  [ "$bad" = 0 ] || die "outputs missing or not within the tolerance"
  [ "$(find "$out" -name '*.kanim' | wc -l)" = "$(wc -l <list.txt)" ] || die "not one output per input"
  cat "$@" | python3 -c '
import json, sys
want = set(l.strip() for l in open("list.txt") if l.strip())
seen = {}
for line in sys.stdin:
    d = json.loads(line)
    assert d["status"] in ("ok", "skipped"), d
    seen[d["input"]] = seen.get(d["input"], 0) + 1
twice = [k for k, n in seen.items() if n != 1]
assert not twice, "listed more than once: %s" % twice[:5]
assert set(seen) == want, "missing from the report: %s" % sorted(want - set(seen))[:5]
' || die "the report does not list each input exactly once"
}

case "$CASE" in
basics)
  make_library 12
  cd lib
  expect_rc 0 "$K" encode --manifest ../list.txt -o ../out --report ../r.jsonl
  [ -f ../out/d3/clip_3.kanim ] || die "outputs do not mirror the inputs' paths"
  [ "$(wc -l <../r.jsonl)" = 12 ] || die "one report line per input"
  python3 -c '
import json
for l in open("../r.jsonl"):
    d = json.loads(l)
    assert set(d) >= {"input", "output", "status", "bytes", "max_error", "tolerance", "seconds"}, d
    assert d["status"] == "ok" and d["max_error"] <= d["tolerance"], d
' || die "report fields"
  # Shards add up to the list, without overlap.
  for s in 0 1 2; do expect_rc 0 "$K" encode --manifest ../list.txt -o ../sharded --shard $s/3 --report ../s.jsonl; done
  [ "$(find ../sharded -name '*.kanim' | wc -l)" = 12 ] || die "shards do not cover the list"
  [ "$(wc -l <../s.jsonl)" = 12 ] || die "shards overlap"
  cmp -s ../out/d1/clip_1.kanim ../sharded/d1/clip_1.kanim || die "sharded output differs"
  # Existing outputs: refused, or skipped when they load; a damaged one is replaced.
  expect_rc 4 "$K" encode --manifest ../list.txt -o ../out
  head -c 100 ../out/d5/clip_5.kanim >cut && mv cut ../out/d5/clip_5.kanim
  expect_rc 0 "$K" encode --manifest ../list.txt -o ../out --skip-existing --report ../r.jsonl
  "$K" -q verify ../out/d5/clip_5.kanim >/dev/null || die "a damaged output was not replaced"
  [ "$(grep -c '"status":"ok"' ../r.jsonl)" = 13 ] || die "the replaced output is not reported once more"
  [ "$(grep -c skipped ../r.jsonl)" = 0 ] || die "inputs already reported were reported again"
  # An input that fails: reported, the others go on, exit 2.
  printf 'HIERARCHY\n' >d0/broken.bvh
  echo ./d0/broken.bvh >>../list.txt
  expect_rc 2 "$K" encode --manifest ../list.txt -o ../out --skip-existing --report ../r.jsonl
  grep -q '"input":"./d0/broken.bvh".*"status":"failed"' ../r.jsonl || die "a failure is not in the report"
  # Paths that climb out are mirrored by their absolute path; an absolute one loses its root.
  expect_rc 0 "$K" encode --manifest <(echo ../lib/d2/clip_2.bvh; echo "$PWD/d4/clip_4.bvh") -o ../abs
  [ -f "../abs$PWD/d2/clip_2.kanim" ] && [ -f "../abs$PWD/d4/clip_4.kanim" ] || die "absolute mirroring"
  expect_rc 1 "$K" encode --manifest ../list.txt -o ../out --shard 3/3
  expect_rc 1 "$K" encode --manifest ../list.txt -o ../out --shard x
  expect_rc 1 "$K" encode --manifest ../list.txt
  expect_rc 1 "$K" encode d1/clip_1.bvh --skip-existing
  ;;
parallel)
  command -v parallel >/dev/null || die "GNU parallel is not installed (scripts/install-deps.sh installs it)"
  make_library 200
  N=40
  cd lib
  run() {
    parallel --will-cite -S 2/: --joblog ../jobs.log "$@" \
      "$K" -q encode --manifest ../list.txt --shard {}/$N -o ../out --skip-existing --report ../report.jsonl \
      ::: $(seq 0 $((N - 1)))
  }
  setsid bash -c "$(declare -f run); K='$K' N=$N run" >/dev/null 2>&1 &
  pid=$!
  for _ in $(seq 1 1200); do
    [ "$(cat ../report.jsonl 2>/dev/null | wc -l)" -ge 60 ] && break
    sleep 0.05
  done
  # A crash: every process of the run stops at once, wherever it is. GNU parallel gives each
  # job its own process group, so the tree is collected by parent id (stopped first, so that
  # nothing new starts meanwhile) and killed by process id.
  tree() { local c; for c in $(ps -o pid= --ppid "$1"); do echo "$c"; tree "$c"; done; }
  all="$pid"
  for _ in 1 2 3; do all="$all $(tree "$pid")"; kill -STOP $all 2>/dev/null; done
  kill -KILL $all 2>/dev/null
  wait "$pid" 2>/dev/null
  done_jobs=$(($(wc -l <../jobs.log) - 1))
  [ "$done_jobs" -lt "$N" ] || die "parallel finished all $N shards before it could be killed"
  echo "killed after $done_jobs of $N shards, $(wc -l <../report.jsonl) inputs reported"
  run --resume-failed >resume.log 2>&1 || { tail -20 resume.log >&2; die "the resumed run failed"; }
  [ "$(($(wc -l <../jobs.log) - 1))" = "$N" ] || die "the joblog does not hold every shard after resuming"
  cd ..
  check_done out report.jsonl
  ;;
slurm)
  [ -n "$SLURM_SCRIPT" ] || die "no Slurm script given"
  make_library 30
  cd lib
  N=7
  for i in $(seq 0 $((N - 1))); do
    SLURM_ARRAY_TASK_ID=$i SLURM_ARRAY_TASK_COUNT=$N SLURM_ARRAY_TASK_MIN=0 KEYANIM="$K" \
      bash "$SLURM_SCRIPT" ../list.txt ../out -q || die "task $i failed"
  done
  # Resubmitted (say after a timeout): nothing to do, nothing reported twice. Arrays numbered
  # from 1 give the same shards.
  for i in $(seq 1 $N); do
    SLURM_ARRAY_TASK_ID=$i SLURM_ARRAY_TASK_COUNT=$N SLURM_ARRAY_TASK_MIN=1 KEYANIM="$K" \
      bash "$SLURM_SCRIPT" ../list.txt ../out -q || die "task $i of the resubmission failed"
  done
  expect_rc 1 env -u SLURM_ARRAY_TASK_ID bash "$SLURM_SCRIPT" ../list.txt ../out
  cd ..
  check_done out out/report.*.jsonl
  ;;
*) die "unknown case $CASE" ;;
esac
echo "ok: manifest $CASE"
