#!/usr/bin/env python3
"""CLI property test (issue 12): random command lines over the real binary, for a bounded time.

usage: property_test.py KEYANIM DATA_DIR [--seconds S] [--seed N] [--no-address-limit]

Each run picks a command, inputs (good, damaged, empty, deep, strangely named, directories,
standard input, /dev/zero, missing files) and option values (numbers at their extremes, NaN,
infinities, huge, negative, empty lists, garbage), runs keyanim with a time limit and limits on
address space and file size, and checks:
  - the exit code is one of the documented table's 0-6 (7, internal error, is a bug; so is a
    death by signal or running out of time);
  - standard error, and standard output unless it carries a binary file, is safe to show on a
    terminal (UTF-8, no control byte but the line feed); --json output parses;
  - the inputs are unchanged (SHA-256 before and after);
  - a command that fails leaves no new file and changes no existing one (a directory run may
    keep the outputs it finished); no temporary file is ever left; an existing file is only
    replaced with -f; every new output is complete (.kanim and .bvh: `keyanim info` reads it;
    .svg: well-formed XML).
The seed is printed; a failure prints the command line that caused it. --seconds (default 60;
$KEYANIM_PROPERTY_SECONDS overrides it) bounds the whole run; $KEYANIM_PROPERTY_SEED picks
another seed.
"""
import argparse
import hashlib
import json
import os
import random
import resource
import shutil
import subprocess
import sys
import tempfile
import time
import xml.dom.minidom

TABLE = set(range(7))  # exit codes 0..6; 7 is "internal error" and means a bug
RUN_SECONDS = 60       # one command; far above what any of them needs here
ADDRESS_LIMIT = 2 << 30
FILE_LIMIT = 256 << 20

NUMBERS = ["0", "-0", "1", "-1", "0.5", "2", "7", "10", "30", "120", "1000", "1e6", "1e9", "1e308", "-1e308",
           "1e-320", "4294967295", "4294967296", "18446744073709551616", "nan", "NaN", "inf", "-inf", "",
           "abc", " 1", "1 ", "0x10", "1e", "+1", "1,5", "\x1b[2J"]
PLAIN = ["0", "1", "2", "3", "7", "10", "30", "120", "0.5", "0.01"]  # most numbers: so that runs get past parsing
SIZES = ["1", "100", "1K", "64K", "1M", "16M", "0", "-1", "abc", "", "99999999999999999999T", "2G"]
# --max-values is always given, and never so high that a decode could write more than about
# 100 MB here (the default cap itself is tested in hostile_test.sh).
VALUES = ["1", "1000", "1M", "4M", "4M", "4M", "0", "-5", "x"]
WEIRD = "r\udcff\x1b[31m\u202ex"  # a joint name that is not UTF-8 and holds escapes


def arg_bytes(s):
    return s.encode("utf-8", "surrogateescape")


class Fixture:
    """The inputs, made once in a scratch directory; `inputs` are hashed around every run."""

    def __init__(self, keyanim, data, root):
        self.k, self.root = keyanim, root
        self.inp = os.path.join(root, "in")
        self.out = os.path.join(root, "out")
        os.makedirs(self.inp)
        os.makedirs(self.out)
        p = lambda name: os.path.join(self.inp, name)
        shutil.copy(os.path.join(data, "cmu_02_01_walk.bvh"), p("walk.bvh"))
        hierarchy = "HIERARCHY\nROOT %s\n{\n OFFSET 5 0 0\n CHANNELS 3 Xposition Yposition Zrotation\n" \
                    " End Site\n {\n  OFFSET 1 2 0\n }\n}\nMOTION\n"
        with open(p("tiny.bvh"), "wb") as f:
            f.write(arg_bytes(hierarchy % WEIRD + "Frames: 4\nFrame Time: 0.1\n1 2 3\n2 3 4\n4 1 0\n5 0 -30\n"))
        with open(p("empty.bvh"), "w") as f:
            f.write(hierarchy % "e" + "Frames: 0\nFrame Time: 0.1\n")
        lines = ["HIERARCHY"]
        for i in range(300):
            lines += [("ROOT" if i == 0 else "JOINT") + " j%d" % i, "{", "OFFSET 0 1 0", "CHANNELS 1 Zrotation"]
        lines += ["End Site", "{", "OFFSET 0 1 0", "}"] + ["}"] * 300 + ["MOTION", "Frames: 3", "Frame Time: 0.1"]
        lines += [" ".join(str((f * i) % 11) for i in range(300)) for f in range(3)]
        with open(p("deep.bvh"), "w") as f:
            f.write("\n".join(lines) + "\n")
        with open(os.path.join(self.inp.encode(), b"n\xffme\x1b.bvh"), "wb") as f:
            f.write(open(p("tiny.bvh"), "rb").read())
        for stem in ("walk", "tiny", "empty", "deep"):  # .kanim names no default output can take
            self.must([self.k, "-q", "encode", p(stem + ".bvh"), "-o", p(stem + "_k.kanim")])
        walk = open(p("walk_k.kanim"), "rb").read()
        with open(p("damaged_k.kanim"), "wb") as f:
            f.write(walk[:100] + bytes([walk[100] ^ 0xFF]) + walk[101:])
        with open(p("cut_k.kanim"), "wb") as f:
            f.write(walk[: len(walk) // 2])
        with open(p("v9_k.kanim"), "wb") as f:  # a later major version: exit 3
            f.write(walk[:8] + b"\x09" + walk[9:])
        with open(p("garbage.bin"), "wb") as f:
            f.write(random.Random(5).randbytes(5000))
        for d, names in (("dir_ok", ["a.bvh", "sub/b.bvh"]), ("dir_clash", ["m.bvh", "m.BVH"])):
            for n in names:
                os.makedirs(os.path.dirname(os.path.join(self.inp, d, n)), exist_ok=True)
                shutil.copy(p("tiny.bvh"), os.path.join(self.inp, d, n))
        os.link(p("tiny.bvh"), p("tiny_link.kanim"))  # a hard link: writing it would destroy tiny.bvh
        os.symlink("walk.bvh", p("walk_sym.svg"))
        self.inputs = self.snapshot(self.inp)
        bvh = [p(n) for n in ("walk.bvh", "tiny.bvh", "empty.bvh", "deep.bvh")] + \
              [os.path.join(self.inp.encode(), b"n\xffme\x1b.bvh").decode("utf-8", "surrogateescape")]
        kanim = [p(s + "_k.kanim") for s in ("walk", "tiny", "empty", "deep", "damaged", "cut", "v9")]
        odd = [p("garbage.bin"), "/dev/zero", "/dev/null", p("missing.bvh"), self.inp, "-"]
        self.bvh, self.kanim, self.odd = bvh, kanim, odd
        self.dirs = [os.path.join(self.inp, "dir_ok"), os.path.join(self.inp, "dir_clash")]

    def must(self, cmd):
        r = subprocess.run([arg_bytes(c) for c in cmd], capture_output=True)
        if r.returncode != 0:
            sys.exit("setup failed: %s: %s" % (cmd, r.stderr.decode(errors="replace")))

    @staticmethod
    def snapshot(top):
        """path -> SHA-256 of every file below top (symlinks: of what they point to)."""
        out = {}
        for d, _, files in os.walk(top.encode()):
            for f in files:
                path = os.path.join(d, f)
                try:
                    out[path] = hashlib.sha256(open(path, "rb").read()).hexdigest()
                except OSError as e:
                    out[path] = "unreadable: %s" % e
        return out

    def reset_outputs(self):
        shutil.rmtree(self.out)
        os.makedirs(self.out)
        for ext in ("kanim", "bvh", "svg"):
            with open(os.path.join(self.out, "exists." + ext), "w") as f:
                f.write("precious\n")


def pick_input(rng, fx, kind):
    pools = {"bvh": fx.bvh, "kanim": fx.kanim}
    r = rng.random()
    if r < 0.6:
        return rng.choice(pools.get(kind, fx.bvh + fx.kanim))
    if r < 0.8:
        return rng.choice(fx.bvh + fx.kanim)
    return rng.choice(fx.odd)


def pick_output(rng, fx, ext, inputs):
    r = rng.random()
    if r < 0.2:
        return None  # the default beside the input
    if r < 0.55:
        return os.path.join(fx.out, "o" + ext)
    # Inputs, and links to them, are offered only when they are this command's inputs: another
    # fixture may rightly be replaced with -f.
    links = {os.path.join(fx.inp, "tiny.bvh"): os.path.join(fx.inp, "tiny_link.kanim"),
             os.path.join(fx.inp, "walk.bvh"): os.path.join(fx.inp, "walk_sym.svg")}
    return rng.choice([os.path.join(fx.out, "exists" + ext), "-", fx.out, os.path.join(fx.root, "missing", "o" + ext),
                       "/dev/null"] + [i for i in inputs if i != "-"] + [links[i] for i in inputs if i in links])


def number(rng):
    return rng.choice(PLAIN if rng.random() < 0.7 else NUMBERS)


def number_list(rng):
    return ",".join(number(rng) for _ in range(rng.choice([0, 1, 2, 3, 5]))) + rng.choice(["", ",", ",,"])


def key_mode(rng):
    return rng.choice(["error", "curvature", "uniform:" + number(rng), "manual:" + number_list(rng), "uniform:",
                       "manual:", "sometimes", "error:1"])


def maybe(rng, p, *items):
    return list(items) if rng.random() < p else []


def encoder_options(rng):
    a = []
    a += maybe(rng, 0.4, "--error", rng.choice([number(rng), number(rng) + "%", "0.05%", "0.5%", "100%", "101%", "%"]))
    a += maybe(rng, 0.4, "--keys", key_mode(rng))
    a += maybe(rng, 0.2, "--tension", rng.choice([number(rng), "fit", "-1", "1", "1.0001"]))
    a += maybe(rng, 0.2, "--level", rng.choice([number(rng), "1", "22", "23"]))
    return a


def make_command(rng, fx):
    """(argv, stdin file or None, single output path or None, kind of run)."""
    cmd = rng.choice(["encode", "encode", "decode", "decode", "info", "sample", "plot", "render", "eval", "verify"])
    a, out, ext = [], None, None
    if cmd == "encode":
        src = rng.choice(fx.dirs) if rng.random() < 0.15 else pick_input(rng, fx, "bvh")
        a = [src] + encoder_options(rng) + maybe(rng, 0.2, "-j", rng.choice(["0", "1", "2", "4294967295", "-1"]))
        a += maybe(rng, 0.3, "--json")
        ext, inputs = ".kanim", [src]
    elif cmd == "decode":
        src = pick_input(rng, fx, "kanim")
        r = rng.random()
        if r < 0.35:
            a += ["--fps", rng.choice(PLAIN + NUMBERS[:12] + ["1e6", "1e9", "1e308", "nan", "-30"])]
        elif r < 0.6:
            a += ["--inbetweens", rng.choice(["0", "1", "7", "100", "65536", "2000000", "4294967295", "-1", "x"])]
        a += maybe(rng, 0.3, "--frames", rng.choice([number(rng) + ":" + number(rng), "0:0", "5:", ":5", ":", "x"]))
        a = [src] + a
        ext, inputs = ".bvh", [src]
    elif cmd == "info":
        src = pick_input(rng, fx, "any")
        a, inputs = [src] + maybe(rng, 0.5, "--json"), [src]
    elif cmd == "sample":
        src = pick_input(rng, fx, "kanim")
        a = [src]
        r = rng.random()
        a += (["--frame", number(rng)] if r < 0.45 else ["--time", number(rng)] if r < 0.9 else
              ["--frame", "1", "--time", "1"] if r < 0.95 else [])
        a += maybe(rng, 0.3, "--joint", rng.choice(["Hips", "LeftHand", WEIRD, "j299", "", "Nobody"]))
        a += maybe(rng, 0.4, "--world") + maybe(rng, 0.5, "--json")
        inputs = [src]
    elif cmd == "plot":
        src = pick_input(rng, fx, "bvh")
        a = [src] + maybe(rng, 0.95, "--channel", rng.choice(
            ["Hips:Xrotation", "RightArm:Zrotation", WEIRD + ":Xposition", "j150:Zrotation", "Nobody:Xrotation",
             "Hips:Wrotation", "", ":", "Hips"]))
        a += maybe(rng, 0.3, "--frames", rng.choice(["0:10", "5:", ":3", "300:999999", number(rng) + ":" + number(rng)]))
        a += encoder_options(rng)
        ext, inputs = ".svg", [src]
    elif cmd == "render":
        src = pick_input(rng, fx, "any")
        a = [src] + maybe(rng, 0.4, "--frame", rng.choice([number(rng), "0", "1", "343", "344"]))
        other = pick_input(rng, fx, "any") if rng.random() < 0.3 else None
        a += ["--against", other] if other else []
        a += encoder_options(rng)
        ext, inputs = ".svg", [src] + ([other] if other else [])
    elif cmd == "eval":
        srcs = [rng.choice(fx.bvh + fx.dirs + fx.odd[:1]) for _ in range(rng.choice([1, 1, 2]))]
        srcs += maybe(rng, 0.1, "-")
        a = srcs + maybe(rng, 0.5, "--error", rng.choice([number_list(rng), "0.05%,0.5%", "1%", ""]))
        a += maybe(rng, 0.3, "--keys", key_mode(rng)) + maybe(rng, 0.2, "-j", rng.choice(["1", "4294967295"]))
        a += maybe(rng, 0.4, "--json")
        inputs = srcs
    else:  # verify
        src = pick_input(rng, fx, "kanim")
        against = pick_input(rng, fx, "bvh") if rng.random() < 0.6 else None
        a = [src] + (["--against", against] if against else [])
        a += maybe(rng, 0.4, "--max-error", rng.choice([number(rng), number(rng) + "%", "0.05%", "1e-9"]))
        a += maybe(rng, 0.4, "--json")
        inputs = [src] + ([against] if against else [])
    if ext:
        out = pick_output(rng, fx, ext, inputs)
        if out is not None:
            a += [rng.choice(["-o", "--output"]), out]
    g = maybe(rng, 0.3, "-f") + maybe(rng, 0.2, "-q") + maybe(rng, 0.1, "-v")
    g += maybe(rng, 0.1, "--max-input", rng.choice(SIZES)) + ["--max-values", rng.choice(VALUES)]
    if rng.random() < 0.05:
        a.insert(rng.randrange(len(a) + 1), rng.choice(["--bogus", "-x", "--json=1", "--", "-o"]))
    argv = [fx.k] + g + [cmd] + a
    stdin = rng.choice(fx.bvh + fx.kanim) if "-" in inputs else None
    dir_run = cmd == "encode" and inputs[0] in fx.dirs
    to_stdout = out == "-" or (ext is not None and out is None and inputs[0] == "-")  # data, not messages
    return argv, stdin, cmd, dir_run, flag_given(a, "--json"), to_stdout, ext is not None


VALUED = {"-o", "--output", "--error", "--keys", "--tension", "--level", "-j", "--fps", "--inbetweens", "--frames",
          "--frame", "--time", "--joint", "--channel", "--against", "--max-error"}


def flag_given(args, flag):
    """Whether `flag` reaches keyanim as an option: not as another option's value, not after --."""
    i = 0
    while i < len(args):
        if args[i] == "--":
            return False
        if args[i] == flag:
            return True
        i += 2 if args[i] in VALUED else 1
    return False


def terminal_safe(data):
    try:
        data.decode("utf-8")
    except UnicodeDecodeError:
        return False
    return not any((b < 0x20 and b != 0x0A) or b == 0x7F for b in data)


def complete(k, path):
    """Whether a new output file is whole: keyanim reads .kanim/.bvh back, .svg parses."""
    if path.endswith(b".svg"):
        try:
            xml.dom.minidom.parse(path.decode("utf-8", "surrogateescape"))
            return True
        except Exception:
            return False
    if path.endswith(b".kanim") or path.endswith(b".bvh"):
        return subprocess.run([k.encode(), b"info", path], capture_output=True).returncode == 0
    return True


def limits(address):
    def apply():
        if address:
            resource.setrlimit(resource.RLIMIT_AS, (ADDRESS_LIMIT, ADDRESS_LIMIT))
        resource.setrlimit(resource.RLIMIT_FSIZE, (FILE_LIMIT, FILE_LIMIT))
        resource.setrlimit(resource.RLIMIT_CORE, (0, 0))
    return apply


def run_one(rng, fx, address):
    argv, stdin, cmd, dir_run, json_out, data_stdout, writes = make_command(rng, fx)
    shown = " ".join(repr(a) if any(c in a for c in " \x1b'\"") or not a else a for a in argv)
    fx.reset_outputs()
    before = fx.snapshot(fx.root)
    with open(stdin or "/dev/null", "rb") as f:
        try:
            r = subprocess.run([arg_bytes(x) for x in argv], stdin=f, capture_output=True, timeout=RUN_SECONDS,
                               preexec_fn=limits(address), cwd=fx.root)
        except subprocess.TimeoutExpired:
            return shown, "did not finish within %d s" % RUN_SECONDS, None
    rc = r.returncode
    problems = []
    if rc < 0:
        problems.append("killed by signal %d" % -rc)
    elif rc == 7:
        problems.append("internal error (exit 7)")
    elif rc not in TABLE:
        problems.append("exit %d is not in the table" % rc)
    if not terminal_safe(r.stderr):
        problems.append("standard error is not safe for a terminal: %r" % r.stderr[:300])
    if not data_stdout and not json_out and not terminal_safe(r.stdout):
        problems.append("standard output is not safe for a terminal: %r" % r.stdout[:300])
    if json_out and r.stdout:
        try:
            json.loads(r.stdout.decode("utf-8"))
        except (ValueError, UnicodeDecodeError) as e:
            problems.append("--json output does not parse (%s): %r" % (e, r.stdout[:300]))
    if json_out and rc == 0 and not r.stdout:
        problems.append("--json and exit 0 but no output")
    after = fx.snapshot(fx.root)
    for path, digest in fx.inputs.items():
        if after.get(path) != digest:
            problems.append("input %r changed" % path)
    temps = [p for p in after if b".tmp." in os.path.basename(p)]
    if temps:
        problems.append("temporary files left: %r" % temps)
    new = [p for p in after if p not in before and p not in temps]
    changed = [p for p in before if p in after and before[p] != after[p] and p not in fx.inputs]
    gone = [p for p in before if p not in after]
    if gone:
        problems.append("files disappeared: %r" % gone)
    if rc != 0 and not dir_run and (new or changed):
        problems.append("a failed command left outputs: new %r, changed %r" % (new, changed))
    if not writes and (new or changed):
        problems.append("a command that writes no file did: new %r, changed %r" % (new, changed))
    if changed and "-f" not in argv[1:argv.index(cmd)]:
        problems.append("existing files replaced without -f: %r" % changed)
    for p in new + changed:
        if not complete(fx.k, p):
            problems.append("output %r is incomplete" % p)
    # Outputs written beside the inputs (default names) or anywhere else go, so that the next
    # run starts clean (out/ is made anew).
    for p in new:
        os.remove(p)
    shutil.rmtree(os.path.join(fx.root, "missing"), ignore_errors=True)
    return shown, "; ".join(problems), rc


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("keyanim")
    ap.add_argument("data")
    ap.add_argument("--seconds", type=float, default=60.0)
    ap.add_argument("--seed", type=int, default=int(os.environ.get("KEYANIM_PROPERTY_SEED", 12)))
    ap.add_argument("--no-address-limit", action="store_true", help="for sanitizer builds")
    args = ap.parse_args()
    if os.environ.get("KEYANIM_PROPERTY_SECONDS"):  # overrides --seconds, e.g. for a long local run
        args.seconds = float(os.environ["KEYANIM_PROPERTY_SECONDS"])
    k = os.path.abspath(args.keyanim)
    rng = random.Random(args.seed)
    counts = {}
    with tempfile.TemporaryDirectory() as root:
        fx = Fixture(k, os.path.abspath(args.data), root)
        start = time.monotonic()
        runs = 0
        while time.monotonic() - start < args.seconds:
            shown, problem, rc = run_one(rng, fx, not args.no_address_limit)
            runs += 1
            counts[rc] = counts.get(rc, 0) + 1
            if problem:
                print("FAIL (seed %d, run %d): %s\n  command: %s" % (args.seed, runs, problem, shown))
                return 1
    print("ok: %d random command lines in %.0f s (seed %d); exit codes: %s" %
          (runs, time.monotonic() - start, args.seed, ", ".join("%s x%d" % (c, n) for c, n in sorted(counts.items()))))
    return 0


if __name__ == "__main__":
    sys.exit(main())
