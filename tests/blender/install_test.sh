#!/usr/bin/env bash
# blender_install: the README's animator path, for a user whose home is a temporary directory
# (nothing of this machine's own Blender set-up is touched):
#   install_test.sh BUILD_DIR KEYANIM_CLI
# the module installed as scripts/quickstart.sh installs it for a user (cmake --install --prefix
# ~/.local: the user site-packages), the add-on by tools/blender/install.sh; then a Blender
# started with that user's preferences (not --factory-startup) has the add-on enabled, finds the
# module without any override, and imports the shipped walk's .kanim through File > Import >
# keyanim: 344 frames at 120 fps, LeftHand where `keyanim sample --world` puts it. Exit 77
# (skipped) without blender.
set -uo pipefail
HERE=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
REPO=$(cd "$HERE/../.." && pwd)
B=$(realpath "$1"); K=$(realpath "$2")
command -v blender >/dev/null || { echo "# SKIP blender not found: install it (scripts/install-deps.sh)"; exit 77; }
T=$(mktemp -d); trap 'rm -rf "$T"' EXIT
die() { echo "FAIL: $*"; exit 1; }
export HOME=$T/home
mkdir -p "$HOME"
unset KEYANIM_PYTHONPATH PYTHONPATH PYTHONUSERBASE BLENDER_USER_CONFIG BLENDER_USER_SCRIPTS
cmake --install "$B" --component python --prefix "$HOME/.local" >"$T/cmake.log" || { cat "$T/cmake.log"; die "cmake --install"; }
out=$("$REPO/tools/blender/install.sh" 2>&1) || die "install.sh exited $?: $out"
echo "$out"
case "$out" in *"keyanim module in $HOME/.local/lib/python3"*"site-packages/keyanim"*) ;;
  *) die "install.sh did not find the module in the user site-packages" ;; esac
"$K" -q encode "$REPO/data/cmu_02_01_walk.bvh" -o "$T/walk.kanim" || die "keyanim encode"
ref=$("$K" sample "$T/walk.kanim" --frame 171 --joint LeftHand --world --json) || die "keyanim sample"
blender -b --python-exit-code 1 --python-expr "
import json, math, sys, addon_utils, bpy
from mathutils import Matrix
assert addon_utils.check('keyanim_blender') == (True, True), 'the add-on is not enabled'
assert bpy.ops.import_anim.keyanim(filepath='$T/walk.kanim') == {'FINISHED'}
s, obj = bpy.context.scene, bpy.context.active_object
assert (s.render.fps, s.render.fps_base, s.frame_start, s.frame_end) == (120, 1.0, 1, 344), (s.render.fps, s.frame_end)
s.frame_set(172)
head = Matrix.Rotation(-math.pi / 2, 4, 'X') @ obj.matrix_world @ obj.pose.bones['LeftHand'].head
want = json.loads('$ref')['joints'][0]['position']
d = math.dist(tuple(head), want)
print('LeftHand at frame 171: %.3g from keyanim sample --world' % d)
assert d < 1e-4, d
" >"$T/blender.log" 2>&1 || { cat "$T/blender.log"; die "Blender with the installed add-on"; }
grep '^LeftHand' "$T/blender.log"
echo "ok: the add-on installed by tools/blender/install.sh imports a .kanim with the module the user installed"
