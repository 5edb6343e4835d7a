#!/usr/bin/env bash
# encode_clips.sh KEYANIM OUTDIR WALK.bvh HOP.bvh CORPUS.bvh: the C API tests' clips, as
# OUTDIR/walk.kanim, hop.kanim and corpus.kanim (the last only if the corpus file exists), and
# walk.runtime.kanim, the walk in the runtime profile.
set -euo pipefail
K=$1 OUT=$2
mkdir -p "$OUT"
"$K" encode "$3" -o "$OUT/walk.kanim" -f -q
"$K" encode "$4" -o "$OUT/hop.kanim" -f -q
"$K" -f -q convert "$OUT/walk.kanim" --runtime -o "$OUT/walk.runtime.kanim"  # view_test.c
if [ -f "$5" ]; then
  "$K" encode "$5" -o "$OUT/corpus.kanim" -f -q
else
  rm -f "$OUT/corpus.kanim"
  echo "encode_clips: $5 not found: the corpus clip's tests will be skipped"
fi
