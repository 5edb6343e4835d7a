"""From a skeleton and its local transforms per frame to what the importers make: an armature
object with one action, and the scene at the motion's rate and range."""
import numpy as np

from . import action, armature, pose


def build(context, name, skeleton, q_xyzw, t, fps, frame_time, first):
    """q_xyzw (frames, nodes, 4) and t (frames, nodes, 3): BVH local transforms of consecutive
    output frames at `fps`, keyed at Blender frames first, first + 1, ...; frame_time is the
    file's own (kept on the action for the export: BVH rounds it, 1/fps would not be it)."""
    obj, bone_names = armature.build(context, name, skeleton)
    rest = armature.rest_orientations(obj, bone_names)
    quat, loc = pose.to_blender(q_xyzw, t, skeleton.offsets, rest)
    frames = first + np.arange(quat.shape[0], dtype=np.float64)
    act = action.write(obj, name, skeleton, bone_names, frames, quat, loc)
    act["keyanim_frame_time"] = float(frame_time)
    act["keyanim_fps"] = float(fps)
    action.set_timing(context.scene, fps, first, quat.shape[0])
    return obj
