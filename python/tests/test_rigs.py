"""Clips of one rig share one skeleton through a RigCache, and rig_hash is the FNV-1a that
keyanim/clip.h describes, computed here again from the skeleton's properties."""

import struct

import numpy as np

from conftest import HOP

CHANNEL_TYPES = ["Xposition", "Yposition", "Zposition", "Xrotation", "Yrotation", "Zrotation"]


def fnv1a(data, h=0xCBF29CE484222325):
    for b in data:
        h = ((h ^ b) * 0x100000001B3) % (1 << 64)
    return h


def rig_hash(clip):
    """clip.h: per node its name, parent, OFFSET bits, End Site flag and channel list."""
    names, end, parents, offsets = clip.joint_names, clip.is_end_site, clip.parents, clip.offsets
    channels = [[] for _ in names]
    node_of = {n: i for i, n in enumerate(names)}
    for c in clip.channel_names:
        joint, kind = c.rsplit(":", 1)
        channels[node_of[joint]].append(CHANNEL_TYPES.index(kind))
    u64 = lambda x: struct.pack("<Q", x % (1 << 64))
    data = bytearray(u64(len(names)))
    for i, name in enumerate(names):
        raw = b"" if end[i] else name.encode()  # the data's End Sites are unnamed ("End Site of ...")
        data += u64(len(raw)) + raw + u64(int(parents[i]))
        data += struct.pack("<3d", *offsets[i]) + u64(int(end[i])) + u64(len(channels[i])) + bytes(channels[i])
    return fnv1a(bytes(data))


def test_clips_of_one_rig_share_it(keyanim, walk, walk_encoded):
    coarse = keyanim.encode(walk, error="0.5%")[0]
    hop = keyanim.encode(keyanim.read_bvh(HOP))[0]
    rigs = keyanim.RigCache()
    a, b = keyanim.Clip(walk_encoded[0], rigs=rigs), keyanim.Clip(coarse, rigs=rigs)
    h = keyanim.Clip(hop, rigs=rigs)
    assert a.shares_rig(b) and not a.shares_rig(h)
    assert rigs.rig_count == 2
    alone = keyanim.Clip(walk_encoded[0])
    assert not alone.shares_rig(a)
    assert alone.rig_hash == a.rig_hash == b.rig_hash != h.rig_hash
    for x, y in zip(alone.local_transforms(frames=[3.5, 40.25]), a.local_transforms(frames=[3.5, 40.25])):
        assert np.array_equal(x, y)  # rotations, then translations
    del a, b, h
    assert rigs.rig_count == 0


def test_rig_hash_is_the_documented_fnv1a(keyanim, walk_clip):
    assert walk_clip.rig_hash == rig_hash(walk_clip)
    hop = keyanim.Clip(keyanim.encode(keyanim.read_bvh(HOP))[0])
    assert hop.rig_hash == rig_hash(hop)
