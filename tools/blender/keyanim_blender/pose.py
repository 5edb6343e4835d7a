"""BVH local transforms <-> Blender pose-bone transforms, and Euler channels, in float64 numpy.

A BVH joint's frame is the armature's axes at rest (OFFSETs only, no rest rotation). A Blender
bone's rest matrix in armature space is [B | head], B its rest orientation (Y along the bone).
Blender poses a bone as P = P_parent (M_parent^-1 M) basis, with M the rest matrices; asking
P = [W B | world position] for the BVH world rotation W gives, for a local rotation R and
translation t:
    basis rotation = B^T R B   (as a quaternion: w kept, vector part turned by B^T)
    basis location = B^T (t - OFFSET)
whatever B is, so bones may point along the limbs and stay exact (check with tests/blender).
"""
import numpy as np

from .skeleton import POSITIONS, ROTATIONS


def to_blender(q_xyzw, t, offsets, rest):
    """BVH local quaternions (frames, nodes, 4) x,y,z,w and translations (frames, nodes, 3) ->
    Blender basis quaternions (frames, nodes, 4) w,x,y,z and locations (frames, nodes, 3);
    rest: (nodes, 3, 3) bone rest orientations B in armature space."""
    q = np.asarray(q_xyzw, dtype=np.float64)
    t = np.asarray(t, dtype=np.float64)
    vec = np.einsum("nji,fnj->fni", rest, q[..., :3])          # B^T v
    quat = np.concatenate([q[..., 3:4], vec], axis=-1)
    loc = np.einsum("nji,fnj->fni", rest, t - offsets[None])   # B^T (t - OFFSET)
    return continuous(quat), loc


def from_blender(quat_wxyz, loc, offsets, rest):
    """The inverse of to_blender: BVH local quaternions (x, y, z, w) and translations."""
    quat = np.asarray(quat_wxyz, dtype=np.float64)
    quat = quat / np.linalg.norm(quat, axis=-1, keepdims=True)  # Blender normalises too
    vec = np.einsum("nij,fnj->fni", rest, quat[..., 1:])         # B v
    t = offsets[None] + np.einsum("nij,fnj->fni", rest, loc)
    return np.concatenate([vec, quat[..., :1]], axis=-1), t


def continuous(quat):
    """Flips quaternions whose dot with the previous frame's is negative (the same rotation), so
    that Blender's per-component interpolation between keys takes the short way."""
    quat = quat.copy()
    for f in range(1, quat.shape[0]):
        flip = np.sum(quat[f] * quat[f - 1], axis=-1) < 0
        quat[f, flip] *= -1
    return quat


def matrices(q_xyzw):
    """(..., 4) quaternions x, y, z, w -> (..., 3, 3) rotation matrices."""
    x, y, z, w = np.moveaxis(q_xyzw, -1, 0)
    return np.stack([
        np.stack([1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)], -1),
        np.stack([2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)], -1),
        np.stack([2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)], -1),
    ], -2)


def euler_degrees(r, order):
    """Angles (frames, 3) in degrees with r = R_order[0](a) R_order[1](b) R_order[2](c), the BVH
    reading of rotation channels in file order; order: three distinct axes 0..2. The middle
    angle is in [-90, 90]; the others are unwrapped over frames (no 360-degree jumps, which
    would cost keys)."""
    i, j, k = order
    s = 1.0 if (j - i) % 3 == 1 else -1.0  # xyz, yzx, zxy are cyclic; the others flip signs
    b = np.arcsin(np.clip(s * r[:, i, k], -1.0, 1.0))
    a = np.arctan2(-s * r[:, j, k], r[:, k, k])
    c = np.arctan2(-s * r[:, i, j], r[:, i, i])
    angles = np.degrees(np.stack([a, b, c], axis=-1))
    return np.degrees(np.unwrap(np.radians(angles), axis=0))


def rotation_order(kinds):
    """Axes of a node's rotation channels in file order, completed to three with the missing
    axes last (a joint with fewer rotation channels is exact when it turns about those only);
    None for a repeated axis, which these channels cannot be solved for."""
    axes = [ROTATIONS.index(k) for k in kinds if k in ROTATIONS]
    if len(set(axes)) != len(axes):
        return None
    return axes + [a for a in range(3) if a not in axes]


def channel_values(skeleton, q_xyzw, t):
    """The BVH channel matrix (frames, channels) of local transforms, in file order: angles in
    degrees by each joint's rotation order, positions as translation components (the replace
    reading: a position channel stands for that component of the OFFSET)."""
    columns = []
    for node, kinds in enumerate(skeleton.channels):
        if not kinds:
            continue
        order = rotation_order(kinds)
        angles = euler_degrees(matrices(q_xyzw[:, node]), order)
        rot_kinds = [k for k in kinds if k in ROTATIONS]
        for kind in kinds:
            if kind in POSITIONS:
                columns.append(t[:, node, POSITIONS.index(kind)])
            else:
                columns.append(angles[:, rot_kinds.index(kind)])
    return np.stack(columns, axis=-1) if columns else np.zeros((q_xyzw.shape[0], 0))
