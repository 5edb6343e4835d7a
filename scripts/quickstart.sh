#!/usr/bin/env bash
# First run for a new user: install what is missing (scripts/install-deps.sh: nothing when all is
# there; its exit codes when it cannot), build, install keyanim with its man page, bash completion,
# viewer page and Python module (where /usr/bin/python3 finds it), and put a real CMU walk through
# the whole loop (BVH -> .kanim -> BVH).
#
# Installs in ~/.local (bin/keyanim, share/man/man1/keyanim.1, ...), or /usr/local when run as
# root; KEYANIM_PREFIX=DIR installs in DIR instead. Says so if that bin/ is not on PATH yet.
set -euo pipefail
cd "$(dirname "$0")/.."
KEYANIM_AGAIN=scripts/quickstart.sh scripts/install-deps.sh || exit $?
if [ -n "${KEYANIM_PREFIX:-}" ]; then prefix=$KEYANIM_PREFIX
elif [ "$(id -u)" -eq 0 ]; then prefix=/usr/local
else prefix=$HOME/.local
fi
# The tool, the library, the man page, the viewer and the Python module: what `cmake --install`
# installs. The tests are built by scripts/test.sh.
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release -DKEYANIM_BUILD_TESTS=OFF -DKEYANIM_BUILD_BENCH=OFF >/dev/null
cmake --build build -j"$(nproc)"
# (Quiet, but for where the Python module went when Python does not search there.)
cmake --install build --prefix "$prefix" | { grep '^-- keyanim:' || true; }
K=$prefix/bin/keyanim
echo "keyanim: installed $K"
if [ -z "${KEYANIM_PREFIX:-}" ]; then  # (another prefix: the install said how to set PYTHONPATH)
  /usr/bin/python3 -c 'import keyanim; print("keyanim: Python module", keyanim.__version__, "at", keyanim.__file__)'
fi

mkdir -p out
"$K" info data/cmu_02_01_walk.bvh
"$K" encode -f data/cmu_02_01_walk.bvh -o out/walk.kanim
"$K" decode -f out/walk.kanim -o out/walk.bvh
"$K" info out/walk.kanim

if [ "$(command -v keyanim)" != "$K" ]; then
  echo
  echo "keyanim: $prefix/bin is not on your PATH$(command -v keyanim >/dev/null && echo " before $(command -v keyanim)"). Type:"
  echo "  export PATH=\"$prefix/bin:\$PATH\""
  echo "(and add that line to ~/.profile to keep it); then 'keyanim', 'man keyanim' and tab completion work."
else
  echo
  echo "keyanim: ready: try 'keyanim help', 'man keyanim', or the session in the README."
fi
