#!/usr/bin/env python3
"""What CTest's JUnit report (ctest --output-junit) says about skipped tests, for scripts/test.sh
and scripts/newcomer.sh: ctest_report.py RESULTS.xml [--expect-skips]

Lists the skipped tests with their reason (the line of their output that says why), and fails
when a test passed without checking anything, which is how a skip that reports itself as a pass
looks, or a doctest case whose name CTest cut at a ';' (its filter then matches nothing): a
doctest case with no assertion ("assertions: 0"), a node:test file with no passing test
("# pass 0"). With --expect-skips (a clone without ../shared), at least one test must be
skipped; with --skips-match REGEX, every test skipped for want of the corpus (its reason names
it) must have a name REGEX matches (the README's filter for the quick run, so that its "all but
the tests over the corpus" is true).
"""
import re
import sys
import xml.etree.ElementTree as ET

EMPTY_PASS = (re.compile(r"\[doctest\] assertions:\s+0 \|"), re.compile(r"^# pass 0$", re.M))
REASON = re.compile(r"keyanim-corpus-skip: .*|# SKIP.*|^# .*\bskip\b.*", re.M)


def main():
    root = ET.parse(sys.argv[1]).getroot()
    skipped, empty, failed = [], [], []
    for case in root.iter("testcase"):
        name, status = case.get("name"), case.get("status")
        out = case.findtext("system-out") or ""
        if case.find("skipped") is not None or status in ("notrun", "skipped", "disabled"):
            reason = REASON.search(out)
            last = [l for l in out.splitlines() if l.strip()][-1:]  # else: a script's last word
            skipped.append((name, reason.group(0).strip() if reason else last[0] if last else "(no reason printed)"))
        elif case.find("failure") is not None or status == "fail":
            failed.append(name)
        elif any(p.search(out) for p in EMPTY_PASS):
            empty.append(name)
    for name, reason in skipped:
        print(f"skipped: {name}: {reason}")
    for name in empty:
        print(f"FAIL: '{name}' passed without checking anything (a skip reported as a pass?)")
    for name in failed:
        print(f"FAIL: '{name}' failed")
    if "--skips-match" in sys.argv:
        pattern = re.compile(sys.argv[sys.argv.index("--skips-match") + 1])
        for name, reason in skipped:
            if "corpus" in reason.lower() and not pattern.search(name):
                print(f"FAIL: skipped test '{name}' is not matched by the README's filter '{pattern.pattern}'")
                failed.append(name)
    if "--expect-skips" in sys.argv and not skipped:
        print("FAIL: no test was skipped, yet the corpus is absent")
        return 1
    print(f"{len(skipped)} skipped, {len(empty)} passed without a check, {len(failed)} failed")
    return 1 if empty or failed else 0


if __name__ == "__main__":
    sys.exit(main())
