"""blender_kanim: check_kanim.py -- WORKDIR FILE.bvh...  (inside Blender, common.py says how)

Each BVH is encoded by `keyanim encode`; its .kanim is imported through the add-on's operator:
every bone head at the first, middle and last source frames equals `keyanim sample --world`
within the float margin (so within the clip's tolerance), the scene plays at the clip's rate over
its range; the action exported through the add-on's operator and decoded by `keyanim sample
--world` stays within twice the tolerance of the original, with the same frames and frame time.
The first clip is also imported resampled at 30 fps (frames at decode --fps 30's positions)."""
import math
import os
import sys

import bpy

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import common  # noqa: E402
from common import check  # noqa: E402


def import_clip(path, **options):
    for obj in list(bpy.data.objects):
        bpy.data.objects.remove(obj)
    check(bpy.ops.import_anim.keyanim(filepath=path, **options) == {"FINISHED"}, "import %s %s" % (path, options))
    return bpy.context.active_object


def check_timing(info, what, frames):
    scene = bpy.context.scene
    fps = scene.render.fps / scene.render.fps_base
    check(abs(fps - 1 / info["frame_time"]) <= 1e-4 * fps, "%s: scene at %.6g fps, the clip's %.6g" % (what, fps, 1 / info["frame_time"]))
    check((scene.frame_start, scene.frame_end) == (1, frames), "%s: frames %d-%d, the clip's 1-%d"
          % (what, scene.frame_start, scene.frame_end, frames))


def check_refusal(out):
    """An existing file is not replaced without Overwrite: the operator reports it, naming it."""
    before = open(out, "rb").read()
    try:
        result = bpy.ops.export_anim.keyanim(filepath=out)
        said = ""
    except RuntimeError as e:  # how bpy.ops hands a script the operator's ERROR report
        result, said = None, str(e)
    check(result is None and out in said and "Overwrite" in said and open(out, "rb").read() == before,
          "export over an existing file refused, naming it: %r" % said.strip())


def check_clip(work, bvh):
    name = os.path.splitext(os.path.basename(bvh))[0]
    kanim, out = os.path.join(work, name + ".kanim"), os.path.join(work, name + ".blender.kanim")
    common.tool("-q", "-f", "encode", bvh, "-o", kanim)
    info = common.tool_json("info", kanim)
    n, tol, margin = info["frames"], info["guarantee"]["tolerance_units"], common.FLOAT_MARGIN * info["size"]
    obj = import_clip(kanim)
    check_timing(info, name, n)
    refs = {f: common.reference(kanim, f) for f in sorted({0, (n - 1) // 2, n - 1})}
    for f, ref in refs.items():
        common.compare_pose(obj, 1 + f, ref, min(margin, tol), "%s frame %d" % (name, f))
    check(bpy.ops.export_anim.keyanim(filepath=out, error="0.05%") == {"FINISHED"}, "export %s" % out)
    check_refusal(out)
    back = common.tool_json("info", out)
    check((back["frames"], back["frame_time"], back["joints"], back["end_sites"]) ==
          (n, info["frame_time"], info["joints"], info["end_sites"]), "%s: exported frames, frame time, joints" % name)
    for f, ref in refs.items():
        again = common.reference(out, f)
        d = max(math.dist(p, q) for (_, p), (_, q) in zip(again, ref))
        check([a for a, _ in again] == [r for r, _ in ref] and d <= 2 * tol,
              "%s frame %d exported: within 2 x %.3g of the original (largest %.3g)" % (name, f, tol, d))
    return kanim, info


def source_position(k, fps, frame_time):
    """Where output frame k at `fps` samples the clip, by decode --fps's rule (README): a rate
    within 0.01% of the clip's divided by M takes every M-th frame, any other every 1/fps s."""
    m = 1 / (fps * frame_time)
    if round(m) >= 1 and abs(m - round(m)) <= 1e-4 * m:
        return k * round(m)
    return k / fps / frame_time


def check_resampled(kanim, info):
    """Imported resampled at 30 fps: keyed frame k is the clip sampled where `keyanim decode
    --fps 30` puts its frame k (120 fps: every 4th source frame)."""
    obj = import_clip(kanim, resample=True, rate=30.0)
    scene = bpy.context.scene
    check(scene.render.fps == 30 and scene.render.fps_base == 1.0, "resampled: scene at 30 fps")
    decoded = common.tool("-q", "decode", kanim, "--fps", 30, "-o", "-").split("Frames:")[1].split()[0]
    check(scene.frame_end == int(decoded), "resampled: %d frames, as decode --fps 30's %s" % (scene.frame_end, decoded))
    k = scene.frame_end // 2
    position = source_position(k, 30.0, info["frame_time"])
    margin = min(common.FLOAT_MARGIN * info["size"], info["guarantee"]["tolerance_units"])
    common.compare_pose(obj, 1 + k, common.reference(kanim, position), margin,
                        "resampled frame %d (source frame %.4f)" % (k, position))


def main():
    work, clips = common.args()[0], common.args()[1:]
    common.enable_addon()
    checked = [check_clip(work, bvh) for bvh in clips]
    check_resampled(*checked[0])
    common.finish()


main()
