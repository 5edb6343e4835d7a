"""keyanim: skeletal motion stored as keyframes only, rebuilt by Cardinal splines.

Read BVH exactly, encode it to the compact .kanim format within a world-space error you
choose, and sample clips at any time, with numpy arrays::

    import keyanim
    motion = keyanim.read_bvh("walk.bvh")            # Motion: channels (frames x channels) ...
    data, report = keyanim.encode(motion, error="0.05%")
    clip = keyanim.Clip(data)                         # or keyanim.Clip("walk.kanim")
    pose = clip.sample([0.0, 0.5, 1.25])              # float32 (3, channels)
    rotations, translations = clip.local_transforms([0.5])
    dataset = keyanim.Dataset("clips/", fps=30, window=64)
    keyanim.write_bank("walks.kbank", {"walk": clip})  # many clips in one file
    bank = keyanim.Bank("walks.kbank")                  # bank.names, bank.clip("walk")

Nodes are the joints and End Sites of the file, in file order; angles are degrees and lengths
the file's units. Failures raise keyanim.Error (a ValueError carrying file:line:column for BVH,
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
