#!/usr/bin/env bash
# Runs one Blender check of the add-on (tests/blender/check_*.py) headless:
#   run.sh KEYANIM_CLI MODULE_DIR CHECK.py FILE...
# in a temporary directory, with Blender's factory settings (no user add-ons or preferences),
# the add-on enabled from this checkout and the keyanim module from MODULE_DIR (the build tree's
# build/python, through KEYANIM_PYTHONPATH, the add-on's override). Exit 77 (CTest: skipped)
# when blender is not installed, or when an input is missing (the corpus, outside the checkout).
set -uo pipefail
HERE=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
cli=$1 module_dir=$2 check=$3; shift 3
command -v blender >/dev/null || { echo "# SKIP blender not found: install it (scripts/install-deps.sh)"; exit 77; }
for f in "$@"; do
  [ -e "$f" ] || { echo "keyanim-corpus-skip: $f not found"; exit 77; }
done
T=$(mktemp -d)
trap 'rm -rf "$T"' EXIT
KEYANIM_CLI=$cli KEYANIM_PYTHONPATH=$module_dir PYTHONDONTWRITEBYTECODE=1 \
  blender -b --factory-startup --python-exit-code 1 -P "$HERE/$check" -- "$T" "$@" >"$T/log" 2>&1
rc=$?
# Blender's own lines (version, "Read ...", "Blender quit") are noise; the checks' lines stay.
grep -v '^Blender \|^Read \|^Blender quit$\|^$' "$T/log"
[ $rc -eq 0 ] || echo "FAIL: blender exited $rc"
exit $rc
