#!/usr/bin/env bash
# glTF export, checked by tools that share no code with keyanim (check_export.mjs: the Khronos
# glTF-Validator, three.js playing the export, BVH forward kinematics written in JS).
#   gltf_test.sh KEYANIM DATA_DIR cli            the command's behaviour on the shipped clips
#   gltf_test.sh KEYANIM CORPUS_DIR corpus FILE_GLOB...  every matching file of the folder: encode at
#                                                0.05%, export with the defaults and with
#                                                --linear, check both
#   gltf_test.sh KEYANIM DATA_DIR deep           a chain deeper than the fit walks a point's
#                                                movers at once (gltf_fit.cpp's kWindow), exported
#                                                and checked as the corpus is
# Needs node, and three and gltf-validator installed beside copies of the .mjs scripts in
# $KEYANIM_GLTF_NODE_DIR (the build tree's tests/gltf, where the build runs npm ci; default: this
# folder, after `npm ci` here). Exits 77 (skipped) when the corpus is absent.
set -uo pipefail
HERE=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
K=$(realpath "$1"); DIR=$(realpath -m "$2"); CASE="$3"; shift 3
die() { echo "FAIL: $*" >&2; exit 1; }
NODE_DIR=${KEYANIM_GLTF_NODE_DIR:-$HERE}
command -v node >/dev/null || die "node not found: run scripts/install-deps.sh"
[ -d "$NODE_DIR/node_modules/three" ] && [ -d "$NODE_DIR/node_modules/gltf-validator" ] ||
  die "$NODE_DIR/node_modules lacks three or gltf-validator: build the project (npm ci runs there)"
CHECK="$NODE_DIR/check_export.mjs"
T=$(mktemp -d)
trap 'rm -rf "$T"' EXIT
cd "$T" || exit 1
expect_rc() {  # expect_rc CODE command...
  local want=$1; shift
  "$@" >"$T/.stdout" 2>"$T/.stderr"; local rc=$?
  [ "$rc" -eq "$want" ] || { cat "$T/.stderr" >&2; die "'$*' exited $rc, expected $want"; }
}
extras() {  # extras FILE.glb FIELD: a number from asset.extras.keyanim
  node -e 'const b=require("fs").readFileSync(process.argv[1]);const n=b.readUInt32LE(12);
           console.log(JSON.parse(b.subarray(20,20+n)).asset.extras.keyanim[process.argv[2]])' "$1" "$2"
}

case "$CASE" in
cli)
  WALK="$DIR/cmu_02_01_walk.bvh"; HOP="$DIR/cmu_131_03_hop.bvh"
  expect_rc 0 "$K" encode "$WALK" -o walk.kanim --error 0.05%
  expect_rc 0 "$K" encode "$HOP" -o hop.kanim --error 0.05%
  expect_rc 0 "$K" decode walk.kanim -o walk.bvh
  expect_rc 0 "$K" decode hop.kanim -o hop.bvh
  # By extension: .glb, and .gltf with its .bin; --to gltf names the output IN.glb.
  expect_rc 0 "$K" decode walk.kanim -o walk.glb
  grep -q 'walk.kanim -> walk.glb: .* error max .* tolerance' .stderr || die "no summary: $(cat .stderr)"
  expect_rc 0 "$K" decode walk.kanim -o "split walk.gltf"
  [ -s "split walk.bin" ] || die ".gltf output wrote no .bin"
  grep -q '"uri":"split%20walk.bin"' "split walk.gltf" || die "the .gltf does not reference its .bin as a URI"
  expect_rc 0 "$K" decode hop.kanim --to gltf
  [ -s hop.glb ] || die "--to gltf did not write hop.glb"
  node "$CHECK" "$WALK" walk.bvh walk.glb "$WALK" walk.bvh "split walk.gltf" "$HOP" hop.bvh hop.glb || die "exports fail their checks"
  # To standard output: a GLB, the same bytes as the file.
  "$K" decode walk.kanim --to gltf -o - >stdout.glb || die "decode to standard output"
  cmp -s stdout.glb walk.glb || die "standard output differs from the .glb"
  # --to bvh wins over the extension.
  expect_rc 0 "$K" decode walk.kanim --to bvh -o really-bvh.glb
  head -c 9 really-bvh.glb | grep -q HIERARCHY || die "--to bvh did not write BVH"
  # --error sets the tolerance (percent of the skeleton size, or units).
  expect_rc 0 "$K" decode walk.kanim -o coarse.glb --error 0.5%
  node -e 'const [a,b]=process.argv.slice(1).map(Number); process.exit(Math.abs(a-10*b)<=1e-4*a?0:1)' \
    "$(extras coarse.glb tolerance)" "$(extras walk.glb tolerance)" || die "--error 0.5% is not ten times the default"
  [ "$(stat -c %s coarse.glb)" -lt "$(stat -c %s walk.glb)" ] || die "a ten times larger tolerance is not smaller"
  expect_rc 0 "$K" decode walk.kanim -o units.glb --error 0.1
  [ "$(extras units.glb tolerance)" = 0.1 ] || die "--error 0.1 gave $(extras units.glb tolerance)"
  # --linear: LINEAR keys only, translations fitted too, still within the tolerance.
  expect_rc 0 "$K" decode hop.kanim -o hop-linear.glb --linear
  node "$CHECK" --linear "$HOP" hop.bvh hop-linear.glb || die "--linear export fails its checks"
  # --fps: LINEAR keys resampled; three.js stays within the error the export reports.
  expect_rc 0 "$K" decode hop.kanim -o hop30.glb --fps 30
  node "$CHECK" --fps "$HOP" hop.bvh hop30.glb || die "--fps export fails its checks"
  # --frames: a range, time 0 at its first frame, checked against the BVH of the same range.
  expect_rc 0 "$K" decode walk.kanim -o range.glb --frames 100:200
  expect_rc 0 "$K" decode walk.kanim -o range.bvh --frames 100:200
  node "$CHECK" range.bvh range.bvh range.glb || die "--frames export fails its checks"
  # Refusals: existing outputs (nothing written, not even the .bin), BVH-only and glTF-only
  # options, a tolerance float32 cannot hold, the input as output.
  expect_rc 4 "$K" decode walk.kanim -o walk.glb
  touch only.gltf
  expect_rc 4 "$K" decode walk.kanim -o only.gltf
  [ ! -e only.bin ] || die "a refused .gltf output still wrote its .bin"
  expect_rc 0 "$K" decode walk.kanim -o walk.glb -f
  expect_rc 1 "$K" decode walk.kanim -o x.glb --inbetweens 2
  expect_rc 1 "$K" decode walk.kanim -o x.bvh --error 0.1
  expect_rc 1 "$K" decode walk.kanim -o x.bvh --linear
  expect_rc 1 "$K" decode walk.kanim -o x.glb --to fbx
  expect_rc 1 "$K" decode walk.kanim -o x.glb --error 1e-12
  grep -q 'float32' .stderr || die "an impossible tolerance is not explained: $(cat .stderr)"
  [ ! -e x.glb ] || die "a failed export left x.glb"
  cp walk.kanim walk.bin
  expect_rc 4 "$K" decode walk.bin -o walk.gltf -f
  cmp -s walk.bin walk.kanim || die "the input was overwritten by the .gltf's buffer"
  echo "glTF CLI cases passed"
  ;;
corpus)
  [ -d "$DIR" ] || { echo "corpus not found at $DIR: glTF corpus tests skipped"; exit 77; }
  triples=(); linear=()
  for pattern in "$@"; do
    for bvh in "$DIR"/$pattern; do
      [ -f "$bvh" ] || continue
      base=$(basename "$bvh" .bvh)
      "$K" -q encode "$bvh" -o "$base.kanim" --error 0.05% || die "encode $bvh"
      "$K" -q decode "$base.kanim" -o "$base.clip.bvh" || die "decode $base.kanim to BVH"
      "$K" decode "$base.kanim" -o "$base.glb" || die "decode $base.kanim to glTF"
      "$K" decode "$base.kanim" -o "$base.linear.glb" --linear || die "decode $base.kanim to glTF --linear"
      triples+=("$bvh" "$base.clip.bvh" "$base.glb")
      linear+=("$bvh" "$base.clip.bvh" "$base.linear.glb")
    done
  done
  [ ${#triples[@]} -gt 0 ] || die "no corpus file matches $*"
  node "$CHECK" --percent 0.05 "${triples[@]}" || die "exports fail their checks"
  node "$CHECK" --percent 0.05 --linear "${linear[@]}" || die "--linear exports fail their checks"
  echo "$(( ${#triples[@]} / 3 )) files: both exports validated and played within tolerance"
  ;;
deep)
  # 300 joints one below the other, each turning a little about all three axes with its own
  # phase: every point's movers are walked in several windows, and the errors of the joints
  # above add up at the tip, so the fit takes many rounds.
  /usr/bin/python3 - chain.bvh 300 30 <<'EOF' || die "writing the chain BVH"
import math, sys
path, n, frames = sys.argv[1], int(sys.argv[2]), int(sys.argv[3])
out = ["HIERARCHY"]
for i in range(n):
    out += [("ROOT" if i == 0 else "JOINT") + " j%d" % i, "{", "OFFSET 0 1 0", "CHANNELS 3 Zrotation Xrotation Yrotation"]
out += ["End Site", "{", "OFFSET 0 1 0", "}"] + ["}"] * n + ["MOTION", "Frames: %d" % frames, "Frame Time: 0.0333333"]
for f in range(frames):
    out.append(" ".join("%.6f %.6f %.6f" % (0.1 * math.sin(0.3 * f + 0.01 * i), 0.05 * math.cos(0.2 * f + 0.03 * i),
                                            0.02 * math.sin(0.1 * f - 0.02 * i)) for i in range(n)))
open(path, "w").write("\n".join(out) + "\n")
EOF
  expect_rc 0 "$K" encode chain.bvh -o chain.kanim --error 0.05%
  expect_rc 0 "$K" decode chain.kanim -o chain.clip.bvh
  expect_rc 0 "$K" decode chain.kanim -o chain.glb
  expect_rc 0 "$K" decode chain.kanim -o chain.linear.glb --linear
  node "$CHECK" --percent 0.05 chain.bvh chain.clip.bvh chain.glb || die "the chain's export fails its checks"
  node "$CHECK" --percent 0.05 --linear chain.bvh chain.clip.bvh chain.linear.glb || die "the chain's --linear export fails its checks"
  echo "a 300-deep chain: both exports validated and played within tolerance"
  ;;
*) die "unknown case $CASE" ;;
esac
