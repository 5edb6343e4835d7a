"""The armature of a skeleton: a bone per node (End Sites as leaf bones), named as the BVH's
joints, heads at the rest pose's positions, each node's BVH data kept on its bone (custom
properties keyanim_*) so that the export writes the same skeleton back. The armature's own space
is the file's (Y up for most BVH); the object is turned +90 degrees about X so that the motion
stands up in Blender's Z-up world (Blender's own BVH importer does the same)."""
import math

import bpy
import numpy as np


UP = (math.pi / 2, 0.0, 0.0)  # the object's rotation: file Y up -> Blender Z up


def _tail_direction(skeleton, rest, j):
    """Where bone j points: towards its children's mean position, else on along its OFFSET,
    else up the file's Y. Any direction is exact (pose.py); this one reads as a skeleton."""
    kids = [c for c in skeleton.children(j) if np.linalg.norm(skeleton.offsets[c]) > 0]
    d = np.mean([rest[c] for c in kids], axis=0) - rest[j] if kids else skeleton.offsets[j]
    n = np.linalg.norm(d)
    return (d / n, n) if n > 0 else (np.array([0.0, 1.0, 0.0]), 0.0)


def _edit_bones(arm, skeleton):
    """Creates the bones (in edit mode) and returns their names, which Blender may shorten (63
    bytes) or suffix (.001) where BVH names are longer or repeated."""
    rest = skeleton.rest_positions()
    shortest = max(skeleton.size(), 1e-6) * 0.01  # Blender drops bones of zero length
    bones = []
    for j, name in enumerate(skeleton.names):
        eb = arm.edit_bones.new(name)
        direction, length = _tail_direction(skeleton, rest, j)
        if skeleton.end_site[j] or not skeleton.children(j):
            length = 0.5 * length  # a leaf: half its OFFSET, so its parent's reads as the limb
        eb.head = rest[j]
        eb.tail = rest[j] + direction * max(length, shortest)
        eb.roll = 0.0
        eb.use_connect = False  # heads stay where the OFFSETs put them, locations stay free
        if skeleton.parents[j] >= 0:
            eb.parent = bones[skeleton.parents[j]]
        eb["keyanim_index"] = j
        eb["keyanim_name"] = name
        eb["keyanim_offset"] = [float(v) for v in skeleton.offsets[j]]
        eb["keyanim_channels"] = " ".join(skeleton.channels[j])
        eb["keyanim_end_site"] = bool(skeleton.end_site[j])
        bones.append(eb)
    return [eb.name for eb in bones]


def build(context, name, skeleton):
    """A new armature object in the active collection, made active; returns (object, bone names
    in node order)."""
    arm = bpy.data.armatures.new(name)
    obj = bpy.data.objects.new(name, arm)
    context.collection.objects.link(obj)
    obj.rotation_mode = "XYZ"
    obj.rotation_euler = UP
    for other in context.selected_objects:
        other.select_set(False)
    obj.select_set(True)
    context.view_layer.objects.active = obj
    bpy.ops.object.mode_set(mode="EDIT")
    try:
        names = _edit_bones(arm, skeleton)
    finally:
        bpy.ops.object.mode_set(mode="OBJECT")
    for bone in obj.pose.bones:
        bone.rotation_mode = "QUATERNION"
    return obj, names


def rest_orientations(obj, bone_names):
    """(nodes, 3, 3) float64: each bone's rest orientation B in armature space, as Blender holds
    it (read back, not recomputed, so that pose.py inverts what Blender applies)."""
    return np.array([np.array(obj.data.bones[n].matrix_local, dtype=np.float64)[:3, :3] for n in bone_names])
