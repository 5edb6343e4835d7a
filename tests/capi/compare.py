#!/usr/bin/env python3
"""What a program calling keyanim's C API printed, checked against `keyanim sample` and the BVH.

  compare.py [--self-test] KEYANIM CLIP.kanim SOURCE.bvh -- PROGRAM [ARGS...]

runs PROGRAM ARGS CLIP.kanim POSITION... (the output format of examples/c/sample_clip.c) and
checks, at every position and on every node:
  - the skeleton (names, parents, End Site flags, counts) against the BVH's HIERARCHY, read here;
  - each Euler channel, bit for bit as binary32, against `keyanim sample --json` (the CLI
    prints the C++ runtime's values; the BVH gives each joint's channel order);
  - each model translation against `keyanim sample --world --json` (the offline side's forward
    kinematics, in double, from the same channel values);
  - each local rotation against a quaternion made here from the CLI's Euler values (BVH's
    rule: q = q1 q2 q3 in channel order), each local translation against the BVH's OFFSET with
    the node's position channels in place, and each model rotation against those composed here.
Exit 0, or 1 with the first problems. --self-test damages the program's output in each way
above (one binary32 step on a channel, a rotation or translation off, a node renamed or
reparented, a position left out) and checks that each is caught.
"""
import json
import math
import struct
import subprocess
import sys

POSITIONS_NOTE = "whole and fractional frames, both ends, beyond them, and times"


def f32(x):
    """x rounded to binary32, as a Python float."""
    return struct.unpack("<f", struct.pack("<f", x))[0]


def read_bvh_hierarchy(path):
    """The BVH's nodes in file order: name, parent, end_site, offset, channels."""
    with open(path, encoding="latin-1") as f:
        tokens = f.read().split("MOTION")[0].split()
    nodes, stack, i = [], [], 0
    pending = None
    while i < len(tokens):
        t = tokens[i]
        if t in ("ROOT", "JOINT"):
            pending = {"name": tokens[i + 1], "end_site": False}
            i += 2
        elif t == "End" and tokens[i + 1] == "Site":
            pending = {"name": "", "end_site": True}
            i += 2
        elif t == "{":
            pending["parent"] = stack[-1] if stack else -1
            pending.setdefault("channels", [])
            nodes.append(pending)
            stack.append(len(nodes) - 1)
            pending = None
            i += 1
        elif t == "}":
            stack.pop()
            i += 1
        elif t == "OFFSET":
            nodes[stack[-1]]["offset"] = [float(v) for v in tokens[i + 1:i + 4]]
            i += 4
        elif t == "CHANNELS":
            n = int(tokens[i + 1])
            nodes[stack[-1]]["channels"] = tokens[i + 2:i + 2 + n]
            i += 2 + n
        else:
            i += 1
    return nodes


def parse_output(text):
    """The program's lines as {"clip": [...], "nodes": [...], "samples": [...]}."""
    out = {"clip": None, "nodes": [], "samples": []}
    for line in text.splitlines():
        kind, _, rest = line.partition(" ")
        if kind == "clip":
            frames, frame_time, nodes, channels = rest.split()
            out["clip"] = {"frames": int(frames), "frame_time": float(frame_time), "nodes": int(nodes),
                           "channels": int(channels)}
        elif kind == "node":
            index, parent, end_site, name = (rest.split(" ", 3) + [""])[:4]
            out["nodes"].append({"index": int(index), "parent": int(parent), "end_site": bool(int(end_site)),
                                 "name": name})
        elif kind == "at":
            what, x = rest.split()
            out["samples"].append({"by": what, "x": float(x), "channels": None, "local": [], "model": []})
        elif kind == "channels":
            out["samples"][-1]["channels"] = [float(v) for v in rest.split()]
        elif kind in ("local", "model"):
            values = rest.split()
            out["samples"][-1][kind].append([float(v) for v in values[1:]])
    return out


def positions(frame_count, frame_time):
    """What the programs are asked for: whole and fractional frames, the ends and beyond, times."""
    last = frame_count - 1
    frames = [0, 1, 2.5, last // 2, last // 2 + 0.25, last - 1.5, last, -1, last + 2]
    times = [] if frame_time <= 0 else [0.0, (last // 3 + 0.75) * frame_time, last * frame_time * 0.9]
    return [("frame", float(f)) for f in frames] + [("time", t) for t in times]


def position_args(frame_count, frame_time):
    return [("t" if by == "time" else "") + repr(x) for by, x in positions(frame_count, frame_time)]


def cli_sample(keyanim, clip, by, x, world):
    cmd = [keyanim, "sample", clip, "--frame" if by == "frame" else "--time", repr(x), "--json"]
    if world:
        cmd.append("--world")
    return json.loads(subprocess.run(cmd, check=True, capture_output=True, text=True).stdout)["joints"]


def quat_mul(a, b):
    ax, ay, az, aw = a
    bx, by, bz, bw = b
    return (aw * bx + ax * bw + ay * bz - az * by, aw * by - ax * bz + ay * bw + az * bx,
            aw * bz + ax * by - ay * bx + az * bw, aw * bw - ax * bx - ay * by - az * bz)


def euler_quat(channels, values):
    """BVH: rotation channels apply in their order, R = R1 R2 R3 (degrees)."""
    q = (0.0, 0.0, 0.0, 1.0)
    for name, v in zip(channels, values):
        if name.endswith("rotation"):
            h = math.radians(v) / 2
            axis = [0.0, 0.0, 0.0]
            axis["XYZ".index(name[0])] = math.sin(h)
            q = quat_mul(q, (axis[0], axis[1], axis[2], math.cos(h)))
    return q


def close(a, b, tol):
    return all(abs(x - y) <= tol for x, y in zip(a, b))


def same_rotation(a, b, tol):
    """A quaternion and its negation are one rotation: a node stored as a quaternion (format 5)
    takes its sign from its reference, not from the product of its Euler angles."""
    return close(a, b, tol) or close(a, [-x for x in b], tol)


def check(keyanim, clip_path, bvh_path, printed):
    """Problems (strings) in `printed` (parse_output's form) against the CLI and the BVH."""
    problems = []
    bvh = read_bvh_hierarchy(bvh_path)
    meta = printed["clip"]
    if meta is None or meta["nodes"] != len(bvh) or len(printed["nodes"]) != len(bvh):
        return [f"node count: printed {meta and meta['nodes']} ({len(printed['nodes'])} lines), the BVH has {len(bvh)}"]
    for n, b in zip(printed["nodes"], bvh):
        if (n["name"], n["parent"], n["end_site"]) != (b["name"], b["parent"], b["end_site"]):
            problems.append(f"node {n['index']}: printed {n}, the BVH says {b}")
    first, column = [], 0
    for b in bvh:
        first.append(column)
        column += len(b["channels"])
    if meta["channels"] != column:
        problems.append(f"channel count: printed {meta['channels']}, the BVH has {column}")
    want = positions(meta["frames"], meta["frame_time"])
    got = [(s["by"], s["x"]) for s in printed["samples"]]
    if got != want:
        return problems + [f"positions sampled: {got}, expected {want}"]
    last = meta["frames"] - 1
    for s in printed["samples"]:
        where = f"{s['by']} {s['x']!r}"
        # The C API clamps a frame beyond the clip to its ends, as Clip::sample does; `keyanim
        # sample` refuses those (exit 1), so it is asked at the end the API clamps to.
        by, x = s["by"], s["x"]
        if by == "frame":
            x = min(max(x, 0.0), float(last))
        euler = cli_sample(keyanim, clip_path, by, x, world=False)
        world = cli_sample(keyanim, clip_path, by, x, world=True)
        joints = [i for i, b in enumerate(bvh) if not b["end_site"]]
        if len(euler) != len(joints) or len(world) != len(bvh) or len(s["local"]) != len(bvh) or \
                len(s["model"]) != len(bvh) or len(s["channels"] or []) != column:
            problems.append(f"{where}: counts differ (CLI {len(euler)} joints, {len(world)} nodes; printed "
                            f"{len(s['channels'] or [])} channels, {len(s['local'])} local, {len(s['model'])} model)")
            continue
        # Channels: bit for bit (the CLI prints binary32 values as doubles; 9 digits read back exactly).
        cli_values = [0.0] * column
        for node, e in zip(joints, euler):
            for k, name in enumerate(bvh[node]["channels"]):
                cli_values[first[node] + k] = e[name]
        for c, (a, b) in enumerate(zip(s["channels"], cli_values)):
            if f32(a) != f32(b):
                problems.append(f"{where}: channel {c}: printed {a!r}, keyanim sample gives {b!r}")
        # Local transforms from the CLI's channels, and model ones composed from them, in double.
        model_q = []
        for i, b in enumerate(bvh):
            vals = cli_values[first[i]:first[i] + len(b["channels"])]
            q = euler_quat(b["channels"], vals)
            t = list(b["offset"])
            for name, v in zip(b["channels"], vals):
                if name.endswith("position"):
                    t["XYZ".index(name[0])] = v
            loc = s["local"][i]
            # Tolerances: binary32 against double, measured on the three clips at most 1.3e-7
            # (local rotation), 3.5e-7 (model rotation) and 1.2e-6 of the largest coordinate
            # (model translation, Bandai's 30 levels); each bound here is 15 to 80 times that,
            # and catches any wrong axis, order, sign or parent.
            if not same_rotation(loc[:4], q, 1e-5):
                problems.append(f"{where}: node {i} local rotation {loc[:4]}, from the Euler channels {q}")
            if not close(loc[4:], t, 1e-5 * max(1.0, max(abs(v) for v in t))):
                problems.append(f"{where}: node {i} local translation {loc[4:]}, expected {t}")
            model_q.append(q if b["parent"] < 0 else quat_mul(model_q[b["parent"]], q))
            mod = s["model"][i]
            if not same_rotation(mod[:4], model_q[i], 1e-5):
                problems.append(f"{where}: node {i} model rotation {mod[:4]}, composed here {model_q[i]}")
            p = world[i]["position"]
            if not close(mod[4:], p, 2e-5 * max(1.0, max(abs(v) for v in p))):
                problems.append(f"{where}: node {i} model translation {mod[4:]}, keyanim sample --world gives {p}")
    return problems


def report(problems, label):
    for p in problems[:20]:
        print(p)
    if len(problems) > 20:
        print(f"... and {len(problems) - 20} more")
    print(f"{label}: {len(problems)} problem(s)")
    return 1 if problems else 0


def clip_meta(keyanim, clip):
    info = json.loads(subprocess.run([keyanim, "info", clip, "--json"], check=True, capture_output=True,
                                     text=True).stdout)
    return info["frames"], info["frame_time"]


def mutations(text):
    """Damaged copies of a program's output, each of which check() must catch: (what, text)."""
    lines = text.splitlines()

    def edit(what, pick, change):
        i = next(k for k, line in enumerate(lines) if pick(line))
        copy = list(lines)
        copy[i] = change(copy[i])
        return what, "\n".join(copy) + "\n"

    def bump(field, by):
        def change(line):
            parts = line.split()
            v = float(parts[field])
            parts[field] = repr(v + by(v))
            return " ".join(parts)
        return change

    next_float = lambda v: struct.unpack("<f", struct.pack("<i", struct.unpack("<i", struct.pack("<f", v))[0] + 1))[0] - v
    return [
        edit("a channel one binary32 step off", lambda l: l.startswith("channels"), bump(5, next_float)),
        edit("a local rotation 1e-4 off", lambda l: l.startswith("local 3 "), bump(3, lambda v: 1e-4)),
        edit("a local translation off", lambda l: l.startswith("local 2 "), bump(7, lambda v: 1e-3 * max(1, abs(v)))),
        edit("a model rotation off", lambda l: l.startswith("model 5 "), bump(5, lambda v: 1e-3)),
        edit("a model translation off", lambda l: l.startswith("model 4 "), bump(8, lambda v: 1e-3 * max(1, abs(v)))),
        edit("a node renamed", lambda l: l.startswith("node 1 "), lambda l: l + "x"),
        edit("a parent changed", lambda l: l.startswith("node 2 "), lambda l: l.replace("node 2 1 ", "node 2 0 ", 1)),
        ("a position left out", "\n".join(l for l in lines if not l.startswith("at time")) + "\n"),
    ]


def self_test(keyanim, clip, bvh, text):
    """check() passes the program's output and catches every mutation of it."""
    failures = 0
    if check(keyanim, clip, bvh, parse_output(text)):
        print("self-test: the unchanged output fails")
        failures += 1
    for what, damaged in mutations(text):
        if not check(keyanim, clip, bvh, parse_output(damaged)):
            print(f"self-test: not caught: {what}")
            failures += 1
    print(f"self-test: {len(mutations(text))} mutations, {failures} failure(s)")
    return 1 if failures else 0


def main():
    selftest = sys.argv[1:2] == ["--self-test"]
    if selftest:
        del sys.argv[1]
    if len(sys.argv) < 6 or sys.argv[4] != "--":
        print(__doc__.strip().split("\n\n")[0], file=sys.stderr)
        return 2
    keyanim, clip, bvh = sys.argv[1:4]
    frames, frame_time = clip_meta(keyanim, clip)
    run = subprocess.run(sys.argv[5:] + [clip] + position_args(frames, frame_time), capture_output=True, text=True)
    if run.returncode == 77:  # the program's way of saying it cannot run here (csharp_test.sh)
        print(run.stdout.strip())
        return 77
    if run.returncode != 0:
        print(run.stdout[-2000:], run.stderr[-2000:])
        print(f"the program failed (exit {run.returncode})")
        return 1
    if selftest:
        return self_test(keyanim, clip, bvh, run.stdout)
    printed = parse_output(run.stdout)
    problems = check(keyanim, clip, bvh, printed)
    return report(problems, f"{' '.join(sys.argv[5:])} on {clip}: {len(printed['samples'])} positions "
                            f"({POSITIONS_NOTE}), {len(printed['nodes'])} nodes")


if __name__ == "__main__":
    sys.exit(main())
