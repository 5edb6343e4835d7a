"""One action of keys on an armature's pose bones, written and read through F-curves (arrays
in bulk: foreach_set), and the scene's frame rate and range."""
import bpy
import numpy as np


def _path(bone, prop):
    return 'pose.bones["%s"].%s' % (bpy.utils.escape_identifier(bone), prop)


def _curve(action, bone, prop, index, frames, values):
    fc = action.fcurves.new(_path(bone, prop), index=index, action_group=bone)
    fc.keyframe_points.add(len(frames))
    co = np.empty((len(frames), 2), dtype=np.float32)
    co[:, 0], co[:, 1] = frames, values
    fc.keyframe_points.foreach_set("co", co.ravel())
    # LINEAR: the keys are every frame of the clip; Bezier handles would overshoot between them.
    fc.keyframe_points.foreach_set("interpolation", [bpy.types.Keyframe.bl_rna.properties["interpolation"]
                                                     .enum_items["LINEAR"].value] * len(frames))
    fc.update()


def write(obj, name, skeleton, bone_names, frames, quat, loc):
    """A new action `name` on obj with keys at Blender frames `frames` (n,): rotation keys on
    joints with rotation channels, location keys on those with position channels (End Sites
    and the rest keep their rest pose, as in the file)."""
    action = bpy.data.actions.new(name)
    for j, bone in enumerate(bone_names):
        kinds = skeleton.channels[j]
        if any(k.endswith("rotation") for k in kinds):
            for i in range(4):
                _curve(action, bone, "rotation_quaternion", i, frames, quat[:, j, i])
        if any(k.endswith("position") for k in kinds):
            for i in range(3):
                _curve(action, bone, "location", i, frames, loc[:, j, i])
    obj.animation_data_create()
    obj.animation_data.action = action
    return action


def _evaluate(action, bone, prop, size, frames, default):
    out = np.tile(np.asarray(default, dtype=np.float64), (len(frames), 1))
    for i in range(size):
        fc = action.fcurves.find(_path(bone, prop), index=i)
        if fc is not None:
            out[:, i] = [fc.evaluate(f) for f in frames]
    return out


def _rotation(pose_bone, action, frames):
    """Quaternions (frames, 4) w,x,y,z of a bone in whatever rotation mode it is keyed."""
    mode = pose_bone.rotation_mode
    if mode == "QUATERNION":
        return _evaluate(action, pose_bone.name, "rotation_quaternion", 4, frames, pose_bone.rotation_quaternion)
    from mathutils import Euler, Quaternion
    if mode == "AXIS_ANGLE":
        aa = _evaluate(action, pose_bone.name, "rotation_axis_angle", 4, frames, pose_bone.rotation_axis_angle)
        return np.array([list(Quaternion(a[1:], a[0])) for a in aa])
    eul = _evaluate(action, pose_bone.name, "rotation_euler", 3, frames, pose_bone.rotation_euler)
    return np.array([list(Euler(e, mode).to_quaternion()) for e in eul])


def read(obj, action, bone_names, frames):
    """Quaternions (frames, nodes, 4) w,x,y,z and locations (frames, nodes, 3) of the action at
    `frames`, from its F-curves (what the action holds: constraints and drivers are not baked);
    the identity and zero for nodes without a bone (None)."""
    quat = np.zeros((len(frames), len(bone_names), 4))
    quat[..., 0] = 1.0
    loc = np.zeros((len(frames), len(bone_names), 3))
    for j, name in enumerate(bone_names):
        if name is None:
            continue
        pose_bone = obj.pose.bones[name]
        quat[:, j] = _rotation(pose_bone, action, frames)
        loc[:, j] = _evaluate(action, name, "location", 3, frames, pose_bone.location)
    return quat, loc


def set_timing(scene, fps, first, count):
    """Scene rate and range for `count` frames at `fps` starting at Blender frame `first`.
    Blender's rate is an integer over a divisor: a rate within 0.01% of a whole number (a CMU
    file's Frame Time .0083333 is 120.0005 fps) is taken as that number, as keyanim's decode
    --fps rule does; any other is fps / fps_base exactly."""
    whole = max(1, round(fps))
    scene.render.fps = whole
    scene.render.fps_base = 1.0 if abs(fps - whole) <= 1e-4 * fps else whole / fps
    scene.frame_start = first
    scene.frame_end = first + max(count, 1) - 1
    scene.frame_set(first)


def scene_fps(scene):
    return scene.render.fps / scene.render.fps_base
