#!/usr/bin/env bash
# Blender as a second, independent glTF player (CTest gltf_blender; scripts/install-deps.sh
# installs Debian's blender, and without it this exits 77, skipped):
#   blender_check.sh KEYANIM FILE.bvh...
# Encodes each BVH at 0.05%, exports it twice, plays both in Blender's glTF importer
# (blender_play.py) and compares every node and shell point with forward kinematics of the clip
# (blender_compare.mjs):
#   --linear exports must stay within the tolerance (exit 1 otherwise);
#   default exports are reported only: Blender's importer ignores CUBICSPLINE tangents
#   (glTF-Blender-IO issue 419), so it does not play them as the glTF specification says.
source "$(dirname "${BASH_SOURCE[0]}")/blender_common.sh"; shift
NODE_DIR=${KEYANIM_GLTF_NODE_DIR:-$HERE}  # blender_compare.mjs beside its node_modules (gltf_test.sh)
for bvh in "$@"; do
  base="$T/$(basename "$bvh" .bvh)"
  "$K" -q encode "$bvh" -o "$base.kanim" --error 0.05% &&
    "$K" -q decode "$base.kanim" -o "$base.clip.bvh" || { echo "FAIL: keyanim on $bvh"; status=1; continue; }
  frames=$(awk '/^Frames:/{print $2; exit}' "$base.clip.bvh")
  ft=$(awk '/^Frame Time:/{print $3; exit}' "$base.clip.bvh")
  for mode in linear default; do
    glb="$base.$mode.glb"
    opt=(); [ $mode = linear ] && opt=(--linear)
    "$K" -q decode "$base.kanim" -o "$glb" "${opt[@]}" || { echo "FAIL: export $bvh ($mode)"; status=1; continue; }
    blender -b --factory-startup --python-exit-code 1 --python "$HERE/blender_play.py" -- \
      "$glb" "$frames" "$ft" "$glb.json" >"$T/blender.log" 2>&1 ||
      { cat "$T/blender.log"; echo "FAIL: Blender on $glb"; status=1; continue; }
    if ! node "$NODE_DIR/blender_compare.mjs" "$base.clip.bvh" "$glb" "$glb.json" && [ $mode = linear ]; then
      status=1
    fi
  done
done
exit $status
