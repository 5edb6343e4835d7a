"""The skeleton an armature stands for, for the export: the BVH data the import kept on its
bones, or, for an armature made in Blender, one read from its bones (documented in README)."""
import numpy as np

from .skeleton import Skeleton

ROOT_CHANNELS = ["Xposition", "Yposition", "Zposition", "Zrotation", "Xrotation", "Yrotation"]
JOINT_CHANNELS = ["Zrotation", "Xrotation", "Yrotation"]


def _from_properties(bones):
    """(Skeleton, bone name per node) from keyanim_* properties, or None when a bone lacks them."""
    if not bones or any("keyanim_index" not in b for b in bones):
        return None
    order = sorted(bones, key=lambda b: b["keyanim_index"])
    index = {b.name: i for i, b in enumerate(order)}
    skeleton = Skeleton(
        names=[str(b["keyanim_name"]) for b in order],
        parents=[index[b.parent.name] if b.parent else -1 for b in order],
        offsets=np.array([list(b["keyanim_offset"]) for b in order], dtype=np.float64),
        end_site=[bool(b["keyanim_end_site"]) for b in order],
        channels=[str(b["keyanim_channels"]).split() for b in order])
    return skeleton, [b.name for b in order]


def _from_bones(bones):
    """A skeleton of any armature: a joint per bone at its head (OFFSET: head minus the parent's
    head, in armature space), the root with positions and ZXY rotations, the others with ZXY
    rotations, and an End Site at each leaf bone's tail; nodes in the order BVH text lists them
    (depth first, an End Site right after its joint)."""
    s = Skeleton([], [], [], [], [])
    bone_of = []

    def add(name, parent, offset, end, kinds, bone):
        s.names.append(name)
        s.parents.append(parent)
        s.offsets.append(offset)
        s.end_site.append(end)
        s.channels.append(kinds)
        bone_of.append(bone)
        return len(s.names) - 1

    def walk(b, parent):
        head = np.array(b.head_local, dtype=np.float64)
        base = np.array(b.parent.head_local, dtype=np.float64) if b.parent else np.zeros(3)
        j = add(b.name, parent, head - base, False, list(JOINT_CHANNELS if b.parent else ROOT_CHANNELS), b.name)
        for c in b.children:
            walk(c, j)
        if not b.children:  # no bone: it follows its joint
            add("End Site of " + b.name, j, np.array(b.tail_local, dtype=np.float64) - head, True, [], None)

    for root in [b for b in bones if b.parent is None]:
        walk(root, -1)
    s.offsets = np.array(s.offsets, dtype=np.float64).reshape(len(s.names), 3)
    return s, bone_of


def skeleton_of(obj):
    """(Skeleton, bone name per node, None for an End Site without a bone of its own)."""
    bones = list(obj.data.bones)
    return _from_properties(bones) or _from_bones(bones)
