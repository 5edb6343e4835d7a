#!/usr/bin/env bash
# Makes the bank vectors of spec section 10 with the keyanim tool: make_b41.sh KEYANIM
#   b41_archive.kbank     seven archive vectors in one bank (v3_rules and v2_rules share a skeleton)
#   b41_dictionary.kbank  the same, with a zstd dictionary (10.4)
#   b41_runtime.kbank     six of them in the runtime profile (9) (not v3_blocks: its image is 245 KB)
#   b41_damaged.kbank     b41_archive with one byte of clip v3_uniform's last section changed: that clip
#                         fails its checksum (10.5), the others decode
# Each clip is named after the vector it came from and decodes to that vector's .json values.
# A vector that exists is checked to hold these bytes, not rewritten (vectors never change).
set -euo pipefail
K=$1
cd "$(dirname "$0")"
T=$(mktemp -d)
trap 'rm -rf "$T"' EXIT
ARCHIVE=(v3_rules.kanim v2_rules.kanim v3_uniform.kanim v3_single.kanim v3_long.kanim v3_predict.kanim v3_blocks.kanim)
"$K" -q pack "${ARCHIVE[@]}" -o "$T/b41_archive.kbank" --dictionary off
"$K" -q pack "${ARCHIVE[@]}" -o "$T/b41_dictionary.kbank" --dictionary on
"$K" -q pack "${ARCHIVE[@]:0:6}" -o "$T/b41_runtime.kbank" --runtime
python3 - "$T/b41_archive.kbank" "$T/b41_damaged.kbank" <<'PY'
import struct, sys
b = bytearray(open(sys.argv[1], "rb").read())
clips, skeletons = struct.unpack_from("<II", b, 16)
offset, size = struct.unpack_from("<QQ", b, 40 + 32 * skeletons + 40 * 2)  # clip 2: v3_uniform
b[offset + size - 10] ^= 0x01  # in its last section, before its CRC-32
open(sys.argv[2], "wb").write(b)
PY
for v in b41_archive b41_dictionary b41_runtime b41_damaged; do
  if [ -e "$v.kbank" ]; then cmp "$T/$v.kbank" "$v.kbank" || { echo "make_b41: $v.kbank differs from what the tool writes" >&2; exit 1; }
  else cp "$T/$v.kbank" "$v.kbank"; echo "make_b41: wrote $v.kbank"; fi
done
