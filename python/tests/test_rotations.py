"""Rotations stored as quaternions (format 5.0, spec/FORMAT.md 4.7): encode(rotations=...) as
`keyanim encode --rotations`, Clip.quat_nodes against the reference decoder
(spec/test-vectors/reference_decoder.py) and the version 5 vectors, sample_stored against the
keys and the vectors' values, and the poses of quaternion nodes against their stored x, y, z
by an independent formula in numpy."""

import json
import pathlib
import struct
import sys

import numpy as np
import pytest

from conftest import (HOP, WALK, assert_decoded_is_sampled, cli_json, euler_quaternions, quat_axes, rotation_angles,
                      stored_quaternions)

VECTORS = pathlib.Path(__file__).resolve().parents[2] / "spec" / "test-vectors"


@pytest.fixture(scope="module")
def reference_decoder():
    sys.path.insert(0, str(VECTORS))
    try:
        import reference_decoder as module
    finally:
        sys.path.remove(str(VECTORS))
    return module


def header(data):
    """(Major_Version, Minor_Version) of a .kanim (section 2.2)."""
    return struct.unpack_from("<HH", data, 8)


@pytest.mark.parametrize("rotations,options", [(None, []), ("quaternion", ["--rotations", "quaternion"]),
                                               ("euler", ["--rotations", "euler"])])
def test_rotations_as_the_tool(keyanim, walk, tmp_path, rotations, options):
    """rotations= gives the bytes and report of `keyanim encode --rotations`; the default is
    'quaternion', a 5.0 file; 'euler' a 3.0 file without quaternion nodes."""
    settings = {} if rotations is None else {"rotations": rotations}
    data, report = keyanim.encode(walk, error="0.5%", **settings)
    out = tmp_path / "walk.kanim"
    tool = cli_json("encode", WALK, "-o", out, "--error", "0.5%", *options, "--json")
    assert out.read_bytes() == data
    assert set(report) == set(tool) and report["error"] == tool["error"] and report["keys"] == tool["keys"]
    clip = keyanim.Clip(data)
    stored = {clip.channel(c)["stored"] for c in range(clip.channel_count)}
    if rotations == "euler":
        assert header(data) == (3, 0) and clip.info["version"] == "3.0" and clip.quat_nodes == []
        assert stored == {"value"}
        assert header(clip.runtime_bytes()) == (4, 0)
    else:
        assert header(data) == (5, 0) and clip.info["version"] == "5.0" == keyanim.format_version
        assert len(clip.quat_nodes) == 27 and stored == {"value", "quat_x", "quat_y", "quat_z"}
        assert header(clip.runtime_bytes()) == (5, 0)
    assert keyanim.Clip(out).info == cli_json("info", out, "--json")


def test_euler_and_quaternion_both_meet_the_tolerance(keyanim, walk):
    euler, quaternion = keyanim.encode(walk, rotations="euler"), keyanim.encode(walk, rotations="quaternion")
    assert quaternion[0] == keyanim.encode(walk)[0]  # the default
    for _, report in (euler, quaternion):
        assert report["error"]["max"] <= report["tolerance"]
    assert euler[0] != quaternion[0]


@pytest.mark.parametrize("bad", ["Euler", "QUATERNION", "quat", "", "euler ", "quaternions", "matrix"])
def test_a_bad_rotations_string_is_refused(keyanim, walk, bad):
    with pytest.raises(ValueError) as info:
        keyanim.encode(walk, rotations=bad)
    e = info.value
    assert isinstance(e, keyanim.Error) and e.kind == "invalid_argument"
    assert "rotations must be 'quaternion' or 'euler', got '%s'" % bad in str(e)


@pytest.mark.parametrize("bad", [None, 1, True, b"euler", ["euler"]])
def test_rotations_of_another_type_is_a_type_error(keyanim, walk, bad):
    with pytest.raises(TypeError, match="rotations must be 'quaternion' or 'euler'"):
        keyanim.encode(walk, rotations=bad)


def test_an_unknown_setting_names_rotations(keyanim, walk):
    with pytest.raises(TypeError, match=r"unexpected keyword argument 'rotation' \(settings: .*rotations"):
        keyanim.encode(walk, rotation="euler")


@pytest.mark.parametrize("profile", ["archive", "runtime"])
def test_quat_nodes_are_the_reference_decoders(keyanim, walk_clip, walk_encoded, reference_decoder, profile):
    """Clip.quat_nodes and channel_keys as the reference decoder reads the same bytes."""
    data = walk_encoded[0] if profile == "archive" else walk_clip.runtime_bytes()
    clip = keyanim.Clip(data)
    want = reference_decoder.parse(data)
    assert tuple(want["version"]) == (5, 0) and clip.info["version"] == "5.0"
    got = [(n["node"], list(n["reference"]), n["channels"][0]) for n in clip.quat_nodes]
    assert got == [(n["node"], n["reference"], n["column"]) for n in want["quat_nodes"]]
    assert clip.quat_nodes == walk_clip.quat_nodes
    for c in range(clip.channel_count):
        frames, values = clip.channel_keys(c)
        assert frames.tolist() == list(want["frames"][c])
        assert np.array_equal(values, np.array(want["values"][c], dtype=np.float32))


def test_quat_nodes_are_the_joints_that_move(walk_clip):
    """The walk's joints of three rotation channels are quaternion nodes, but for the four whose
    rotation never moves (zero channels), which stay Euler channels without keys."""
    quat = {n["node"] for n in walk_clip.quat_nodes}
    for node, name in enumerate(walk_clip.joint_names):
        channels = [c for c, n in enumerate(walk_clip.channel_names) if n.rsplit(":", 1)[0] == name]
        rotations = [c for c in channels if walk_clip.channel_names[c].endswith("rotation")]
        if node in quat:
            assert len(rotations) == 3 and rotations[2] - rotations[0] == 2
        elif rotations:
            assert [walk_clip.channel(c)["key_count"] for c in rotations] == [0, 0, 0], name
    assert len(quat) == 27


def test_sample_stored_at_the_keys_is_the_keys(walk_clip):
    for c in range(walk_clip.channel_count):
        frames, values = walk_clip.channel_keys(c)
        if len(frames):
            assert np.array_equal(walk_clip.sample_stored(frames.astype(np.float64))[:, c], values)
    assert walk_clip.sample_stored(10.5).shape == (96,) and walk_clip.sample_stored([[1.0, 2.0]]).shape == (1, 2, 96)
    assert walk_clip.sample_stored([]).shape == (0, 96)


def test_poses_of_quat_nodes_are_their_stored_rotations(walk_clip):
    """local_transforms gives a quaternion node the rotation reference * (x, y, z, w) of its
    stored values (4.7, computed in binary32 by the library, here in float64)."""
    frames = np.arange(0.0, 343.0, 0.75)
    q, _ = walk_clip.local_transforms(frames=frames)
    stored = walk_clip.sample_stored(frames)
    for node in walk_clip.quat_nodes:
        want = stored_quaternions(node["reference_quaternion"], stored[:, list(node["channels"])])
        assert rotation_angles(q[:, node["node"]], want).max() <= 2e-6, node["joint"]


def test_decoded_angles_are_continuous_and_sampled_ones_per_position(keyanim):
    """The hop turns past 180 degrees: sample_frames gives each position's Euler angles (the
    middle one in [-90, 90]), to_motion the same rotations with angles continuous from frame to
    frame, which then differ from the sampled ones by whole turns or the other Euler triple."""
    clip = keyanim.Clip(keyanim.encode(HOP, error="0.5%")[0])
    frames = np.arange(float(clip.frame_count))
    sampled, decoded = clip.sample_frames(frames), clip.to_motion().channels
    assert_decoded_is_sampled(clip, decoded, sampled)
    quat = [c for node in clip.quat_nodes for c in node["channels"]]
    assert np.abs(np.diff(sampled[:, quat], axis=0)).max() > 180  # a wrap between two frames
    assert np.abs(decoded[:, quat] - sampled[:, quat]).max() >= 359


def test_continuous_angles_are_the_decoded_ones(keyanim):
    """sample_frames(..., continuous=True) chooses each frame's angles nearest the frame
    before's, as to_motion() does: the decoded angles (computed in float64) within float32's
    rounding, no step of 180 degrees; a run restarts at each row of the positions' last axis."""
    clip = keyanim.Clip(keyanim.encode(HOP, error="0.5%")[0])
    frames = np.arange(float(clip.frame_count))
    plain, continuous = clip.sample_frames(frames), clip.sample_frames(frames, continuous=True)
    decoded = clip.to_motion().channels
    quat = [c for node in clip.quat_nodes for c in node["channels"]]
    # Without, wraps (steps past 180 degrees); with, each angle within 180 degrees of the frame before's
    # (steps near 180 remain where the rotation passes near the middle angle's +-90).
    assert np.abs(np.diff(plain[:, quat], axis=0)).max() > 200
    assert np.abs(np.diff(continuous[:, quat], axis=0)).max() <= 180.001
    assert np.abs(continuous[:, quat] - decoded[:, quat]).max() < 1e-3
    other = [c for c in range(clip.channel_count) if c not in quat]
    assert np.array_equal(continuous[:, other], plain[:, other])
    assert np.array_equal(clip.sample(frames * clip.frame_time, continuous=True)[:, quat], continuous[:, quat])
    # Two rows: the second starts where sample_frames would, then follows on.
    half = len(frames) // 2
    rows = clip.sample_frames(np.stack([frames[:half], frames[half:2 * half]]), continuous=True)
    assert np.array_equal(rows[1, 0], plain[half])
    assert np.array_equal(rows[0], continuous[:half])
    assert np.abs(np.diff(rows[1][:, quat], axis=0)).max() <= 180.001


def test_dataset_windows_are_continuous(keyanim, tmp_path):
    """A Dataset's "channels" windows of a quaternion clip are sample_frames(continuous=True)'s:
    no step of a whole turn, as there are between plain sample_frames' frames of this clip."""
    path = tmp_path / "hop.kanim"
    path.write_bytes(keyanim.encode(HOP, error="0.5%")[0])
    clip = keyanim.Clip(path)
    quat = [c for node in clip.quat_nodes for c in node["channels"]]
    ds = keyanim.Dataset([path], window=64, stride=16)
    assert len(ds) > 10
    for i in range(len(ds)):
        assert np.array_equal(ds[i], clip.sample_frames(ds.positions(i), continuous=True))
    worst = max(np.abs(np.diff(ds[i][:, quat], axis=0)).max() for i in range(len(ds)))
    plain = max(np.abs(np.diff(clip.sample_frames(ds.positions(i))[:, quat], axis=0)).max() for i in range(len(ds)))
    assert worst <= 180.001 and plain > 200, (worst, plain)


@pytest.mark.parametrize("name", ["v5_quat", "v5_blocks"])
def test_the_version_5_vectors(keyanim, name):
    """The reference decoder's expected values (the vectors' JSON): quaternion nodes, stored
    values at every position in the clip, and the nodes' rotations, in both profiles."""
    want = json.loads((VECTORS / f"{name}.json").read_text())
    archive, runtime = keyanim.Clip(VECTORS / f"{name}.kanim"), keyanim.Clip(VECTORS / f"{name}_runtime.kanim")
    assert runtime.runtime_bytes() == (VECTORS / f"{name}_runtime.kanim").read_bytes()
    for clip in (archive, runtime):
        assert clip.info["version"] == want["format_version"] == "5.0"
        assert [(n["node"], list(n["reference"])) for n in clip.quat_nodes] == \
               [(n["node"], n["reference"]) for n in want["quat_nodes"]]
        samples = [s for s in want["samples"] if 0 <= s["position"] <= clip.frame_count - 1]
        assert len(samples) > 100
        positions = np.array([s["position"] for s in samples])
        values = np.array([s["values"] for s in samples], dtype=np.float64)
        stored = clip.sample_stored(positions)
        assert np.array_equal(stored.astype(np.float64), values)
        rotations = np.array([s["rotations"] for s in samples])  # (positions, quaternion nodes, 4)
        q, _ = clip.local_transforms(frames=positions)
        angles = clip.sample_frames(positions)
        for j, node in enumerate(clip.quat_nodes):
            rotation = stored_quaternions(node["reference_quaternion"], stored[:, list(node["channels"])])
            assert rotation_angles(rotation, rotations[:, j]).max() <= 1e-12  # 4.7 in float64, both
            assert rotation_angles(q[:, node["node"]], rotations[:, j]).max() <= 2e-6
            euler = euler_quaternions(angles[:, list(node["channels"])], quat_axes(clip, node))
            assert rotation_angles(euler, rotations[:, j]).max() <= 1e-5
        values_only = [c for c in range(clip.channel_count) if clip.channel(c)["stored"] == "value"]
        assert np.array_equal(angles[:, values_only], stored[:, values_only])
