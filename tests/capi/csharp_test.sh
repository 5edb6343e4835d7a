#!/usr/bin/env bash
# csharp_test.sh EXAMPLE_DIR LIBDIR WORKDIR CLIP POSITION...: compiles examples/csharp with
# Debian's mcs and runs it with mono on libkeyanim_c.so from LIBDIR (compare.py checks what it
# prints). Exit 77 (skipped) when mcs or mono is absent.
set -uo pipefail
src=$1 libdir=$2 work=$3; shift 3
for tool in mcs mono; do
  if ! command -v $tool >/dev/null; then
    echo "SKIP: $tool not found: the C# example needs Debian's mono-mcs and mono-runtime (scripts/install-deps.sh)"
    exit 77
  fi
done
mkdir -p "$work"
exe=$(mktemp "$work/SampleClip.XXXXXX.exe")
trap 'rm -f "$exe"' EXIT
mcs -warnaserror -out:"$exe" "$src/SampleClip.cs" >&2 || { echo "mcs failed"; exit 1; }
LD_LIBRARY_PATH="$libdir${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}" mono "$exe" "$@"
