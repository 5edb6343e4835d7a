#!/usr/bin/env bash
# Makes the version 5.0 bank vectors of spec section 10 with the keyanim tool: make_b50.sh KEYANIM
#   b50_archive.kbank  v5_quat and v5_blocks (members of version 5, with quaternion nodes) beside
#                      v3_rules and v3_long (members of version 4, laid out as 3.0), no dictionary
#   b50_runtime.kbank  the same four clips in the runtime profile (9): members of versions 5 and 4
# A bank with a member of version 5 is of version 5.0 (10.2). Each clip is named after the vector
# it came from and decodes to that vector's .json values (the runtime members too: their clips
# are the archive vectors').
# A vector that exists is checked to hold these bytes, not rewritten (vectors never change).
set -euo pipefail
K=$1
[[ "$K" == */* ]] && K=$(realpath "$K")  # a path to the tool stays valid after the cd below
cd "$(dirname "$0")"
T=$(mktemp -d)
trap 'rm -rf "$T"' EXIT
CLIPS=(v5_quat.kanim v5_blocks.kanim v3_rules.kanim v3_long.kanim)
"$K" -q pack "${CLIPS[@]}" -o "$T/b50_archive.kbank" --dictionary off
"$K" -q pack "${CLIPS[@]}" -o "$T/b50_runtime.kbank" --runtime
for v in b50_archive b50_runtime; do
  if [ -e "$v.kbank" ]; then cmp "$T/$v.kbank" "$v.kbank" || { echo "make_b50: $v.kbank differs from what the tool writes" >&2; exit 1; }
  else cp "$T/$v.kbank" "$v.kbank"; echo "make_b50: wrote $v.kbank"; fi
done
