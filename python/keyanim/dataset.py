"""keyanim.Dataset: fixed-length windows over many clips, for training loops."""

import math
import operator
import os
import stat
from concurrent.futures import ThreadPoolExecutor

import numpy as np

from ._keyanim import Clip, Error, read_bvh

OUTPUTS = ("channels", "local_quaternions", "local_translations", "world_positions")
_KANIM_SIGNATURE = b"\x89KAN"


def _is_kanim(path):
    # Only a regular file: a FIFO would block the open (and its read) for ever, a device such
    # as /dev/zero never end.
    if not stat.S_ISREG(os.stat(path).st_mode):
        raise Error("%s: not a regular file" % os.fsdecode(path))
    with open(path, "rb") as f:
        return f.read(4) == _KANIM_SIGNATURE


def _whole(value, name):
    """An integer >= 1: int or numpy integer (anything with __index__), not bool."""
    whole = None
    if not isinstance(value, (bool, np.bool_)):
        try:
            whole = operator.index(value)
        except TypeError:
            pass
    if whole is None or whole < 1:
        raise ValueError("%s must be an integer >= 1, got %r" % (name, value))
    return whole


def _collect(paths_or_directory):
    """The clip files: every .kanim and .bvh below a directory (sorted), or the paths given."""
    if isinstance(paths_or_directory, (str, bytes, os.PathLike)):
        root = os.fspath(paths_or_directory)
        if not os.path.isdir(root):
            return [root]
        found = []
        for dirpath, _, filenames in os.walk(root):
            for name in filenames:
                lower = os.fsdecode(name).lower()
                full = os.path.join(dirpath, name)
                if (lower.endswith(".kanim") or lower.endswith(".bvh")) and os.path.isfile(full):
                    found.append(full)  # regular files only (a FIFO named x.bvh is left out)
        return sorted(found)
    return [os.fspath(p) for p in paths_or_directory]


def _load(path):
    """A .kanim (recognised by its signature) as it is; anything else read as BVH once and kept
    as a clip with every frame a key (Clip.from_motion)."""
    path = os.fsdecode(path)  # a bytes path is a path, not a clip's bytes (Clip(bytes))
    if _is_kanim(path):
        return Clip(path)
    return Clip.from_motion(read_bvh(path))


class Dataset:
    """Dataset(paths_or_directory, fps=None, window=64, stride=None, output="channels")

    Windows of `window` frames over many clips: .kanim files, and BVH files (each read once and
    kept as a clip holding every source frame). `paths_or_directory` is a directory (every
    .kanim and .bvh below it, sorted) or a list of files.

    fps: None samples each clip at its own source frames; a rate samples every clip at frames
      every 1/fps seconds from its start (in-betweens come from the curves), as
      Clip.to_motion(fps) does.
    window, stride: each window holds `window` frames at that rate; a window starts every
      `stride` frames (default: window, windows that do not overlap). A clip shorter than one
      window gives none.
    output: what dataset[i] returns, one name or a tuple of names (then a tuple of arrays):
      "channels"            float32 (window, channels): the channel values (angles unwrapped)
      "local_quaternions"   float32 (window, nodes, 4): local rotations (x, y, z, w)
      "local_translations"  float32 (window, nodes, 3)
      "world_positions"     float32 (window, nodes, 3)
    position_channels: "replace" (default) or "add", as Clip.local_transforms.
    workers: threads that load the files (default: one per core; loading releases the GIL).

    len(dataset) counts the windows; dataset[i] samples only the window's frames of one clip
    (the GIL released), never a whole clip. `clips`, `paths` and `locate(i)` say where a window
    comes from. Clips may have different skeletons: arrays then differ in shape between clips.
    A dataset pickles as its settings and paths (the files are read again on unpickling), so
    that a DataLoader's worker processes can take it.
    """

    def __init__(self, paths_or_directory, fps=None, window=64, stride=None, output="channels",
                 position_channels="replace", workers=None):
        self._settings = dict(fps=fps, window=window, stride=stride, output=output,
                              position_channels=position_channels, workers=workers)
        self.paths = _collect(paths_or_directory)
        if not self.paths:
            raise ValueError("no .kanim or .bvh files in %r" % (paths_or_directory,))
        window = _whole(window, "window")
        stride = window if stride is None else _whole(stride, "stride")
        if fps is not None and not (isinstance(fps, (int, float)) and math.isfinite(fps) and fps > 0):
            raise ValueError("fps must be None or a positive number, got %r" % (fps,))
        names = (output,) if isinstance(output, str) else tuple(output)
        for name in names:
            if name not in OUTPUTS:
                raise ValueError("output %r is not one of %s" % (name, ", ".join(OUTPUTS)))
        if not names:
            raise ValueError("output names nothing to return")
        if position_channels not in ("replace", "add"):
            raise ValueError("position_channels must be 'replace' or 'add', got %r" % (position_channels,))
        self.fps, self.window, self.stride = fps, window, stride
        self._names, self._single = names, isinstance(output, str)
        self._reading = position_channels
        with ThreadPoolExecutor(max_workers=workers or os.cpu_count() or 1) as pool:
            self.clips = list(pool.map(_load, self.paths))
        counts = [self._windows_in(clip, path) for clip, path in zip(self.clips, self.paths)]
        self._ends = np.cumsum(counts, dtype=np.int64)

    def _frames_at_rate(self, clip, path):
        """Frames of `clip` at the dataset's rate (decode.h's rule for fps)."""
        if self.fps is None or clip.frame_count <= 1:
            return clip.frame_count
        if not clip.frame_time > 0:
            raise Error("%s: the clip has no frame time; cannot sample it at %g fps" % (path, self.fps))
        return clip.frame_count_at(self.fps)

    def _windows_in(self, clip, path):
        frames = self._frames_at_rate(clip, path)
        return 0 if frames < self.window else (frames - self.window) // self.stride + 1

    def __len__(self):
        return int(self._ends[-1])

    def locate(self, index):
        """(clip index, first frame of window `index` at the dataset's rate)."""
        n = len(self)
        if not isinstance(index, (int, np.integer)) or isinstance(index, bool):
            raise TypeError("dataset indices must be integers, not %s" % type(index).__name__)
        if index < 0:
            index += n
        if not 0 <= index < n:
            raise IndexError("window %d is out of range for %d windows" % (index, n))
        clip = int(np.searchsorted(self._ends, index, side="right"))
        start = int(self._ends[clip - 1]) if clip > 0 else 0
        return clip, (int(index) - start) * self.stride

    def positions(self, index):
        """The source frame positions (float64) that window `index` samples."""
        c, first = self.locate(index)
        clip = self.clips[c]
        return clip.frame_positions_at(self.fps, np.arange(first, first + self.window, dtype=np.int64))

    def __getitem__(self, index):
        c, _ = self.locate(index)
        clip, at = self.clips[c], self.positions(index)
        out = {}
        for name in self._names:
            if name == "channels":
                out[name] = clip.sample_frames(at)
            elif name == "world_positions":
                out[name] = clip.world_positions(frames=at, position_channels=self._reading)
            elif name not in out:
                q, t = clip.local_transforms(frames=at, position_channels=self._reading)
                out["local_quaternions"], out["local_translations"] = q, t
        arrays = tuple(out[name] for name in self._names)
        return arrays[0] if self._single else arrays

    def __repr__(self):
        return "<keyanim.Dataset: %d windows of %d frames over %d clips%s>" % (
            len(self), self.window, len(self.clips), "" if self.fps is None else " at %g fps" % self.fps)

    def __getstate__(self):
        return {"paths": self.paths, "settings": self._settings}

    def __setstate__(self, state):
        self.__init__(state["paths"], **state["settings"])
