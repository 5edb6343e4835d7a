#!/usr/bin/env python3
"""symbols_test.py keyanim.h libkeyanim_c.so: the library exports exactly the functions the
header declares with KEYANIM_C_API (nm -D --defined-only), nothing of the C++ runtime inside it,
and its SONAME carries the version (readelf -d)."""
import re
import subprocess
import sys


def main():
    header, lib = sys.argv[1:3]
    with open(header) as f:
        text = re.sub(r"/\*.*?\*/", "", f.read(), flags=re.S)
    declared = set(re.findall(r"KEYANIM_C_API[^;(]*?\b(keyanim_\w+)\s*\(", text))
    nm = subprocess.run(["nm", "-D", "--defined-only", lib], check=True, capture_output=True, text=True).stdout
    exported = {line.split()[-1] for line in nm.splitlines() if line.strip()}
    problems = [f"exported but not declared: {s}" for s in sorted(exported - declared)]
    problems += [f"declared but not exported: {s}" for s in sorted(declared - exported)]
    dyn = subprocess.run(["readelf", "-d", lib], check=True, capture_output=True, text=True).stdout
    soname = re.search(r"Library soname: \[([^\]]+)\]", dyn)
    if not soname or not re.fullmatch(r"libkeyanim_c\.so\.\d+\.\d+", soname.group(1)):
        problems.append(f"SONAME: {soname.group(1) if soname else 'none'}, expected libkeyanim_c.so.MAJOR.MINOR")
    for p in problems:
        print(p)
    print(f"symbols: {len(declared)} declared, {len(exported)} exported, {len(problems)} problem(s)")
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
