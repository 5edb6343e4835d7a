#!/usr/bin/env python3
"""Progress on long work: progress_test.py KEYANIM DATA_DIR

Standard error is a pseudo-terminal and standard output a pipe, as when a user runs keyanim in
a terminal (or pipes its JSON). A long encode shows its stages (parsing, fitting, verifying with
the round, measuring, compressing), a bar, a percentage and the time left, and erases the line
before its summary; a decode and a directory show theirs. Nothing of it appears when standard
error is not a terminal, or with -q; with --json, standard output holds the JSON alone.
"""
import json
import os
import pty
import re
import select
import shutil
import subprocess
import sys
import tempfile
import time

CSI_ERASE = "\x1b[K"


def run(args, tty=True):
    """Runs keyanim with stderr on a pseudo-terminal (or a pipe); returns (code, stdout, stderr)."""
    if not tty:
        p = subprocess.run(args, capture_output=True, text=True, timeout=600)
        return p.returncode, p.stdout, p.stderr
    master, slave = pty.openpty()
    p = subprocess.Popen(args, stdout=subprocess.PIPE, stderr=slave, stdin=subprocess.DEVNULL)
    os.close(slave)
    err = b""
    while True:  # read the terminal until the process has closed it
        ready, _, _ = select.select([master], [], [], 600)
        if not ready:
            p.kill()
            raise RuntimeError("keyanim hangs")
        try:
            chunk = os.read(master, 65536)
        except OSError:  # EIO: no writer left
            break
        if not chunk:
            break
        err += chunk
    out = p.stdout.read().decode()
    p.wait()
    os.close(master)
    return p.returncode, out, err.decode(errors="replace").replace("\r\n", "\n")


def long_clip(source, path, copies):
    """The source clip's motion `copies` times over (a longer take of the same walk)."""
    text = open(source).read().replace("\r\n", "\n")
    head, motion = text.split("MOTION\n", 1)
    lines = motion.split("\n")
    frames = [l for l in lines[2:] if l.strip()]
    with open(path, "w") as f:
        f.write(head + "MOTION\nFrames: %d\n%s\n" % (len(frames) * copies, lines[1]))
        for _ in range(copies):
            f.write("\n".join(frames) + "\n")


def main():
    keyanim, data = os.path.abspath(sys.argv[1]), os.path.abspath(sys.argv[2])
    walk = os.path.join(data, "cmu_02_01_walk.bvh")
    failures = []

    def check(ok, message):
        if not ok:
            failures.append(message)
            print("FAIL:", message)

    tmp = tempfile.mkdtemp()
    try:
        big = os.path.join(tmp, "long.bvh")
        long_clip(walk, big, 60)  # 20640 frames: a few seconds of work, enough for a time left
        k = os.path.join(tmp, "long.kanim")

        start = time.monotonic()
        code, out, err = run([keyanim, "encode", big, "-o", k, "-j", "1"])
        seconds = time.monotonic() - start
        check(code == 0, f"encode under a terminal: exit {code}: {err[-500:]}")
        lines = err.split("\r")
        for stage in ("parsing", "fitting, round 0", "verifying, round 1", "measuring", "compressing"):
            check(any(f"long.bvh: {stage}  [" in l for l in lines), f"encode: no '{stage}' stage shown")
        # The time left is shown once a second of work is measured (and before the work is done).
        check(seconds < 2 or any(re.search(r"\] +\d+%  \d+:\d\d left", l) for l in lines),
              f"encode: no percentage with a time left in {seconds:.1f} s")
        percents = [int(m.group(1)) for m in re.finditer(r"\] +(\d+)%", err)]
        check(percents == sorted(percents), f"encode: the percentage goes back: {percents}")
        summary = err.rsplit("\r", 1)[-1]
        check(summary.startswith(CSI_ERASE) and "long.bvh -> " in summary[len(CSI_ERASE):] and "[" not in summary[len(CSI_ERASE):],
              f"encode: the bar is not erased before the summary: {summary!r}")
        check(out == "", f"encode: standard output should be empty: {out!r}")

        # The shorter runs: the shipped walk.
        k = os.path.join(tmp, "walk.kanim")
        code, out, err = run([keyanim, "encode", walk, "-o", k, "--json"])
        check(code == 0 and "fitting" in err, f"encode --json under a terminal: exit {code}, no progress")
        try:
            check(json.loads(out)["frames"] == 344, "encode --json: wrong frame count")
        except ValueError:
            check(False, f"encode --json: standard output is not JSON alone: {out[:200]!r}")

        code, out, err = run([keyanim, "-q", "encode", walk, "-o", k, "-f"])
        check(code == 0 and err == "", f"encode -q under a terminal: exit {code}, printed {err[:200]!r}")
        code, out, err = run([keyanim, "encode", walk, "-o", k, "-f"], tty=False)
        check(code == 0 and "\r" not in err and "[" not in err and err.count("\n") == 1,
              f"encode, standard error not a terminal: exit {code}, printed {err!r}")

        code, out, err = run([keyanim, "decode", k, "-o", os.path.join(tmp, "back.bvh")])
        check(code == 0 and "walk.kanim: decoding  [" in err and err.rsplit("\r", 1)[-1].startswith(CSI_ERASE),
              f"decode under a terminal: exit {code}, {err[-300:]!r}")
        code, out, err = run([keyanim, "decode", k, "-o", os.path.join(tmp, "walk.glb")])
        check(code == 0 and "walk.kanim: fitting, round 0  [" in err and "walk.kanim: measuring  [" in err
              and err.rsplit("\r", 1)[-1].startswith(CSI_ERASE), f"glTF export under a terminal: exit {code}, {err[-300:]!r}")
        code, out, err = run([keyanim, "decode", k, "-o", os.path.join(tmp, "back.bvh"), "-f"], tty=False)
        check(code == 0 and "\r" not in err, f"decode, not a terminal: {err!r}")

        d = os.path.join(tmp, "dir")
        os.mkdir(d)
        for name in ("a", "b", "c"):
            shutil.copy(walk, os.path.join(d, name + ".bvh"))
        code, out, err = run([keyanim, "encode", d, "-o", os.path.join(tmp, "out")])
        # The bar is erased, then the run's one summary line (issue 28, item 13) is all that stays.
        last = err.rsplit("\r", 1)[-1]
        check(code == 0 and re.search(r"3 inputs: \d done  \[", err) and last.startswith(CSI_ERASE)
              and re.fullmatch(r"[^\r\n]* -> [^\r\n]*: 3 inputs, 3 encoded in [^\r\n]*\n", last[len(CSI_ERASE):]),
              f"directory under a terminal: exit {code}, {err[-300:]!r}")
    finally:
        shutil.rmtree(tmp)
    print("progress: ok" if not failures else f"{len(failures)} failures")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
