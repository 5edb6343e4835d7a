#!/usr/bin/python3
"""Read a BVH, encode it, plot one channel's original curve against the decoded one (keys
marked), and print the encoder's error report.

    /usr/bin/python3 examples/plot_channel.py [IN.bvh] [--channel JOINT:CHANNEL] [--error E]
                                              [--rotations euler|quaternion] [-o OUT.png]

Defaults: the CMU walk shipped in data/, its LeftUpLeg:Xrotation, 0.05% of the skeleton size,
and plot_channel.png in the current directory. Rotations are encoded as Euler channels by
default (as `keyanim plot` does), so that a rotation channel's keys are its own angles; with
--rotations quaternion (encode()'s default, format 5.0) a joint's three rotation channels hold
the x, y, z of its rotation, and the dots mark the decoded angle at its key frames. Needs the
keyanim module (scripts/quickstart.sh installs it) and matplotlib (Debian: python3-matplotlib).
"""

import argparse
import json
import os
import sys

import matplotlib

matplotlib.use("Agg")  # files only, no display needed
import matplotlib.pyplot as plt
import numpy as np

import keyanim

HERE = os.path.dirname(os.path.abspath(__file__))


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("bvh", nargs="?", default=os.path.join(HERE, "..", "data", "cmu_02_01_walk.bvh"))
    p.add_argument("--channel", default="LeftUpLeg:Xrotation", help="JOINT:CHANNEL (default %(default)s)")
    p.add_argument("--error", default="0.05%", help="tolerance, E%% or units (default %(default)s)")
    p.add_argument("--rotations", default="euler", choices=("euler", "quaternion"),
                   help="how rotations are encoded (default %(default)s, as `keyanim plot`)")
    p.add_argument("-o", "--output", default="plot_channel.png", help="PNG to write (default %(default)s)")
    args = p.parse_args(argv)

    motion = keyanim.read_bvh(args.bvh)
    if args.channel not in motion.channel_names:
        p.error("%s has no channel %s; it has %s" % (args.bvh, args.channel, ", ".join(motion.channel_names)))
    data, report = keyanim.encode(motion, error=args.error, rotations=args.rotations)
    clip = keyanim.Clip(data)
    c = motion.channel_names.index(args.channel)

    frames = np.arange(motion.frame_count)
    fine = np.linspace(0, motion.frame_count - 1, 8 * motion.frame_count)  # in-betweens too
    key_frames, key_values = clip.channel_keys(c)
    if clip.channel(c)["stored"] != "value":  # a quaternion node's keys hold x, y or z, not degrees:
        key_values = clip.sample_frames(key_frames.astype(np.float64))[:, c]  # mark the angle there
    fig, ax = plt.subplots(figsize=(10, 4))
    ax.plot(frames, motion.channels[:, c], color="tab:blue", lw=2.5, alpha=0.5, label="original")
    ax.plot(fine, clip.sample_frames(fine)[:, c], color="tab:orange", lw=1, label="decoded")
    ax.plot(key_frames, key_values, "o", color="tab:orange", ms=3, label="%d keys" % len(key_frames))
    ax.set_xlabel("frame")
    ax.set_ylabel(args.channel + (" (degrees)" if "rotation" in args.channel else " (units)"))
    ax.set_title("%s: %d of %d frames keyed, max error %.3g units" % (
        os.path.basename(args.bvh), len(key_frames), motion.frame_count, report["error"]["max"]))
    ax.legend()
    fig.tight_layout()
    fig.savefig(args.output, dpi=100)
    print(json.dumps(report, indent=2))
    print("wrote %s" % args.output, file=sys.stderr)


if __name__ == "__main__":
    main()
