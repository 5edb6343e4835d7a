"""blender_bvh: check_bvh.py -- WORKDIR FILE.bvh...  (inside Blender, common.py says how)

Each BVH is imported through the add-on's File > Import > BVH (keyanim): every bone head at the
first, middle and last frames equals `keyanim sample --world` of the file encoded with a key at
every frame and a tolerance of 1e-6% (`--keys uniform:1 --error 0.000001%`), within the float
margin plus that clip's own error against the file as the encoder measured it (its notes'
max_error: about 1e-8 of the skeleton's size); the scene plays at the file's rate over its
frames. The action exported through the add-on passes `keyanim verify --against FILE.bvh
--max-error 0.06%` (0.05% by the encoder against Blender's pose, which is within the float
margin of the file): the same skeleton, names and frames. A malformed file is refused with a
report naming it, line and column."""
import os
import sys

import bpy

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import common  # noqa: E402
from common import check  # noqa: E402


def check_file(work, bvh):
    name = os.path.splitext(os.path.basename(bvh))[0]
    kanim = os.path.join(work, name + ".every-frame.kanim")
    common.tool("-q", "-f", "encode", bvh, "--keys", "uniform:1", "--error", "0.000001%", "-o", kanim)
    info = common.tool_json("info", kanim)
    n = info["frames"]
    limit = common.FLOAT_MARGIN * info["size"] + info["notes"]["max_error"]
    for obj in list(bpy.data.objects):
        bpy.data.objects.remove(obj)
    check(bpy.ops.import_anim.keyanim_bvh(filepath=bvh) == {"FINISHED"}, "import %s" % bvh)
    obj = bpy.context.active_object
    scene = bpy.context.scene
    fps = scene.render.fps / scene.render.fps_base
    check(abs(fps * info["frame_time"] - 1) <= 1e-4 and (scene.frame_start, scene.frame_end) == (1, n),
          "%s: scene at %.6g fps over frames %d-%d (the file: %d at %g s)"
          % (name, fps, scene.frame_start, scene.frame_end, n, info["frame_time"]))
    for f in sorted({0, (n - 1) // 2, n - 1}):
        common.compare_pose(obj, 1 + f, common.reference(kanim, f), limit,
                            "%s frame %d" % (name, f))
    out = os.path.join(work, name + ".blender.kanim")
    check(bpy.ops.export_anim.keyanim(filepath=out) == {"FINISHED"}, "export %s" % out)
    v = common.tool_json("verify", out, "--against", bvh, "--max-error", "0.06%")
    check(v["ok"] and v["valid"], "%s exported: keyanim verify: error max %.3g, allowed %.3g"
          % (name, v["error"]["max"], v["max_error_allowed"]))


def check_malformed(work):
    bad = os.path.join(work, "malformed.bvh")
    with open(bad, "w") as f:
        f.write("HIERARCHY\nROOT Hips\n{\n  OFFSET 0 zero 0\n")
    try:
        bpy.ops.import_anim.keyanim_bvh(filepath=bad)
        said = ""
    except RuntimeError as e:  # how bpy.ops hands a script the operator's ERROR report
        said = str(e)
    check("malformed.bvh:4:" in said, "a malformed BVH is refused, naming file and line: %r" % said.strip())


def main():
    work, files = common.args()[0], common.args()[1:]
    common.enable_addon()
    for bvh in files:
        check_file(work, bvh)
    check_malformed(work)
    common.finish()


main()
