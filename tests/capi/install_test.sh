#!/usr/bin/env bash
# install_test.sh BUILD_DIR EXAMPLE.c CLIP.kanim: what `cmake --install` gives a C user, from a
# scratch prefix (moved after installing, since keyanim-c.pc finds its prefix from its place):
# examples/c/sample_clip.c compiled with pkg-config's keyanim-c flags alone, and through CMake's
# find_package(keyanim) + keyanim::c; both run on the clip with the library found by its
# SONAME from the prefix's lib/; the installed header compiles as C99 and as C++.
set -uo pipefail
BUILD=$(realpath "$1"); EXAMPLE=$(realpath "$2"); CLIP=$(realpath "$3")
T=$(mktemp -d); trap 'rm -rf "$T"' EXIT
die() { echo "FAIL: $*" >&2; exit 1; }
cmake --install "$BUILD" --prefix "$T/first" >"$T/install.log" 2>&1 || { cat "$T/install.log"; die "cmake --install"; }
mv "$T/first" "$T/prefix"
P=$T/prefix
pc=$(find "$P" -name keyanim-c.pc)
[ -n "$pc" ] || die "no keyanim-c.pc installed"
export PKG_CONFIG_PATH=$(dirname "$pc")
pkg-config --exists keyanim-c || die "pkg-config does not find keyanim-c"
[ -n "$(pkg-config --modversion keyanim-c)" ] || die "keyanim-c.pc has no version"
flags=$(pkg-config --cflags --libs keyanim-c)
case "$flags" in *"$P/"*) ;; *) die "pkg-config's flags do not point into the moved prefix: $flags" ;; esac
libdir=$(pkg-config --variable=libdir keyanim-c)
# shellcheck disable=SC2086
cc -std=c99 -pedantic -Wall -Wextra -Werror "$EXAMPLE" $flags -o "$T/pc_example" || die "compiling with pkg-config's flags: $flags"
LD_LIBRARY_PATH=$libdir "$T/pc_example" "$CLIP" 3.5 >"$T/pc.out" || die "the pkg-config build does not run"
grep -q '^at frame 3.5$' "$T/pc.out" || die "the pkg-config build printed no sample"
readelf -d "$T/pc_example" | grep -q 'NEEDED.*libkeyanim_c\.so\.[0-9]*\.[0-9]*\]' || die "the program does not need the SONAME"
# The header alone, in C++ too (extern "C").
echo '#include <keyanim.h>
int main(void) { return keyanim_status_name(0)[0] == 0; }' >"$T/h.c"
cc -std=c99 -pedantic -Werror -I"$P/include" -fsyntax-only "$T/h.c" || die "keyanim.h as C99"
c++ -x c++ -std=c++11 -pedantic -Werror -I"$P/include" -fsyntax-only "$T/h.c" || die "keyanim.h as C++"
# CMake: find_package(keyanim) and keyanim::c.
mkdir "$T/consumer"
cat >"$T/consumer/CMakeLists.txt" <<CMAKE
cmake_minimum_required(VERSION 3.25)
project(consumer LANGUAGES C CXX)
find_package(keyanim 0.2 REQUIRED)
add_executable(sample_clip "$EXAMPLE")
target_link_libraries(sample_clip PRIVATE keyanim::c)
CMAKE
cmake -S "$T/consumer" -B "$T/consumer/build" -DCMAKE_PREFIX_PATH="$P" >"$T/cmake.log" 2>&1 || { cat "$T/cmake.log"; die "configuring a find_package(keyanim) consumer"; }
cmake --build "$T/consumer/build" >"$T/build.log" 2>&1 || { cat "$T/build.log"; die "building against keyanim::c"; }
"$T/consumer/build/sample_clip" "$CLIP" 3.5 >"$T/cmake.out" || die "the CMake build does not run"
cmp -s "$T/pc.out" "$T/cmake.out" || die "the two builds print different samples"
echo "ok: pkg-config and find_package(keyanim) builds of sample_clip.c agree ($(wc -l <"$T/pc.out") lines)"
