"""File > Export > keyanim (.kanim): the active armature's action over the scene's frame range,
encoded by keyanim.encode within the chosen error and shell, written to a temporary file beside
the output and renamed once complete (an existing file is replaced only with Overwrite)."""
import os
import tempfile

import bpy
import numpy as np
from bpy.props import BoolProperty, StringProperty
from bpy_extras.io_utils import ExportHelper

from . import action, armature, bvh_text, module, pose, prefs, report
from .skeleton_of import skeleton_of


def frame_time(scene, act):
    """The imported file's own Frame Time while the scene plays at its rate (BVH rounds it:
    .0083333, not 1/120), else the scene's."""
    fps = action.scene_fps(scene)
    kept = act.get("keyanim_frame_time")
    if kept and abs(1.0 / kept - fps) <= 1e-4 * fps:
        return float(kept)
    return 1.0 / fps


def motion_of(keyanim, obj, act, scene):
    """A keyanim.Motion of the action at every frame of the scene's range."""
    skel, bone_names = skeleton_of(obj)
    frames = np.arange(scene.frame_start, scene.frame_end + 1, dtype=np.float64)
    rest = np.array([np.eye(3) if n is None else armature.rest_orientations(obj, [n])[0] for n in bone_names])
    quat, loc = action.read(obj, act, bone_names, frames)
    q, t = pose.from_blender(quat, loc, skel.offsets, rest)
    for node, kinds in enumerate(skel.channels):
        if kinds and pose.rotation_order(kinds) is None:
            raise ValueError("joint %r: rotation channels %s repeat an axis" % (skel.names[node], " ".join(kinds)))
    with tempfile.TemporaryDirectory(prefix="keyanim-blender-") as tmp:
        path = os.path.join(tmp, "layout.bvh")
        with open(path, "w", encoding="utf-8", errors="surrogateescape") as f:
            f.write(bvh_text.text(skel, len(frames), frame_time(scene, act)))
        motion = keyanim.read_bvh(path)
    motion.channels = pose.channel_values(skel, q, t)
    return motion


def write_new(path, data, overwrite):
    if os.path.lexists(path) and not overwrite:
        raise FileExistsError("%s exists: tick Overwrite to replace it" % path)
    fd, tmp = tempfile.mkstemp(prefix=".keyanim-", suffix=".tmp", dir=os.path.dirname(os.path.abspath(path)))
    try:
        with os.fdopen(fd, "wb") as f:
            f.write(data)
        os.replace(tmp, path)
    except BaseException:
        os.unlink(tmp)
        raise


class ExportKanim(bpy.types.Operator, ExportHelper):
    """Export the active armature's action to a keyanim clip (.kanim) within a world-space error"""
    bl_idname = "export_anim.keyanim"
    bl_label = "Export keyanim"
    filename_ext = ".kanim"
    filter_glob: StringProperty(default="*.kanim", options={"HIDDEN"})
    error: StringProperty(name="Error", default="0.05%",
                          description="Largest world-space distance any joint, End Site or shell point may move: "
                                      "a percentage of the skeleton's size (0.05%) or a length in the file's units")
    shell: StringProperty(name="Shell", default="2%",
                          description="Distance of the three shell points along each joint's axes that the error "
                                      "also holds for (keeps rotations right): a percentage or a length; 0 for none")
    overwrite: BoolProperty(name="Overwrite", default=False, description="Replace an existing file")

    def execute(self, context):
        with report.errors(self, self.filepath):
            obj = context.active_object
            act = obj.animation_data.action if obj and obj.type == "ARMATURE" and obj.animation_data else None
            if act is None:
                raise ValueError("the active object is not an armature with an action")
            keyanim = module.load(prefs.module_dir(context))
            shell = self.shell if self.shell.strip().endswith("%") else float(self.shell)
            error = self.error if self.error.strip().endswith("%") else float(self.error)
            data, summary = keyanim.encode(motion_of(keyanim, obj, act, context.scene), error=error, shell=shell)
            write_new(self.filepath, data, self.overwrite)
            self.report({"INFO"}, "%s: %d frames, %d bytes, error max %g" % (
                self.filepath, summary["frames"], len(data), summary["error"]["max"]))
            return {"FINISHED"}
        return {"CANCELLED"}
