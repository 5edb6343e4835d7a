#!/usr/bin/env python3
"""The README's sessions, pasted line by line: readme_session.py [--write] README.md

Runs, in the current directory and in order, every command of every session block of the README
(a fenced block whose lines start with "$ ": the command, then what it prints), with bash, as a
user pasting them would. What the command prints (standard output and error together) must be
what the README shows (nothing when it shows nothing), compared word by word per line, except the timing columns
of a table whose header ends in "enc ms  dec ms". Exits 1 on the first command that fails or
prints something else, showing both. With --write (for the maintainer who changed what a
command prints), every output the README shows is replaced by what the command printed instead.
"""
import re
import subprocess
import sys

TIMING_HEADER = re.compile(r"enc ms\s+dec ms\s*$")


def parse(lines):
    """[(command, [lines the README shows it print], (first, end))] of every session block (a
    fenced block whose first line starts with '$ '), in order; lines[first:end] are the shown
    output's lines."""
    result = []
    in_block, is_session, first = False, False, False
    for i, line in enumerate(lines):
        if line.startswith("```"):
            in_block, is_session, first = not in_block, False, True
            continue
        if not in_block:
            continue
        if first:
            is_session, first = line.startswith("$ "), False
        if not is_session:
            continue
        if line.startswith("$ "):
            result.append((line[2:], [], (i + 1, i + 1)))
        else:
            command, shown, (start, _) = result[-1]
            shown.append(line)
            result[-1] = (command, shown, (start, i + 1))
    return result


def rewrite(readme, lines, commands, printed):
    """The README with the output shown under each session command replaced by what it printed
    (printed[i] for the i-th command)."""
    out, at = [], 0
    for (_, shown, (start, end)), actual in zip(commands, printed):
        out += lines[at:start] + actual
        at = end
    out += lines[at:]
    with open(readme, "w", encoding="utf-8") as f:
        f.write("\n".join(out) + "\n")


def words(line, timing, header):
    w = line.split()
    if timing:
        w = w[:-4] if header else w[:-2]
    return w


def same(expected, actual):
    if len(expected) != len(actual):
        return False
    timing = False
    for e, a in zip(expected, actual):
        header = bool(TIMING_HEADER.search(e))
        timing = timing or header
        if words(e, timing, header) != words(a, timing, header):
            return False
    return True


def main():
    write = sys.argv[1:2] == ["--write"]
    readme = sys.argv[-1]
    lines = open(readme, encoding="utf-8").read().splitlines()
    commands = parse(lines)
    if not commands:
        print("FAIL: no session in", readme)
        return 1
    printed = []
    for command, expected, _ in commands:
        p = subprocess.run(["bash", "-c", command], stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                           text=True, timeout=600)
        actual = p.stdout.rstrip("\n").split("\n") if p.stdout.strip() else []
        printed.append(actual)
        print("$", command)
        print(p.stdout, end="")
        if p.returncode != 0:
            print(f"FAIL: exit {p.returncode}")
            return 1
        if not write and not same(expected, actual):  # printing what the README leaves out is a drift too
            print("FAIL: the README shows:")
            print("\n".join(expected))
            return 1
    if write:
        rewrite(readme, lines, commands, printed)
        print(f"readme session: {readme} shows what its {len(commands)} commands print now")
        return 0
    print(f"readme session: {len(commands)} commands as the README shows them")
    return 0


if __name__ == "__main__":
    sys.exit(main())
