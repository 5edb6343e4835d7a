"""keyanim.Dataset: fixed-length windows over many clips, for training loops."""

import math
import operator
import os
import stat
from concurrent.futures import ThreadPoolExecutor

import numpy as np

from ._keyanim import Bank, Clip, Error, read_bvh

OUTPUTS = ("channels", "local_quaternions", "local_translations", "world_positions")
_KANIM_SIGNATURE = b"\x89KAN"
_SUFFIXES = (".kanim", ".kbank", ".bvh")


def _kind(path):
    """'bank' (Header_Flags bit 2, spec section 10.2, or a .kbank name), 'kanim' (the
    signature) or 'bvh' (anything else, which the BVH reader then judges)."""
    # Only a regular file: a FIFO would block the open (and its read) for ever, a device such
    # as /dev/zero never end.
    if not stat.S_ISREG(os.stat(path).st_mode):
        raise Error("%s: not a regular file" % os.fsdecode(path))
    with open(path, "rb") as f:
        head = f.read(16)
    if (head[:4] == _KANIM_SIGNATURE and len(head) == 16 and head[12] & 4) or path.lower().endswith(".kbank"):
        return "bank"
    return "kanim" if head[:4] == _KANIM_SIGNATURE else "bvh"


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
    """The files: every .kanim, .kbank and .bvh below a directory (sorted), or the paths given."""
    if isinstance(paths_or_directory, (str, bytes, os.PathLike)):
        root = os.fspath(paths_or_directory)
        if not os.path.isdir(root):
            return [root]
        found = []
        for dirpath, _, filenames in os.walk(root):
            for name in filenames:
                lower = os.fsdecode(name).lower()
                full = os.path.join(dirpath, name)
                if lower.endswith(_SUFFIXES) and os.path.isfile(full):
                    found.append(full)  # regular files only (a FIFO named x.bvh is left out)
        return sorted(found)
    return [os.fspath(p) for p in paths_or_directory]


def _sources(path):
    """What `path` holds, one (path, kind, bank, index, name) per clip: a bank's clips in its
    order (the bank opened, no clip read yet), else the file alone (bank, index, name None)."""
    path = os.fsdecode(path)  # a bytes path is a path, not a clip's bytes (Clip(bytes))
    kind = _kind(path)
    if kind != "bank":
        return [(path, kind, None, None, None)]
    bank = Bank(path)
    return [(path, kind, bank, i, name) for i, name in enumerate(bank.names)]


def _load(source):
    """A bank's clip; a .kanim as it is; anything else read as BVH once and kept as a clip with
    every frame a key (Clip.from_motion)."""
    path, kind, bank, index, _ = source
    if kind == "bank":
        return bank.clip(index)
    if kind == "kanim":
        return Clip(path)
    return Clip.from_motion(read_bvh(path))


def _rig_hash(skeleton):
    if skeleton is None:
        return None
    if isinstance(skeleton, (bool, np.bool_)):
        raise ValueError("skeleton must be None or a rig hash (an int, as Clip.rig_hash), got %r" % (skeleton,))
    try:
        return operator.index(skeleton)
    except TypeError:
        raise ValueError("skeleton must be None or a rig hash (an int, as Clip.rig_hash), got %r" % (skeleton,)) from None


class Dataset:
    """Dataset(paths_or_directory, fps=None, window=64, stride=None, output="channels",
    skeleton=None)

    Windows of `window` frames over many clips: .kanim files, banks (.kbank: every clip of the
    bank, in its order) and BVH files (each read once and kept as a clip holding every source
    frame). `paths_or_directory` is one file, a directory (every .kanim, .kbank and .bvh below
    it, sorted) or a list of files; a bank is known by its header, whatever its name.

    fps: None samples each clip at its own source frames; a rate samples every clip at frames
      every 1/fps seconds from its start (in-betweens come from the curves), as
      Clip.to_motion(fps) does.
    window, stride: each window holds `window` frames at that rate; a window starts every
      `stride` frames (default: window, windows that do not overlap). A clip shorter than one
      window gives none.
    output: what dataset[i] returns, one name or a tuple of names (then a tuple of arrays):
      "channels"            float32 (window, channels): the channel values, as
                            Clip.sample_frames gives them (see below)
      "local_quaternions"   float32 (window, nodes, 4): local rotations (x, y, z, w)
      "local_translations"  float32 (window, nodes, 3)
      "world_positions"     float32 (window, nodes, 3)
    position_channels: "replace" (default) or "add", as Clip.local_transforms.
    workers: threads that load the clips (default: one per core; loading releases the GIL).
    skeleton: None (every clip) or a rig hash (an int, as Clip.rig_hash): only the clips of that
      skeleton, so that every window has one shape. A rig hash names a skeleton whatever file or
      bank it comes from, and stays valid across datasets and pickling.

    Channels: a BVH file's angles are unwrapped (consecutive frames differ by less than 180
    degrees), as are those of .kanim clips encoded with rotations='euler'. A joint that the
    encoder stored as a quaternion node (format 5.0, encode()'s default: Clip.quat_nodes) has
    its rotation channels' Euler angles computed from its rotation, continuous within a window
    (Clip.sample_frames(..., continuous=True): each frame's angles nearest the frame before's,
    as Clip.to_motion() and a BVH file have them); a window's first frame has the middle angle
    in [-90, 90], so two windows may start on different (equivalent) angles. To learn
    rotations, "local_quaternions" are continuous for every joint.

    len(dataset) counts the windows; dataset[i] samples only the window's frames of one clip
    (the GIL released), never a whole clip. `clips`, `paths` (the file of each clip; a bank's
    path for its clips), `names` (each clip's name in its bank, None for a file of its own) and
    `locate(i)` say where a window comes from; `files` lists the files read.

    Mixed skeletons: arrays then differ in shape between clips (over the corpus, channels from
    (64, 6) to (64, 132)), which a DataLoader's default collate cannot stack. `skeletons` lists the rig hashes of the clips found, in order of first
    appearance (those left out by skeleton= too). Either make one dataset per skeleton,
    Dataset(path, skeleton=h) for h in Dataset(path).skeletons, or keep them together and
    batch per skeleton: DataLoader(ds, batch_sampler=ds.batches(32, shuffle=True)), whose
    every batch holds windows of one skeleton (see batches()).

    A dataset pickles as its settings and files (the files are read again on unpickling), so
    that a DataLoader's worker processes can take it.
    """

    def __init__(self, paths_or_directory, fps=None, window=64, stride=None, output="channels",
                 position_channels="replace", workers=None, skeleton=None):
        self._settings = dict(fps=fps, window=window, stride=stride, output=output,
                              position_channels=position_channels, workers=workers, skeleton=skeleton)
        self.files = _collect(paths_or_directory)
        if not self.files:
            raise ValueError("no .kanim, .kbank or .bvh files in %r" % (paths_or_directory,))
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
        wanted = _rig_hash(skeleton)
        self.fps, self.window, self.stride, self.skeleton = fps, window, stride, wanted
        self._names, self._single = names, isinstance(output, str)
        self._reading = position_channels
        sources = [source for path in self.files for source in _sources(path)]
        with ThreadPoolExecutor(max_workers=workers or os.cpu_count() or 1) as pool:
            clips = list(pool.map(_load, sources))
        self.skeletons = list(dict.fromkeys(clip.rig_hash for clip in clips))
        kept = [i for i, clip in enumerate(clips) if wanted is None or clip.rig_hash == wanted]
        if not kept:
            raise ValueError("no clip has the skeleton %#x; the files' skeletons (rig hashes): %s"
                             % (wanted, ", ".join("%#x" % h for h in self.skeletons)))
        self.clips = [clips[i] for i in kept]
        self.paths = [sources[i][0] for i in kept]
        self.names = [sources[i][4] for i in kept]
        counts = [self._windows_in(clip, path) for clip, path in zip(self.clips, self.paths)]
        self._counts = np.asarray(counts, dtype=np.int64)
        self._ends = np.cumsum(self._counts)

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
                out[name] = clip.sample_frames(at, continuous=True)
            elif name == "world_positions":
                out[name] = clip.world_positions(frames=at, position_channels=self._reading)
            elif name not in out:
                q, t = clip.local_transforms(frames=at, position_channels=self._reading)
                out["local_quaternions"], out["local_translations"] = q, t
        arrays = tuple(out[name] for name in self._names)
        return arrays[0] if self._single else arrays

    def __repr__(self):
        return "<keyanim.Dataset: %d windows of %d frames over %d clips%s%s>" % (
            len(self), self.window, len(self.clips), "" if self.fps is None else " at %g fps" % self.fps,
            "" if self.skeleton is None else " of skeleton %#x" % self.skeleton)

    def batches(self, batch_size, shuffle=False, drop_last=False, seed=None):
        """Window indices in batches of one skeleton each: a PyTorch DataLoader's batch_sampler
        (DataLoader(ds, batch_sampler=ds.batches(32))), so that its default collate stacks
        arrays of one shape. Each skeleton's windows are cut into batches of `batch_size` (its
        last one smaller, or left out with drop_last). Without shuffle, in window order, one
        skeleton after another (in the order of `skeletons`); with it, every pass over the
        batches shuffles the windows within each skeleton and then the order of the batches,
        from numpy's generator seeded with `seed`."""
        return SkeletonBatches(self, _whole(batch_size, "batch_size"), shuffle, drop_last, seed)

    def __getstate__(self):
        return {"files": self.files, "settings": self._settings}

    def __setstate__(self, state):
        self.__init__(state["files"], **state["settings"])


class SkeletonBatches:
    """Dataset.batches(...): an iterable of lists of window indices, each list's windows of one
    skeleton; len() is the number of batches in a pass."""

    def __init__(self, dataset, batch_size, shuffle, drop_last, seed):
        order = {h: k for k, h in enumerate(dataset.skeletons)}
        per_clip = np.array([order[clip.rig_hash] for clip in dataset.clips], dtype=np.int64)
        per_window = np.repeat(per_clip, dataset._counts)
        self._groups = [np.flatnonzero(per_window == k) for k in sorted(set(per_clip.tolist()))]
        self.batch_size, self.shuffle, self.drop_last = batch_size, bool(shuffle), bool(drop_last)
        self._rng = np.random.default_rng(seed)

    def _cut(self, windows):
        size = self.batch_size
        end = len(windows) - len(windows) % size if self.drop_last else len(windows)
        return [windows[i:i + size].tolist() for i in range(0, end, size)]

    def __iter__(self):
        batches = []
        for windows in self._groups:
            batches += self._cut(self._rng.permutation(windows) if self.shuffle else windows)
        if self.shuffle:
            batches = [batches[i] for i in self._rng.permutation(len(batches))]
        return iter(batches)

    def __len__(self):
        size = self.batch_size
        return sum(len(g) // size if self.drop_last else -(-len(g) // size) for g in self._groups)
