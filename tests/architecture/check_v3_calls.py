#!/usr/bin/env python3
"""The runtime's AVX2 copies call no code of another level (internal/cpu.h).

Every function the sources mark KEYANIM_V3_TARGET is found in the built library's disassembly
(objdump -dr); a call or tail jump out of it to anything but the C library's memory functions
(whose copies on an AVX2 machine are AVX code) fails the check: such a callee is compiled for
the baseline, and legacy-SSE code between AVX code costs a transition each way (about 1 us a
pose once, on CMU 01_01).

Usage: check_v3_calls.py LIBRARY.a SOURCE_DIR
       check_v3_calls.py --self-test   (compiles a v3 function that calls out, and one that
                                         does not, and checks that only the first is refused)
"""
import os
import re
import subprocess
import sys
import tempfile

ALLOWED = {"memcpy", "memset", "memmove"}
V3 = re.compile(r"KEYANIM_V3_TARGET\s+[\w:<>]+\s+(\w+)\s*\(")


def v3_names(source_dir):
    names = set()
    for root, _, files in os.walk(source_dir):
        for f in files:
            if f.endswith((".cpp", ".h")):
                with open(os.path.join(root, f), encoding="utf-8") as fh:
                    names.update(V3.findall(fh.read()))
    return names


def calls_out(objdump_text, names):
    """(function, callee) for each call or jump from a function named in `names` to a symbol
    outside it, from objdump -dr output (relocations name the callee)."""
    found, current, previous = [], None, ""
    for line in objdump_text.splitlines():
        m = re.match(r"^[0-9a-f]+ <(.+)>:$", line)
        if m:
            name = m.group(1).replace("(anonymous namespace)::", "")
            base = re.sub(r"\(.*", "", name).split("::")[-1].split(" [clone")[0]
            current = base if base in names else None
            continue
        if current is None:
            previous = line
            continue
        reloc = re.search(r"R_X86_64_(?:PLT32|PC32)\s+(\S+)", line)
        if reloc and re.search(r"\s(call|jmp)\s", previous):
            target = re.sub(r"[-+]0x[0-9a-f]+$", "", reloc.group(1))
            if target.split("@")[0] not in ALLOWED:
                found.append((current, target))
        previous = line
    return found


def check(library, source_dir):
    names = v3_names(source_dir)
    if not names:
        print("check_v3_calls: no KEYANIM_V3_TARGET function in " + source_dir)
        return 1
    text = subprocess.run(["objdump", "-dr", "--no-show-raw-insn", "-C", library], capture_output=True, text=True,
                          check=True).stdout
    seen = {n for n in names if re.search(r"^[0-9a-f]+ <[^>]*\b" + n + r"\(", text, re.M)}
    bad = calls_out(text, names)
    for fn, target in bad:
        print(f"check_v3_calls: {fn} (an AVX2 copy) calls {target}, code of another level: inline it "
              f"(KEYANIM_INLINE) so that each level has its own copy")
    print(f"check_v3_calls: {len(seen)} AVX2 copies in {os.path.basename(library)}, {len(bad)} calls out")
    return 1 if bad or not seen else 0


def self_test():
    src = r'''
#define KEYANIM_V3_TARGET [[gnu::target("avx2")]]
[[gnu::noinline]] float helper(float x) { return x * 3.0f + 1.0f; }
KEYANIM_V3_TARGET float bad_v3(float x) { return helper(x) * 2.0f; }
KEYANIM_V3_TARGET void good_v3(float* x, int n) { for (int i = 0; i < n; ++i) x[i] *= 2.0f; }
'''
    with tempfile.TemporaryDirectory() as d:
        with open(os.path.join(d, "t.cpp"), "w") as f:
            f.write(src)
        obj = os.path.join(d, "t.o")
        subprocess.run(["c++", "-O2", "-std=c++20", "-fno-inline", "-c", os.path.join(d, "t.cpp"), "-o", obj], check=True)
        text = subprocess.run(["objdump", "-dr", "--no-show-raw-insn", "-C", obj], capture_output=True, text=True,
                              check=True).stdout
        bad = calls_out(text, v3_names(d))
        ok = [fn for fn, _ in bad] == ["bad_v3"] and "helper" in bad[0][1]
    print("check_v3_calls self-test: " + ("ok" if ok else f"FAILED, found {bad}"))
    return 0 if ok else 1


if __name__ == "__main__":
    if sys.argv[1:] == ["--self-test"]:
        sys.exit(self_test())
    if len(sys.argv) != 3:
        print(__doc__)
        sys.exit(2)
    sys.exit(check(sys.argv[1], sys.argv[2]))
