"""File > Import > BVH (keyanim): BVH text read exactly by keyanim.read_bvh (Blender 3.4's own
BVH importer fails on Debian 12: it opens files with mode 'rU', which Python 3.11 refuses), made
into the same armature and action as a .kanim import, keyed at every frame."""
import os

import bpy
import numpy as np
from bpy.props import IntProperty, StringProperty
from bpy_extras.io_utils import ImportHelper

from . import build, module, prefs, report, skeleton
from .skeleton import POSITIONS


def local_translations(motion, skel):
    """(frames, nodes, 3) float64: OFFSETs with each position channel standing for its component
    (the replace reading, Blender's and keyanim's default), taken from the channel values."""
    t = np.tile(skel.offsets, (motion.frame_count, 1, 1))
    values = motion.channels
    column = 0
    for node, kinds in enumerate(skel.channels):
        for kind in kinds:
            if kind in POSITIONS:
                t[:, node, POSITIONS.index(kind)] = values[:, column]
            column += 1
    return t


class ImportBvhKeyanim(bpy.types.Operator, ImportHelper):
    """Import BVH motion capture exactly (keyanim's reader) as an armature with one action"""
    bl_idname = "import_anim.keyanim_bvh"
    bl_label = "Import BVH (keyanim)"
    bl_options = {"REGISTER", "UNDO"}
    filename_ext = ".bvh"
    filter_glob: StringProperty(default="*.bvh", options={"HIDDEN"})
    first_frame: IntProperty(name="Start Frame", default=1, description="Blender frame of the file's first frame")

    def execute(self, context):
        with report.errors(self, self.filepath):
            keyanim = module.load(prefs.module_dir(context))
            motion = keyanim.read_bvh(self.filepath)
            if motion.frame_count == 0:
                raise ValueError("the file has no frames: nothing to key")
            if not motion.frame_time > 0:
                raise ValueError("Frame Time %r: Blender needs a rate above 0" % motion.frame_time)
            skel = skeleton.from_keyanim(motion)
            q = motion.local_quaternions()
            build.build(context, os.path.splitext(os.path.basename(self.filepath))[0], skel, q,
                        local_translations(motion, skel), motion.fps, motion.frame_time, self.first_frame)
            self.report({"INFO"}, "%s: %d frames at %g fps" % (self.filepath, motion.frame_count, motion.fps))
            return {"FINISHED"}
        return {"CANCELLED"}
