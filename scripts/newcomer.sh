#!/usr/bin/env bash
# A new user's first minutes, as a script (issue 16). CI runs it after scripts/test.sh (.ci/run).
# It builds twice from scratch (the set-up's build, then the test suite's), a few minutes on two
# cores, so it is a CI step rather than a CTest test that every local run would pay for. Locally:
# scripts/newcomer.sh (it clones the committed HEAD: commit first).
#  1. a fresh clone of this repository in a scratch directory, with no ../shared beside it;
#  2. the README's set-up command (the ```sh block under "Quick start"), as written, installing
#     into a scratch prefix (KEYANIM_PREFIX: an installed keyanim is left alone), with that
#     prefix's bin/ on PATH as the set-up asks;
#  3. every session of the README (blocks of "$ " lines) pasted line by line, printing what the
#     README shows (tests/newcomer/readme_session.py), leaving nothing in the checkout (they
#     write under the ignored scratch/); outputs named for another format (walk.fbx) refused;
#  4. every command's --help read for options described twice and incomplete usage lines, and
#     the README's usage block against it (tests/cli/help_test.py); `man keyanim`, the bash
#     completion and `import keyanim` found; the README's glTF sizes of data/ remade
#     (tests/docs/gltf_table_check.py);
#  5. the README's test command, without its sanitizer stage: CTest must report the corpus tests
#     as skipped with their reason, and no test may pass without checking anything
#     (tests/ctest_report.py).
set -euo pipefail
here=$(cd "$(dirname "$0")/.." && pwd)
PY=/usr/bin/python3
[ -x "$PY" ] || PY=python3
T=$(mktemp -d "${TMPDIR:-/tmp}/keyanim-newcomer.XXXXXX")
trap 'rm -rf "$T"' EXIT
export TMPDIR=$T/tmp  # what the commands leave in the temporary directory (keyanim view's page) goes too
mkdir "$TMPDIR"
step() { printf '\nnewcomer: %s\n' "$*"; }
# block HEADING PATTERN: the first ```sh block after the README heading, that holds PATTERN.
block() { awk -v h="$1" -v p="$2" '$0 ~ "^## " h {s=1} s && /^```sh/ {b=1; t=""; next}
                                    b && /^```/ {if (t ~ p) {printf "%s", t; exit} b=0; next} b {t = t $0 "\n"}' README.md; }

step "1. a fresh clone of $(git -C "$here" rev-parse --short HEAD), with no ../shared beside it"
[ -z "$(git -C "$here" status --porcelain --untracked-files=no)" ] ||
  echo "newcomer: note: uncommitted changes in $here are not in the clone"
git clone -q "$here" "$T/keyanim"
[ ! -e "$T/shared" ] || { echo "newcomer: FAIL: $T/shared exists"; exit 1; }
cd "$T/keyanim"

step "2. the README's set-up command"
setup=$(block "Quick start" "quickstart")
[ -n "$setup" ] || { echo "newcomer: FAIL: no set-up command under the README's Quick start"; exit 1; }
printf '%s\n' "$setup"
export KEYANIM_PREFIX=$T/prefix
bash -euo pipefail -c "$setup"
export PATH="$KEYANIM_PREFIX/bin:$PATH"
[ "$(command -v keyanim)" = "$KEYANIM_PREFIX/bin/keyanim" ] || { echo "newcomer: FAIL: keyanim is not installed"; exit 1; }

step "3. the README's sessions, pasted line by line"
"$PY" tests/newcomer/readme_session.py README.md
# They write under scratch/, which git ignores: nothing is left in the checkout (issue 28, item 19).
left=$(git status --porcelain --untracked-files=all)
[ -z "$left" ] || { echo "newcomer: FAIL: the README's sessions left files in the checkout:"; echo "$left"; exit 1; }
echo "the sessions left nothing in the checkout"
# An output named for another format is refused, naming the file and the extension to use, and
# nothing is written (issue 28, item 12): what a user who types walk.fbx or out.bvh gets.
refused() {  # refused FILE EXT command...
  local file=$1 ext=$2 rc=0; shift 2
  "$@" 2>"$T/refused.err" || rc=$?
  [ "$rc" -eq 1 ] && grep -q "$file: this writes .*name it $ext" "$T/refused.err" && [ ! -e "$file" ] ||
    { echo "newcomer: FAIL: '$*' exited $rc (expected 1, naming $file and $ext): $(cat "$T/refused.err")"; exit 1; }
}
refused scratch/walk.fbx .bvh keyanim decode scratch/walk.kanim -o scratch/walk.fbx
refused scratch/out.bvh .kanim keyanim encode data/cmu_02_01_walk.bvh -o scratch/out.bvh
refused scratch/curve.png .svg keyanim plot data/cmu_02_01_walk.bvh --channel Hips:Xrotation -o scratch/curve.png
echo "outputs named for another format are refused: $(head -n1 "$T/refused.err")"

step "4. every command's help; man keyanim; bash completion; import keyanim"
"$PY" tests/cli/help_test.py "$(command -v keyanim)" README.md
"$PY" tests/docs/gltf_table_check.py "$(command -v keyanim)" .  # the README's glTF sizes of data/
man -w keyanim | grep -q "^$KEYANIM_PREFIX/" || { echo "newcomer: FAIL: man keyanim does not find the installed page"; exit 1; }
[ -f "$KEYANIM_PREFIX/share/bash-completion/completions/keyanim" ] || { echo "newcomer: FAIL: no bash completion installed"; exit 1; }
echo "man page and completion installed"
# The Python module: in the prefix's site-packages, which the install named (a scratch prefix is
# not on Python's path; ~/.local and /usr/local are: python/tests/install_test.sh).
site=$(ls -d "$KEYANIM_PREFIX"/lib/python3*/site-packages 2>/dev/null | head -n1)
[ -f "$site/keyanim/__init__.py" ] || { echo "newcomer: FAIL: no Python module installed in $KEYANIM_PREFIX"; exit 1; }
PYTHONPATH=$site /usr/bin/python3 -c 'import keyanim, sys; assert keyanim.__file__.startswith(sys.argv[1]); print("Python module", keyanim.__version__, "installed")' "$site" ||
  { echo "newcomer: FAIL: /usr/bin/python3 cannot import the installed keyanim"; exit 1; }

step "5. the README's test command, without the sanitizer stage"
tests=$(block "Running the tests" "scripts/test.sh")
[ -n "$tests" ] || { echo "newcomer: FAIL: no test command in the README"; exit 1; }
printf '%s\n' "$tests"
KEYANIM_SKIP_SANITIZE=1 KEYANIM_PROPERTY_SECONDS=10 bash -euo pipefail -c "$tests" 2>&1 | tee "$T/test.log"
grep -q "corpus not found beside the checkout: the corpus tests listed as Skipped above did not run" "$T/test.log" ||
  { echo "newcomer: FAIL: the test command does not say why tests were skipped"; exit 1; }
# The README's quick command leaves out the corpus tests by a filter: every test skipped here
# (no corpus) must be one that filter names.
filter=$(grep -o "ctest --test-dir build -j2 -E '[^']*'" README.md | head -n1 | sed "s/.*-E '\\(.*\\)'/\\1/")
[ -n "$filter" ] || { echo "newcomer: FAIL: no quick ctest filter in the README"; exit 1; }
"$PY" tests/ctest_report.py build/ctest-results.xml --expect-skips --skips-match "$filter"
step "ok"
