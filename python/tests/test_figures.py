"""The tool's figures against what the module and an independent forward kinematics compute:
`keyanim plot`'s line on what one channel's reconstruction does in world space (issue 28, item
16: a flat reconstruction beside a varying original must say whether it is within the
tolerance)."""

import re

import numpy as np
import pytest

from conftest import WALK, cli, independent_error, parse_bvh


# `keyanim plot` encodes with --rotations euler unless told otherwise (it draws a channel's own
# keys); the module's encode() stores quaternion nodes by default. Each is compared with the
# module's encoding of the same rotations.
@pytest.mark.parametrize("rotations,options", [("euler", []), ("quaternion", ["--rotations", "quaternion"])])
def test_plot_states_the_world_error_of_the_channel_alone(keyanim, walk, tmp_path, rotations, options):
    svg = tmp_path / "hand.svg"
    r = cli("plot", WALK, "--channel", "LeftHand:Xrotation", "--error", "0.5%", *options, "-o", svg)
    m = re.search(r"alone, it moves a point by ([0-9.e+-]+) at most \((.*), frame (\d+)\), ([0-9.e+-]+)x the "
                  r"tolerance ([0-9.e+-]+)", r.stderr)
    assert m, r.stderr
    moved, share, tolerance = float(m[1]), float(m[4]), float(m[5])
    text = svg.read_text()
    assert "this channel&apos;s reconstruction alone moves a point by" in text or \
        "this channel's reconstruction alone moves a point by" in text, text[:2000]
    assert "x the tolerance" in text

    # The same encoding through the module; only this channel replaced by its reconstruction,
    # measured by the tests' own forward kinematics over joints, End Sites and shell points.
    data, report = keyanim.encode(walk, error="0.5%", rotations=rotations)
    assert abs(report["tolerance"] - tolerance) <= 1e-5 * tolerance
    channel = walk.channel_names.index("LeftHand:Xrotation")
    clip = keyanim.Clip(data)
    assert (clip.channel(channel)["stored"] == "value") == (rotations == "euler")  # (ZYX: it holds z)
    decoded = clip.sample_frames(np.arange(walk.frame_count, dtype=np.float64))[:, channel]
    bvh = parse_bvh(WALK)
    mixed = bvh.values.copy()
    mixed[:, channel] = decoded
    expected = independent_error(bvh, mixed, report["error"]["shell"])
    assert 0 < expected < tolerance
    assert abs(moved - expected) <= 1e-4 * expected, (moved, expected)
    assert abs(share - expected / tolerance) <= 1e-4 * share
