# The prologue that blender_check.sh and blender_skin_check.sh share, sourced with the tool as
# $1: HERE (this folder), K (the tool, absolute), T (a temporary folder, removed at exit) and
# status = 0. Exits 77 (CTest's skip) when blender is not installed.
set -uo pipefail
HERE=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
K=$(realpath "$1")
command -v blender >/dev/null || { echo "blender not found: Blender check skipped"; exit 77; }
T=$(mktemp -d)
trap 'rm -rf "$T"' EXIT
status=0
