#!/usr/bin/env bash
# `cmake --install` puts the Python package where /usr/bin/python3 finds it for the prefix
# (python/install_module.cmake), checked without touching this machine's own directories:
#   - a user base (PYTHONUSERBASE, as ~/.local): the user site-packages; `import keyanim` then
#     works from anywhere with no PYTHONPATH;
#   - /usr/local, staged under DESTDIR: the directory must be on the interpreter's sys.path;
#   - any other prefix: PREFIX/lib/python3.X/site-packages, with a message saying to set
#     PYTHONPATH, after which the import works.
# usage: install_test.sh BUILD_DIR PYTHON
set -euo pipefail
B=$(realpath "$1"); PY=$2
WALK=$(realpath "$(dirname "$0")/../../data/cmu_02_01_walk.bvh")
T=$(mktemp -d); trap 'rm -rf "$T"' EXIT
cd "$T"
die() { echo "FAIL: $*" >&2; exit 1; }
ver=$("$PY" -c 'import sys; print("%d.%d" % sys.version_info[:2])')

# 1. A user base.
PYTHONUSERBASE=$T/user cmake --install "$B" --component python --prefix "$T/user" >install1.log
site=$T/user/lib/python$ver/site-packages
[ -f "$site/keyanim/__init__.py" ] && ls "$site"/keyanim/_keyanim*.so >/dev/null || die "not in the user site-packages $site"
got=$(env -u PYTHONPATH PYTHONUSERBASE="$T/user" "$PY" -c 'import keyanim; print(keyanim.__file__)')
[ "$got" = "$site/keyanim/__init__.py" ] || die "import keyanim found $got"
env -u PYTHONPATH PYTHONUSERBASE="$T/user" "$PY" -c 'import keyanim, numpy; m = keyanim.read_bvh("'"$WALK"'"); assert m.frame_count == 344'

# 2. /usr/local, staged.
DESTDIR=$T/stage cmake --install "$B" --component python --prefix /usr/local >install2.log
dir=$(cd "$T/stage/usr/local" && ls -d lib/python3*/*-packages/keyanim)
dir=/usr/local/${dir%/keyanim}
"$PY" -c 'import sys; assert sys.argv[1] in sys.path, sys.argv[1]' "$dir" || die "$dir is not on $PY's sys.path"

# 3. Another prefix: installed, and the message says how to find it.
cmake --install "$B" --component python --prefix "$T/opt" >install3.log
other=$T/opt/lib/python$ver/site-packages
[ -f "$other/keyanim/__init__.py" ] || die "not in $other"
grep -q "export PYTHONPATH=\"$other\"" install3.log || die "no PYTHONPATH advice: $(cat install3.log)"
got=$(PYTHONPATH=$other "$PY" -c 'import keyanim; print(keyanim.__file__)')
[ "$got" = "$other/keyanim/__init__.py" ] || die "with PYTHONPATH, import keyanim found $got"
echo "ok: user base, /usr/local (staged) and another prefix"
