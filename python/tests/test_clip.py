"""keyanim.Clip: loading from paths and bytes, sampling against spec/FORMAT.md appendix A
evaluated independently in numpy binary32, poses against independent forward kinematics,
info and decoding against the keyanim tool, and damaged files."""

import os
import pathlib
import warnings

import numpy as np
import pytest

from conftest import (HOP, WALK, assert_decoded_is_sampled, cli, cli_json, corpus_files, euler_quaternions,
                      frames_at_rate, local_rotations, local_translations, parse_bvh, quat_axes, quaternion_matrices,
                      rotation_angles, stored_quaternions, world_positions)

F = np.float32


def appendix_a(frames, values, interpolation, tension, rule, x):
    """The value of one channel at frame position x (binary64), operation for operation in
    binary32 as spec/FORMAT.md appendix A states it."""
    n = len(frames)
    if n == 0:
        return F(0)
    f = F(x)
    K = [F(k) for k in frames]
    if n == 1 or not f > K[0]:
        return values[0]
    if f >= K[-1]:
        return values[-1]
    j = max(i for i in range(n - 1) if K[i] <= f)
    if f == K[j]:
        return values[j]
    u = (f - K[j]) / (K[j + 1] - K[j])
    p0, p1 = values[j], values[j + 1]
    if interpolation == "linear":
        return p0 + u * (p1 - p0)
    pm, p2 = values[max(j - 1, 0)], values[min(j + 2, n - 1)]
    s = (F(1) - F(tension)) * F(0.5)
    a0 = a1 = F(1)
    if rule == "step_adjusted":
        length = F(int(frames[j + 1]) - int(frames[j]))
        if j > 0:
            a0 = F(2) * length / (F(int(frames[j]) - int(frames[j - 1])) + length)
        if j + 2 < n:
            a1 = F(2) * length / (length + F(int(frames[j + 2]) - int(frames[j + 1])))
    m0 = s * a0 * (p1 - pm)
    m1 = s * a1 * (p2 - p0)
    u2 = u * u
    u3 = u2 * u
    h01 = F(-2) * u3 + F(3) * u2
    h10 = u3 - F(2) * u2 + u
    h11 = u3 - u2
    return ((p0 + h01 * (p1 - p0)) + h10 * m0) + h11 * m1


def test_load_from_path_and_bytes(keyanim, walk_encoded, tmp_path):
    data = walk_encoded[0]
    path = tmp_path / "walk.kanim"
    path.write_bytes(data)
    clips = [keyanim.Clip(data), keyanim.Clip(bytearray(data)), keyanim.Clip(memoryview(data)),
             keyanim.Clip(str(path)), keyanim.Clip(path)]  # (bytes are the file itself, not a path)
    for c in clips:
        assert (c.frame_count, c.channel_count, c.total_keys) == (344, 96, walk_encoded[1]["keys"])
        assert np.array_equal(c.sample_frames([0, 17.25]), clips[0].sample_frames([0, 17.25]))
    assert clips[0].file is None and clips[3].file == str(path)
    assert clips[0].frame_time == 0.0083333 and clips[0].duration == pytest.approx(343 * 0.0083333)
    assert "tolerance_units" in clips[0].encoder_notes
    assert clips[0].memory_bytes > 0
    # The rig's part and the animation's part, apart; info says the same.
    c = clips[0]
    assert c.skeleton_bytes > 0 and c.animation_bytes > 0
    assert c.skeleton_bytes + c.animation_bytes == c.memory_bytes
    assert (c.info["skeleton_bytes"], c.info["animation_bytes"]) == (c.skeleton_bytes, c.animation_bytes)
    # 38 nodes with their names, OFFSETs and channel lists cost more than their names' bytes.
    assert c.skeleton_bytes > sum(len(n) for n in c.joint_names)
    assert repr(clips[0]).startswith("<keyanim.Clip: 344 frames, 38 nodes, 96 channels")


def test_skeleton_properties_are_the_motions(walk, walk_clip):
    assert walk_clip.joint_names == walk.joint_names
    assert walk_clip.channel_names == walk.channel_names
    assert np.array_equal(walk_clip.parents, walk.parents)
    assert np.array_equal(walk_clip.offsets, walk.offsets)
    assert np.array_equal(walk_clip.is_end_site, walk.is_end_site)


def check_appendix_a(clip, positions):
    """Appendix A on what every channel's keys hold (sample_stored), bit for bit; sample_frames
    gives the same for channels stored as values. Returns (sample_frames, sample_stored)."""
    rule = clip.info["tangent_rule"]
    got, stored = clip.sample_frames(positions), clip.sample_stored(positions)
    assert got.dtype == stored.dtype == np.float32 and got.shape == stored.shape == (len(positions), clip.channel_count)
    for c in range(clip.channel_count):
        info = clip.channel(c)
        frames, values = clip.channel_keys(c)
        assert len(frames) == info["key_count"] and frames.dtype == np.uint32 and values.dtype == np.float32
        want = [appendix_a(frames, values, info["interpolation"], info["tension"], rule, x) for x in positions]
        assert np.array_equal(stored[:, c], np.array(want, dtype=F)), clip.channel_names[c]
        # At its keys a channel holds its keys' values exactly.
        assert np.array_equal(clip.sample_stored(frames.astype(np.float64))[:, c], values)
        if info["stored"] == "value":
            assert np.array_equal(got[:, c], stored[:, c]), clip.channel_names[c]
            assert np.array_equal(clip.sample_frames(frames.astype(np.float64))[:, c], values)
        else:
            assert info["stored"] in ("quat_x", "quat_y", "quat_z")
    return got, stored


def check_quat_nodes(clip, positions):
    """4.7 and Appendix B: each quaternion node's rotation channels hold stored x, y, z (in that
    order, on shared key frames), and sample_frames gives the Euler angles (middle one in
    [-90, 90]) of the rotation reference * (x, y, z, w), normalized, computed here in numpy."""
    got, stored = clip.sample_frames(positions), clip.sample_stored(positions)
    seen = set()
    for node in clip.quat_nodes:
        c = list(node["channels"])
        assert c == [c[0], c[0] + 1, c[0] + 2] and sorted(quat_axes(clip, node)) == ["X", "Y", "Z"]
        assert clip.joint_names[node["node"]] == node["joint"]
        assert all(clip.channel_names[k].rsplit(":", 1)[0] == node["joint"] for k in c)
        assert [clip.channel(k)["stored"] for k in c] == ["quat_x", "quat_y", "quat_z"]
        key_frames = [clip.channel_keys(k)[0] for k in c]
        assert np.array_equal(key_frames[0], key_frames[1]) and np.array_equal(key_frames[0], key_frames[2])
        X, Y, Z = node["reference"]
        assert all(isinstance(v, int) and -32768 <= v < 32768 for v in (X, Y, Z)) and X * X + Y * Y + Z * Z <= 2 ** 30
        reference = np.array([X, Y, Z, np.sqrt(2.0 ** 30 - (X * X + Y * Y + Z * Z))]) * 2.0 ** -15
        np.testing.assert_allclose(node["reference_quaternion"], reference, rtol=0, atol=1e-15)
        rotation = stored_quaternions(reference, stored[:, c])
        angles = rotation_angles(euler_quaternions(got[:, c], quat_axes(clip, node)), rotation)
        assert angles.max() <= 1e-5, (node["joint"], angles.max())
        assert (np.abs(got[:, c[1]]) <= 90).all() and (np.abs(got[:, c]) <= 180).all(), node["joint"]
        seen.update(c)
    assert seen == {c for c in range(clip.channel_count) if clip.channel(c)["stored"] != "value"}


def test_sampling_is_appendix_a(walk_clip):
    positions = np.array([0, 0.3, 1, 17.25, 100.5, 200.125, 342.9, 343])
    check_appendix_a(walk_clip, positions)
    assert len(walk_clip.quat_nodes) == 27  # the default encoding: each joint of three rotation channels
    check_quat_nodes(walk_clip, np.concatenate([positions, np.arange(0.0, 343.25, 0.25)]))


def test_an_euler_clip_samples_its_keys(walk_euler_clip):
    """rotations='euler': no quaternion node, every channel's keys its own values (degrees)."""
    assert walk_euler_clip.quat_nodes == [] and walk_euler_clip.info["version"] == "3.0"
    assert {walk_euler_clip.channel(c)["stored"] for c in range(96)} == {"value"}
    positions = np.array([0, 0.3, 1, 17.25, 100.5, 200.125, 342.9, 343])
    got, stored = check_appendix_a(walk_euler_clip, positions)
    assert np.array_equal(got, stored)


def test_times_and_frames_agree(walk_clip):
    ft = walk_clip.frame_time
    frames = np.array([0.0, 2.0, 10.5, 343.0])
    assert np.array_equal(walk_clip.sample(frames * ft), walk_clip.sample_frames(frames))
    assert walk_clip.sample(0.5).shape == (96,)
    assert walk_clip.sample([[0.1, 0.2], [0.3, 0.4]]).shape == (2, 2, 96)
    assert walk_clip.sample([]).shape == (0, 96)


def test_sample_matches_the_tool(walk_clip, walk_encoded, tmp_path):
    path = tmp_path / "walk.kanim"
    path.write_bytes(walk_encoded[0])
    tool = cli_json("sample", path, "--frame", "100.25", "--json")
    row = walk_clip.sample_frames(100.25)
    names = walk_clip.channel_names
    values = {}
    for joint in tool["joints"]:
        for key, v in joint.items():
            if key != "name":
                values[joint["name"] + ":" + key] = v
    assert [values[n] for n in names] == [float(v) for v in row]


def test_local_transforms_match_independent_rotations(walk, walk_bvh, walk_clip):
    frames = np.arange(0, 344, 7)
    q, t = walk_clip.local_transforms(frames=frames.astype(np.float64))
    assert q.shape == (len(frames), 38, 4) and t.shape == (len(frames), 38, 3) and q.dtype == np.float32
    decoded = walk_clip.sample_frames(frames).astype(np.float64)
    np.testing.assert_allclose(np.linalg.norm(q, axis=-1), 1.0, atol=1e-6)
    np.testing.assert_allclose(quaternion_matrices(q.astype(np.float64)), local_rotations(walk_bvh, decoded), atol=2e-6)
    np.testing.assert_allclose(t, local_translations(walk_bvh, decoded), rtol=1e-6, atol=1e-5)
    # By time, the same; and 'add' adds the OFFSET to the root's position channels.
    q2, t2 = walk_clip.local_transforms(frames * walk_clip.frame_time)
    np.testing.assert_allclose(q2, q, atol=1e-6)
    _, added = walk_clip.local_transforms(frames=frames.astype(np.float64), position_channels="add")
    np.testing.assert_allclose(added[:, 0], t[:, 0] + walk.offsets[0], atol=1e-5)
    # Quaternions are continuous from frame to frame (no sign flips).
    qs = walk_clip.local_transforms(frames=np.arange(344.0))[0]
    assert (np.sum(qs[1:] * qs[:-1], axis=-1) > 0).all()


def test_world_positions_match_independent_fk(walk_bvh, walk_clip):
    frames = np.arange(0, 344, 5).astype(np.float64)
    got = walk_clip.world_positions(frames=frames)
    assert got.shape == (len(frames), 38, 3) and got.dtype == np.float32
    want = world_positions(walk_bvh, walk_clip.sample_frames(frames).astype(np.float64))
    np.testing.assert_allclose(got, want, rtol=0, atol=1e-4)
    np.testing.assert_allclose(walk_clip.world_positions(frames * walk_clip.frame_time), got, atol=1e-5)


def test_info_is_the_tools(walk_clip, walk_encoded, tmp_path):
    path = tmp_path / "walk.kanim"
    path.write_bytes(walk_encoded[0])
    import keyanim
    from_file = keyanim.Clip(path).info
    assert from_file == cli_json("info", path, "--json")
    in_memory = walk_clip.info
    assert in_memory["file"] is None and {k: v for k, v in in_memory.items() if k != "file"} == \
        {k: v for k, v in from_file.items() if k != "file"}
    # The default encoding writes quaternion nodes: format 5.0, the module's format_version.
    assert in_memory["format"] == "kanim" and in_memory["version"] == keyanim.format_version == "5.0"
    assert walk_clip.quat_nodes


def test_info_of_an_euler_clip_is_the_tools(walk_euler_clip, walk_euler_encoded, tmp_path):
    path = tmp_path / "walk.kanim"
    path.write_bytes(walk_euler_encoded[0])
    import keyanim
    info = keyanim.Clip(path).info
    assert info == cli_json("info", path, "--json") and info["version"] == "3.0"


def test_to_motion(keyanim, walk_clip, walk_euler_clip, walk_encoded, tmp_path):
    m = walk_clip.to_motion()
    assert m.frame_count == 344 and m.source is None
    assert_decoded_is_sampled(walk_clip, m.channels, walk_clip.sample_frames(np.arange(344.0)))
    # Without quaternion nodes, the decoded values are the sampled ones, every channel.
    e = walk_euler_clip.to_motion()
    assert np.array_equal(e.channels, walk_euler_clip.sample_frames(np.arange(344.0)).astype(np.float64))
    m30 = walk_clip.to_motion(fps=30)
    assert m30.frame_count == int(np.floor(343 * 0.0083333 * 30 + 1e-6)) + 1
    assert m30.frame_time == pytest.approx(1 / 30)
    path = tmp_path / "walk.kanim"
    path.write_bytes(walk_encoded[0])
    cli("decode", path, "--fps", "30", "-o", tmp_path / "walk30.bvh")
    assert np.array_equal(keyanim.read_bvh(tmp_path / "walk30.bvh").channels, m30.channels)
    for bad in (-1, float("nan"), float("inf")):
        with pytest.raises(keyanim.Error) as info:
            walk_clip.to_motion(fps=bad)
        assert info.value.kind == "invalid_argument"


def test_a_rate_within_rounding_of_the_clips_own(keyanim, walk_clip, walk_euler_clip):
    # The walk stores Frame Time .0083333, a hair under 1/120 s: 120 fps is its own rate.
    source = walk_clip.to_motion()
    m120 = walk_clip.to_motion(fps=120)
    assert m120.frame_count == 344 == walk_clip.frame_count_at(120)
    assert np.array_equal(m120.channels, source.channels)
    # 240 fps: the source frames and one in-between each, at exact half frames.
    m240 = walk_clip.to_motion(fps=240)
    assert m240.frame_count == 687 == walk_clip.frame_count_at(240)
    assert_decoded_is_sampled(walk_clip, m240.channels, walk_clip.sample_frames(np.arange(687) / 2))
    e240 = walk_euler_clip.to_motion(fps=240)
    assert np.array_equal(e240.channels, walk_euler_clip.sample_frames(np.arange(687) / 2).astype(np.float64))
    # 40 fps: every third source frame; 119 fps: frames every 1/119 s up to the end.
    assert np.array_equal(walk_clip.frame_positions_at(40, [0, 1, 114]), [0.0, 3.0, 342.0])
    assert walk_clip.frame_count_at(40) == 115
    assert walk_clip.frame_count_at(119) == int(np.floor(343 * 0.0083333 * 119 + 1e-6)) + 1
    for fps in (15, 24, 30, 40, 60, 100, 119, 120, 240, 360):
        assert walk_clip.frame_count_at(fps) == frames_at_rate(344, 0.0083333, fps) == walk_clip.to_motion(fps=fps).frame_count
    assert walk_clip.frame_positions_at(119, [7])[0] == (7 / 119) / 0.0083333
    assert walk_clip.frame_count_at() == 344
    assert np.array_equal(walk_clip.frame_positions_at(None, [-3, 5, 999]), [0.0, 5.0, 343.0])
    for bad in (0, -1, float("nan"), float("inf")):
        with pytest.raises(keyanim.Error):
            walk_clip.frame_count_at(bad)


def test_from_motion_keeps_every_frame(keyanim, walk, tmp_path):
    clip = keyanim.Clip.from_motion(walk)
    assert clip.total_keys == 344 * 96 - 20 * 344  # zero channels need no keys
    got = clip.sample_frames(np.arange(344.0)).astype(np.float64)
    diff = (got - walk.channels + 180.0) % 360.0 - 180.0  # angles unwrapped: compare modulo 360
    bound = np.abs(walk.channels).max(axis=0) * 2.0 ** -23  # half the channel's float32 step, and rounding
    assert (np.abs(diff) <= bound + 1e-12).all()
    # Between frames: Catmull-Rom through the source frames.
    c = walk.channel_names.index("LeftUpLeg:Xrotation")
    f, v = clip.channel_keys(c)
    assert np.array_equal(f, np.arange(344))
    assert clip.channel(c) == {"interpolation": "cardinal", "tension": 0.0, "key_count": 344, "stored": "value"}
    assert clip.quat_nodes == [] and np.array_equal(clip.sample_stored([10.5]), clip.sample_frames([10.5]))
    assert clip.sample_frames(10.5)[c] == appendix_a(f, v, "cardinal", 0.0, "step_adjusted", 10.5)


def test_positions_outside_the_clip_are_refused(keyanim, walk_clip):
    # As `keyanim sample --frame 1000` (exit 1): not clamped to the last frame (issue 28, item 18).
    calls = (lambda f: walk_clip.world_positions(frames=f), lambda f: walk_clip.sample_frames(f),
             lambda f: walk_clip.local_transforms(frames=f), lambda f: walk_clip.sample_stored(f))
    for call in calls:
        for bad in ([1000], [0, 344], [-1], [-0.5], [343.0001]):
            with pytest.raises(keyanim.Error) as info:
                call(bad)
            assert info.value.kind == "invalid_argument"
            assert "frame %.9g is not in the clip" % [b for b in bad if not 0 <= b <= 343][0] in str(info.value)
            assert "344 frames, 0 to 343" in str(info.value)
    for t in ([100.0], [-0.1], [walk_clip.duration * 1.001]):
        with pytest.raises(keyanim.Error, match=r"time .* s is not in the clip \(it has 344 frames, times 0 to"):
            walk_clip.sample(t)
        with pytest.raises(keyanim.Error, match="is not in the clip"):
            walk_clip.world_positions(t)
    # The ends are in the clip: frame 343, and the duration (which rounding may put a hair past it).
    assert walk_clip.world_positions(frames=[0, 343]).shape == (2, 38, 3)
    assert walk_clip.sample(np.linspace(0, walk_clip.duration, 7)).shape == (7, 96)
    assert walk_clip.fps == pytest.approx(1 / 0.0083333) and walk_clip.duration == pytest.approx(343 * 0.0083333)


def test_a_bvh_file_is_pointed_to_read_bvh(keyanim, walk_bvh):
    from conftest import WALK
    for source in (WALK, open(WALK, "rb").read()):
        with pytest.raises(keyanim.Error) as info:
            keyanim.Clip(source)
        assert "is BVH text, not a .kanim" in str(info.value), str(info.value)
        assert "keyanim.read_bvh" in str(info.value) and "Clip.from_motion" in str(info.value)


def test_info_parses_the_notes(keyanim, walk_clip, walk_encoded):
    info = walk_clip.info
    notes = info["notes"]
    # Every key=value line of the notes, a number where the text is one.
    lines = dict(line.split("=", 1) for line in info["encoder_notes"].splitlines() if "=" in line)
    assert set(notes) == set(lines)
    for key, text in lines.items():
        try:
            want = float(text)
        except ValueError:
            want = text
        assert notes[key] == want, (key, notes[key], text)
    assert isinstance(notes["rounds"], int) and notes["tolerance"] == "0.05%"
    # The notes keep six significant digits.
    assert notes["max_error"] == float("%.6g" % walk_encoded[1]["error"]["max"])
    assert notes["worst_point"] == walk_encoded[1]["error"]["worst_point"]


def test_argument_errors(keyanim, walk_clip):
    with pytest.raises(ValueError, match="NaN"):
        walk_clip.sample([0.0, float("nan")])
    with pytest.raises(ValueError, match="NaN"):
        walk_clip.sample_stored([0.0, float("nan")])
    with pytest.raises(TypeError):
        walk_clip.sample_stored("soon")
    with pytest.raises(TypeError):
        walk_clip.sample("soon")
    with pytest.raises(TypeError):
        walk_clip.local_transforms([0.0], frames=[0.0])
    with pytest.raises(TypeError):
        walk_clip.world_positions()
    with pytest.raises(ValueError, match="position_channels"):
        walk_clip.local_transforms([0.0], position_channels="sideways")
    with pytest.raises(IndexError):
        walk_clip.channel_keys(96)
    with pytest.raises(IndexError):
        walk_clip.channel(-97)
    assert walk_clip.channel(-1) == walk_clip.channel(95)
    with pytest.raises(TypeError):
        keyanim.Clip(3.5)


def test_damaged_files_name_section_and_offset(keyanim, walk_encoded, tmp_path):
    data = walk_encoded[0]
    path = tmp_path / "bad.kanim"
    cases = {
        "truncated": data[: len(data) // 2],
        "bad_signature": b"\x89KAX" + data[4:],
        "checksum_mismatch": data[:-1] + bytes([data[-1] ^ 1]),
        "trailing_bytes": data + b"\0",
        "empty": b"",
    }
    for name, bad in cases.items():
        path.write_bytes(bad)
        with pytest.raises(keyanim.Error) as info:
            keyanim.Clip(path)
        e = info.value
        assert e.kind == "malformed" and e.file == str(path) and e.section
        assert str(e) == "%s: section %s, offset %d (0x%X): %s: %s" % (path, e.section, e.offset, e.offset, e.status, e.message)
        if name != "empty":
            assert e.status == name
        # The tool names the same place.
        r = cli("verify", path, check=False)
        assert r.returncode == 2
        if name not in ("bad_signature", "empty"):  # (which the tool refuses before loading)
            assert "section %s, offset %d (0x%X)" % (e.section, e.offset, e.offset) in r.stderr
        with pytest.raises(keyanim.Error) as from_bytes:
            keyanim.Clip(bad)
        assert from_bytes.value.file is None and from_bytes.value.offset == e.offset
    with pytest.raises(FileNotFoundError):
        keyanim.Clip(tmp_path / "missing.kanim")
    with pytest.raises(IsADirectoryError):
        keyanim.Clip(tmp_path)


def test_unsupported_version(keyanim, walk_encoded):
    data = bytearray(walk_encoded[0])
    data[8] = 99  # major version (u16 little-endian after the 8-byte signature)
    with pytest.raises(keyanim.Error) as info:
        keyanim.Clip(bytes(data))
    assert info.value.kind == "unsupported" and info.value.status == "unsupported_version"


@pytest.mark.corpus
@pytest.mark.parametrize("path", corpus_files() or [None], ids=lambda p: p.name if p else "none")
def test_corpus_clips(keyanim, path, tmp_path):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        m = keyanim.read_bvh(path)
    data, report = keyanim.encode(m, error="0.5%")
    clip = keyanim.Clip(data)
    n = clip.frame_count
    positions = np.linspace(0, max(n - 1, 0), 41)
    rows, stored = clip.sample_frames(positions), clip.sample_stored(positions)
    for c in range(0, clip.channel_count, 7):
        info = clip.channel(c)
        f, v = clip.channel_keys(c)
        want = [appendix_a(f, v, info["interpolation"], info["tension"], clip.info["tangent_rule"], x) for x in positions]
        assert np.array_equal(stored[:, c], np.array(want, dtype=F))
        if info["stored"] == "value":
            assert np.array_equal(rows[:, c], stored[:, c])
    check_quat_nodes(clip, positions)
    bvh = parse_bvh(path)
    want = world_positions(bvh, rows.astype(np.float64))
    size = max(report["tolerance"] / 0.005, 1.0)
    np.testing.assert_allclose(clip.world_positions(frames=positions), want, rtol=0, atol=1e-5 * size)
    q, t = clip.local_transforms(frames=positions)
    np.testing.assert_allclose(quaternion_matrices(q.astype(np.float64)), local_rotations(bvh, rows.astype(np.float64)),
                               atol=5e-6)
    np.testing.assert_allclose(t, local_translations(bvh, rows.astype(np.float64)), rtol=1e-6, atol=1e-6 * size)
    if clip.frame_time > 0:
        times = positions * clip.frame_time
        np.testing.assert_allclose(clip.sample(times), rows, rtol=1e-5, atol=1e-5)
        m30 = clip.to_motion(fps=30)
        assert m30.frame_count == frames_at_rate(n, clip.frame_time, 30)
    assert_decoded_is_sampled(clip, clip.to_motion().channels, clip.sample_frames(np.arange(float(n))))
    path = tmp_path / "clip.kanim"
    path.write_bytes(data)
    assert keyanim.Clip(path).info == cli_json("info", path, "--json")
