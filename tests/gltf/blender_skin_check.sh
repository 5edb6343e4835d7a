#!/usr/bin/env bash
# The glTF export in Blender as an animator meets it (issue 27):
#   blender_skin_check.sh KEYANIM FILE.bvh...
# Each BVH is encoded at 0.05% and exported to .glb with --linear (Blender 3.4's importer ignores
# CUBICSPLINE tangents, README "glTF export"), once with the bone mesh and once with --no-mesh.
# Blender (headless, factory settings) imports each with the scene's frame rate set first to the
# clip's, rounded (the importer reads none from the file: it places time t on frame t * fps),
# the mesh one with Shading "Flat" (Debian's Blender 3.4 with numpy 1.24 fails on any mesh
# under the default "Normals": np.bool), the other with the defaults; blender_skin.py checks one
# armature, one action over the clip's frames, bones named as keyanim names joints and End Sites,
# and every bone's head at the first, middle and last frame against `keyanim sample --world
# --json` (an independent reference: keyanim's own decoder and forward kinematics, not the
# export's) within the clip's tolerance (`keyanim info --json`) plus a float32 margin of 1e-5 of
# the skeleton size (Blender's pose matrices are float32). Exits 77 (skipped) without blender or
# without the files.
source "$(dirname "${BASH_SOURCE[0]}")/blender_common.sh"; shift
for bvh in "$@"; do [ -f "$bvh" ] || { echo "$bvh not found (corpus absent?): skipped"; exit 77; }; done
for bvh in "$@"; do
  base="$T/$(basename "$bvh" .bvh)"
  "$K" -q encode "$bvh" -o "$base.kanim" --error 0.05% &&
    "$K" -q decode "$base.kanim" -o "$base.glb" --linear &&
    "$K" -q decode "$base.kanim" -o "$base.bare.glb" --linear --no-mesh &&
    "$K" info "$base.kanim" --json >"$base.info.json" || { echo "FAIL: keyanim on $bvh"; status=1; continue; }
  frames=$(/usr/bin/python3 -c 'import json,sys; print(json.load(open(sys.argv[1]))["frames"])' "$base.info.json")
  samples=()
  for f in 0 $(( (frames - 1) / 2 )) $(( frames - 1 )); do
    "$K" sample "$base.kanim" --world --json --frame "$f" >"$base.$f.json" || { echo "FAIL: keyanim sample $f"; status=1; }
    samples+=("$base.$f.json")
  done
  # The reference: names (joints and End Sites in file order), tolerance, the frames' positions.
  fps=$(/usr/bin/python3 - "$base.info.json" "$base.ref.json" "${samples[@]}" <<'PY'
import json, sys
info = json.load(open(sys.argv[1]))
poses = {}
for path in sys.argv[3:]:
    s = json.load(open(path))
    poses[str(round(s["frame_position"]))] = {j["name"]: j["position"] for j in s["joints"]}
names = [j["name"] for j in json.load(open(sys.argv[3]))["joints"]]
ref = {"frames": info["frames"], "tolerance": info["guarantee"]["tolerance_units"], "margin": 1e-5 * info["size"],
       "names": names, "poses": poses}
json.dump(ref, open(sys.argv[2], "w"))
print(round(1 / info["frame_time"]))
PY
  ) || { echo "FAIL: reference of $bvh"; status=1; continue; }
  for run in "$base.glb FLAT" "$base.bare.glb NORMALS"; do
    set -- $run
    blender -b --factory-startup --python-exit-code 1 -P "$HERE/blender_skin.py" -- "$1" "$fps" "$2" "$base.ref.json" \
      >"$T/blender.log" 2>&1 || { grep -v '^$' "$T/blender.log" | tail -25; echo "FAIL: Blender on $(basename "$1") ($2)"; status=1; continue; }
    grep -E "^$T" "$T/blender.log" | sed "s|$T/||"
  done
done
exit $status
