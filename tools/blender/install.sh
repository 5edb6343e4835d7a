#!/usr/bin/env bash
# Installs the keyanim Blender add-on for this user and enables it:
#   tools/blender/install.sh [--link]
# Copies keyanim_blender/ into Blender's user add-on folder (~/.config/blender/3.X/scripts/addons,
# as Blender itself names it; --link makes a symbolic link to this checkout instead, for
# working on the add-on), enables it in the saved preferences, then says where Blender finds the
# keyanim Python module (installed by scripts/quickstart.sh; KEYANIM_PYTHONPATH or the add-on's
# preference point at another). Exit codes: 0 installed and the module found; 1 usage;
# 2 blender not found; 3 installed, but the module not found (the message says what to do);
# 4 the add-on folder could not be written.
set -uo pipefail
HERE=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
say() { echo "keyanim: $*" >&2; }
link=0
case "${1-}" in
  "") ;;
  --link) link=1 ;;
  *) say "usage: tools/blender/install.sh [--link]"; exit 1 ;;
esac
command -v blender >/dev/null || { say "blender not found: install it (Debian: apt-get install blender)"; exit 2; }
# Blender's answers are marked lines among its own output.
ask() { blender -b "$@" 2>&1 | sed -n 's/^KEYANIM=//p'; }
dir=$(ask --factory-startup --python-expr \
  "import bpy; print('KEYANIM=' + bpy.utils.user_resource('SCRIPTS', path='addons', create=True))")
[ -n "$dir" ] || { say "Blender did not name its user add-on folder"; exit 4; }
dest="$dir/keyanim_blender"
rm -rf "$dest" || { say "cannot replace $dest"; exit 4; }  # an earlier copy or link of this add-on
if [ $link = 1 ]; then ln -s "$HERE/keyanim_blender" "$dest"; else cp -R "$HERE/keyanim_blender" "$dest"; fi ||
  { say "cannot write $dest"; exit 4; }
find "$dest/" -name __pycache__ -prune -exec rm -rf {} + 2>/dev/null
# Enabled in the user's saved preferences (no --factory-startup: those are the ones saved).
found=$(ask --python-expr "import addon_utils, bpy
addon_utils.enable('keyanim_blender', default_set=True, persistent=True)
bpy.ops.wm.save_userpref()
from keyanim_blender import module
try:
    print('KEYANIM=' + module.load().__file__)
except ImportError as e:
    print('KEYANIM=missing: ' + str(e))")
echo "keyanim: the Blender add-on is in $dest ($([ $link = 1 ] && echo linked || echo copied)) and enabled"
case "$found" in
  missing:*) say "${found#missing: }"; exit 3 ;;
  "") say "Blender did not confirm that it enabled the add-on"; exit 4 ;;
  *) echo "keyanim: it uses the keyanim module in $(dirname "$found")" ;;
esac
