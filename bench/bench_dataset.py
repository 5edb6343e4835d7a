#!/usr/bin/python3
"""Dataset benchmark: training windows per second from keyanim.Dataset over .kanim files, over
BVH files read once (kept in memory as clips), and from the same windows read from BVH by the
module's own reader at every access (keyanim.read_bvh, then the window's rows): what a loader
without a cache does.

    /usr/bin/python3 bench/bench_dataset.py [FILE.bvh|DIR ...] [--window 64] [--fps F]
        [--windows 2000] [--reread 200] [--output channels] [--error 0.05%] [--seed 1]

Inputs default to every .bvh of the shared corpus (KEYANIM_CORPUS_DIR, else ../shared/corpus
beside the checkout), or data/ without it. The .kanim files are encoded first (not timed). The
same randomly chosen windows are read in each way: --windows of them from the datasets,
--reread of them through read_bvh (each one parses a whole file).

Prints one JSON object. Times are CPU seconds of the calling thread (time.thread_time: the
datasets sample on it; indexing: of the process), which other processes on a shared machine
disturb less than wall time; they are still noisy there. Fields: windows_per_second of kanim, bvh_in_memory and bvh_reread,
and kanim_over_bvh_reread, their ratio.
"""

import argparse
import json
import os
import sys
import tempfile
import time
import warnings

import numpy as np

import keyanim

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.dirname(HERE)


def default_inputs():
    corpus = os.environ.get("KEYANIM_CORPUS_DIR", os.path.join(REPO, "..", "shared", "corpus"))
    return [corpus] if os.path.isdir(corpus) else [os.path.join(REPO, "data")]


def bvh_files(inputs):
    files = []
    for p in inputs:
        if os.path.isdir(p):
            files += [os.path.join(d, f) for d, _, names in os.walk(p) for f in names if f.lower().endswith(".bvh")]
        else:
            files.append(p)
    return sorted(files)


def cpu_rate(count, read):
    """Windows per CPU second of this thread, reading `count` windows with read(k)."""
    t0 = time.thread_time()
    for k in range(count):
        read(k)
    seconds = time.thread_time() - t0
    return {"windows": count, "cpu_seconds": seconds, "windows_per_second": count / seconds if seconds > 0 else None}


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("inputs", nargs="*")
    p.add_argument("--window", type=int, default=64)
    p.add_argument("--fps", type=float, default=None)
    p.add_argument("--windows", type=int, default=2000)
    p.add_argument("--reread", type=int, default=200)
    p.add_argument("--output", default="channels", choices=["channels", "local_quaternions", "world_positions"])
    p.add_argument("--error", default="0.05%")
    p.add_argument("--seed", type=int, default=1)
    args = p.parse_args(argv)

    files = bvh_files(args.inputs or default_inputs())
    with tempfile.TemporaryDirectory() as tmp, warnings.catch_warnings():
        warnings.simplefilter("ignore")  # BVH files with more motion lines than declared
        kanims, bvh_bytes, kanim_bytes, frames = [], 0, 0, 0
        for i, f in enumerate(files):
            data, report = keyanim.encode(keyanim.read_bvh(f), error=args.error)
            kanims.append(os.path.join(tmp, "%03d.kanim" % i))
            with open(kanims[-1], "wb") as out:
                out.write(data)
            bvh_bytes += os.path.getsize(f)
            kanim_bytes += len(data)
            frames += report["frames"]

        settings = dict(fps=args.fps, window=args.window, output=args.output)
        # Indexing loads the files on a worker thread: CPU time of the whole process.
        t0 = time.process_time()
        kanim_ds = keyanim.Dataset(kanims, workers=1, **settings)
        kanim_index = time.process_time() - t0
        t0 = time.process_time()
        bvh_ds = keyanim.Dataset(files, workers=1, **settings)
        bvh_index = time.process_time() - t0
        assert len(kanim_ds) == len(bvh_ds), "the same files give the same windows"
        if len(bvh_ds) == 0:
            sys.exit("bench_dataset: no window of %d frames in the inputs" % args.window)

        rng = np.random.default_rng(args.seed)
        picks = [int(i) for i in rng.integers(0, len(bvh_ds), max(args.windows, args.reread))]

        def reread(k):
            """The window read from BVH at every access by the module's reader."""
            c, first = bvh_ds.locate(picks[k])
            m = keyanim.read_bvh(files[c])
            if args.fps is None and args.output == "channels":
                return m.channels[first:first + args.window]
            at = bvh_ds.positions(picks[k])  # another rate, or poses: through a clip of the motion
            clip = keyanim.Clip.from_motion(m)
            if args.output == "channels":
                return clip.sample_frames(at)
            if args.output == "world_positions":
                return clip.world_positions(frames=at)
            return clip.local_transforms(frames=at)[0]

        # The in-memory BVH dataset and the re-read give the same windows (checked on a few).
        for k in range(min(5, args.reread)):
            a, b = bvh_ds[picks[k]], reread(k)
            assert a.shape == b.shape

        result = {
            "files": len(files),
            "frames": frames,
            "bvh_bytes": bvh_bytes,
            "kanim_bytes": kanim_bytes,
            "window": args.window,
            "fps": args.fps,
            "output": args.output,
            "error": args.error,
            "windows_in_dataset": len(bvh_ds),
            "timing": "CPU seconds of the calling thread (time.thread_time); noisy on a shared machine",
            "kanim": dict(cpu_rate(args.windows, lambda k: kanim_ds[picks[k]]), index_cpu_seconds=kanim_index,
                          memory_bytes=sum(c.memory_bytes for c in kanim_ds.clips)),
            "bvh_in_memory": dict(cpu_rate(args.windows, lambda k: bvh_ds[picks[k]]), index_cpu_seconds=bvh_index,
                                  memory_bytes=sum(c.memory_bytes for c in bvh_ds.clips)),
            "bvh_reread": cpu_rate(args.reread, reread),
        }
        k, r = result["kanim"]["windows_per_second"], result["bvh_reread"]["windows_per_second"]
        result["kanim_over_bvh_reread"] = k / r if k and r else None
        print(json.dumps(result, indent=2))


if __name__ == "__main__":
    main()
