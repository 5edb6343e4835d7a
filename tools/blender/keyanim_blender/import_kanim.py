"""File > Import > keyanim (.kanim, .kbank): a clip (a bank's, picked by name) as an armature
and one action, keyed at the clip's source frames or resampled at a chosen rate by the clip's
own curves (keyanim.Clip's sampling: nothing is decoded here)."""
import os

import bpy
import numpy as np
from bpy.props import BoolProperty, FloatProperty, IntProperty, StringProperty
from bpy_extras.io_utils import ImportHelper

from . import build, module, prefs, report, skeleton

_bank_names = {}  # path -> (mtime, names): the Clip field's suggestions, read once per file


def _clip_names(op, context, edit_text):
    path = bpy.path.abspath(op.filepath)
    if not path.endswith(".kbank") or not os.path.isfile(path):
        return []
    stamp = os.path.getmtime(path)
    if _bank_names.get(path, (None,))[0] != stamp:
        try:
            _bank_names[path] = (stamp, list(module.load(prefs.module_dir(context)).Bank(path).names))
        except (ImportError, ValueError, OSError):
            return []
    return [n for n in _bank_names[path][1] if edit_text.lower() in n.lower()]


def open_clip(keyanim, path, clip_name):
    """(clip, name for the armature, note for the user): a .kanim, or a bank's clip by name
    (its first clip when none is named)."""
    if not path.lower().endswith(".kbank"):
        return keyanim.Clip(path), os.path.splitext(os.path.basename(path))[0], ""
    bank = keyanim.Bank(path)
    if not len(bank):
        raise ValueError("the bank holds no clip")
    name = clip_name or bank.names[0]
    if name not in bank:
        raise ValueError("the bank has no clip named %r (it has %d: %s%s)"
                         % (name, len(bank), ", ".join(bank.names[:5]), ", ..." if len(bank) > 5 else ""))
    note = "" if clip_name else " (clip %r, 1 of %d: name another in Clip)" % (name, len(bank))
    return bank.clip(name), name, note


def frame_positions(clip, fps):
    """Source frame positions of the output frames: every source frame (fps None), or frames
    every 1/fps s as `keyanim decode --fps` places them."""
    if fps is None:
        return np.arange(clip.frame_count, dtype=np.float64)
    return clip.frame_positions_at(fps, np.arange(clip.frame_count_at(fps)))


class ImportKanim(bpy.types.Operator, ImportHelper):
    """Import a keyanim clip (.kanim, or one clip of a .kbank bank) as an armature with one action"""
    bl_idname = "import_anim.keyanim"
    bl_label = "Import keyanim"
    bl_options = {"REGISTER", "UNDO"}
    filename_ext = ".kanim"
    filter_glob: StringProperty(default="*.kanim;*.kbank", options={"HIDDEN"})
    clip: StringProperty(name="Clip", description="A bank's clip to import, by name (empty: its first clip)",
                         search=_clip_names, search_options={"SUGGESTION"})
    resample: BoolProperty(name="Resample", default=False,
                           description="Key frames every 1/Rate s (in-betweens from the clip's curves) "
                                       "instead of the clip's source frames; the scene takes that rate")
    rate: FloatProperty(name="Rate", default=30.0, min=0.01, max=10000.0, description="Frames per second when resampling")
    first_frame: IntProperty(name="Start Frame", default=1, description="Blender frame of the clip's first frame")

    def execute(self, context):
        with report.errors(self, self.filepath):
            keyanim = module.load(prefs.module_dir(context))
            clip, name, note = open_clip(keyanim, self.filepath, self.clip)
            fps = self.rate if self.resample else None
            positions = frame_positions(clip, fps)
            q, t = clip.local_transforms(frames=positions)
            build.build(context, name, skeleton.from_keyanim(clip), q, t, fps or clip.fps,
                        clip.frame_time if fps is None else 1.0 / fps, self.first_frame)
            self.report({"INFO"}, "%s: %d frames at %g fps%s" % (self.filepath, len(positions), fps or clip.fps, note))
            return {"FINISHED"}
        return {"CANCELLED"}
