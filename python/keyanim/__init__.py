"""keyanim: skeletal motion stored as keyframes only, rebuilt by Cardinal splines.

Read BVH exactly, encode it to the compact .kanim format within a world-space error you
choose, and sample clips at any time, with numpy arrays::

    import keyanim
    motion = keyanim.read_bvh("walk.bvh")            # Motion: channels (frames x channels) ...
    data, report = keyanim.encode(motion, error="0.05%")  # rotations="quaternion" (5.0) or "euler" (3.0)
    clip = keyanim.Clip(data)                         # or keyanim.Clip("walk.kanim")
    pose = clip.sample([0.0, 0.5, 1.25])              # float32 (3, channels): Euler angles, positions
    stored = clip.sample_stored([0.5])                # what the keys hold; clip.quat_nodes says where
    rotations, translations = clip.local_transforms([0.5])
    dataset = keyanim.Dataset("clips/", fps=30, window=64)
    keyanim.write_bank("walks.kbank", {"walk": clip})  # many clips in one file
    bank = keyanim.Bank("walks.kbank")                  # bank.names, bank.clip("walk")

Nodes are the joints and End Sites of the file, in file order; angles are degrees and lengths
the file's units. By default encode() stores each joint with three rotation channels (about
three axes) as a quaternion node (format 5.0): its three channels' keys hold the x, y, z of its
rotation relative to a reference (Clip.quat_nodes, Clip.channel(c)["stored"]). Sampling still
gives every rotation channel's Euler angle, computed at each position (Clip.sample_stored gives
the stored x, y, z); Clip.to_motion keeps the angles continuous from frame to frame, as BVH has
them. encode(..., rotations="euler") keeps every channel's own keys (format 3.0, which older
decoders read). Failures raise keyanim.Error (a ValueError carrying file:line:column for BVH,
section and byte offset for .kanim) or OSError for files that cannot be read or written.
"""

from ._keyanim import (
    Bank,
    Clip,
    Error,
    Motion,
    RigCache,
    __version__,
    encode,
    format_version,
    measure_error,
    read_bvh,
    write_bank,
)
from .dataset import Dataset

__all__ = [
    "Bank",
    "Clip",
    "Dataset",
    "Error",
    "Motion",
    "RigCache",
    "encode",
    "format_version",
    "measure_error",
    "read_bvh",
    "write_bank",
]
