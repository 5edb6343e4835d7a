"""What the Blender checks share (run inside Blender: blender -b --factory-startup -P CHECK.py --
ARGS): the add-on enabled from the source tree, the keyanim tool as the independent reference,
and bone heads read back in the file's frame.

The reference is `keyanim sample --world --json` (the C++ sampler and forward kinematics, another
program than the add-on, which goes through the Python module and Blender's pose evaluation).
FLOAT_MARGIN: Blender holds keys and bone matrices in float32 (about 6e-8 relative per
operation, a few dozen operations down a chain of joints), so positions may differ from the
tool's float64 forward kinematics by about 1e-6 of the skeleton's size; 1e-5 of it is allowed."""
import json
import math
import os
import subprocess
import sys

import addon_utils
import bpy
from mathutils import Matrix

FLOAT_MARGIN = 1e-5  # of the skeleton's size
HERE = os.path.dirname(os.path.abspath(__file__))
ADDON_DIR = os.path.join(os.path.dirname(os.path.dirname(HERE)), "tools", "blender")
# The documented convention: the armature object turned +90 degrees about X (file Y up ->
# Blender Z up); the checks undo it to compare in the file's frame.
TO_FILE = Matrix.Rotation(-math.pi / 2, 4, "X")

failures = []


def args():
    return sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []


def enable_addon():
    """The add-on from this checkout (tools/blender), as a user's Blender enables it."""
    if ADDON_DIR not in sys.path:
        sys.path.insert(0, ADDON_DIR)
    mod = addon_utils.enable("keyanim_blender", default_set=True, handle_error=None)
    if mod is None or not mod.__file__.startswith(ADDON_DIR):
        raise SystemExit("FAIL: the add-on did not load from %s" % ADDON_DIR)
    return mod


def tool(*argv):
    r = subprocess.run([os.environ["KEYANIM_CLI"], *map(str, argv)], capture_output=True, text=True)
    if r.returncode != 0:
        raise SystemExit("FAIL: keyanim %s exited %d: %s" % (" ".join(map(str, argv)), r.returncode, r.stderr))
    return r.stdout


def tool_json(*argv):
    return json.loads(tool(*argv, "--json"))


def reference(kanim, frame):
    """[(name, (x, y, z))] of every node at a frame position, by `keyanim sample --world`."""
    return [(j["name"], j["position"]) for j in tool_json("sample", kanim, "--frame", frame, "--world")["joints"]]


def check(ok, what):
    print(("ok: " if ok else "FAIL: ") + what)
    if not ok:
        failures.append(what)


def bones_by_node(obj):
    """Pose bones in node order (the add-on keeps each node's index on its bone)."""
    bones = sorted(obj.pose.bones, key=lambda b: b.bone["keyanim_index"])
    return bones


def heads_in_file_frame(obj, blender_frame):
    """Every bone's head world position at a frame, turned back into the file's frame."""
    bpy.context.scene.frame_set(blender_frame)
    return [TO_FILE @ (obj.matrix_world @ b.head) for b in bones_by_node(obj)]


def largest_distance(heads, ref):
    return max(math.dist(tuple(h), p) for h, (_, p) in zip(heads, ref))


def compare_pose(obj, blender_frame, ref, limit, what):
    bones = bones_by_node(obj)
    names_ok = len(bones) == len(ref) and all(b.bone["keyanim_name"] == n for b, (n, _) in zip(bones, ref))
    check(names_ok, "%s: a bone per node, named as the file's nodes (%d)" % (what, len(ref)))
    if names_ok:
        d = largest_distance(heads_in_file_frame(obj, blender_frame), ref)
        check(d <= limit, "%s: bone heads within %.3g of keyanim sample --world (largest %.3g)" % (what, limit, d))


def finish():
    if failures:
        raise SystemExit("FAIL: %d check(s) failed" % len(failures))
    print("all checks passed")
