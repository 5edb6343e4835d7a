#!/usr/bin/env bash
# compare_clip.sh CLIP.kanim SOURCE.bvh PYTHON compare.py KEYANIM PROGRAM...: compare.py on one
# clip, or exit 77 (skipped) when the clip is the corpus one and the corpus is absent.
set -uo pipefail
clip=$1 bvh=$2; shift 2
if [ ! -f "$bvh" ]; then
  echo "SKIP: $bvh not found (the shared corpus is absent)"
  exit 77
fi
py=$1 compare=$2 keyanim=$3; shift 3
exec "$py" "$compare" "$keyanim" "$clip" "$bvh" -- "$@"
