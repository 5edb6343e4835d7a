"""keyanim.read_bvh and keyanim.Motion, against an independent reading of the same files."""

import os
import pathlib
import warnings

import numpy as np
import pytest

from conftest import (FIXTURES, HOP, WALK, cli, corpus_files, independent_error, local_rotations, parse_bvh,
                      quaternion_matrices, skeleton_size, world_positions)


def check_against_text(m, bvh):
    assert m.frame_count == bvh.values.shape[0] >= bvh.frame_count  # more lines: all kept, with a warning
    assert m.frame_time == bvh.frame_time
    assert m.channels.dtype == np.float64 and m.channels.shape == bvh.values.shape
    # Every value bit for bit as the text holds it (Python's float() is correctly rounded).
    assert np.array_equal(m.channels, bvh.values)
    assert m.parents.tolist() == bvh.parents
    assert np.array_equal(m.offsets, bvh.offsets)
    assert m.is_end_site.tolist() == bvh.end_site
    for name, got, end in zip(bvh.names, m.joint_names, bvh.end_site):
        assert got == name or (end and not name and got.startswith("End Site"))
    assert [c.split(":")[-1] for c in m.channel_names] == [c for _, c in bvh.channels]
    assert m.channel_count == len(bvh.channels)


def test_read_bvh_matches_the_text(keyanim, walk, walk_bvh):
    check_against_text(walk, walk_bvh)
    assert walk.source == str(WALK)
    assert walk.channel_names[:4] == ["Hips:Xposition", "Hips:Yposition", "Hips:Zposition", "Hips:Zrotation"]
    assert repr(walk) == "<keyanim.Motion: 344 frames, 38 nodes, 96 channels>"


def test_read_bvh_takes_path_objects_and_bytes(keyanim):
    a = keyanim.read_bvh(pathlib.Path(HOP))
    b = keyanim.read_bvh(os.fsencode(str(HOP)))
    assert np.array_equal(a.channels, b.channels) and a.frame_count == 1102


@pytest.mark.parametrize("name", ["crlf", "lone_cr", "tabs", "mixed_rotation_orders", "multi_root",
                                  "names_with_spaces_colons", "no_end_site", "one_frame",
                                  "six_channels_all_joints", "zero_frames"])
def test_read_bvh_fixtures(keyanim, name):
    path = FIXTURES / (name + ".bvh")
    check_against_text(keyanim.read_bvh(path), parse_bvh(path))


def test_read_bvh_warns_about_extra_lines(keyanim):
    with pytest.warns(UserWarning, match="Frames"):
        m = keyanim.read_bvh(FIXTURES / "frames_more_lines.bvh")
    assert m.frame_count == parse_bvh(FIXTURES / "frames_more_lines.bvh").values.shape[0]


@pytest.mark.parametrize("name", ["missing_brace", "non_numeric", "nan_value", "inf_value", "too_many_values",
                                  "truncated_motion_line", "frames_fewer_lines"])
def test_read_bvh_errors_name_the_place(keyanim, name):
    path = FIXTURES / (name + ".bvh")
    with pytest.raises(keyanim.Error) as info:
        keyanim.read_bvh(path)
    e = info.value
    assert isinstance(e, ValueError)
    assert e.kind == "malformed" and e.file == str(path)
    assert e.line >= 1 and e.column >= 1
    assert str(e) == "%s:%d:%d: %s" % (path, e.line, e.column, e.message)
    assert e.section is None and e.status is None
    # The same place as the tool reports.
    r = cli("info", path, check=False)
    assert r.returncode == 2 and "%s:%d:%d:" % (path, e.line, e.column) in r.stderr


def test_read_bvh_file_errors(keyanim, tmp_path):
    with pytest.raises(FileNotFoundError) as info:
        keyanim.read_bvh(tmp_path / "missing.bvh")
    assert info.value.filename == str(tmp_path / "missing.bvh")
    with pytest.raises(IsADirectoryError):
        keyanim.read_bvh(tmp_path)
    garbage = tmp_path / "garbage.bvh"
    garbage.write_bytes(b"\x00\x01binary")
    with pytest.raises(keyanim.Error) as e:
        keyanim.read_bvh(garbage)
    assert e.value.line == 1
    with pytest.raises(TypeError):
        keyanim.read_bvh(42)


def test_read_bvh_of_a_kanim_says_what_the_tool_says(keyanim, walk_encoded, tmp_path):
    # One message for one mistake (issue 28, item 18): the CLI's, not the reader's "found '\x89KAN'".
    path = tmp_path / "walk.kanim"
    path.write_bytes(walk_encoded[0])
    with pytest.raises(keyanim.Error) as info:
        keyanim.read_bvh(path)
    tool = cli("encode", path, "-o", tmp_path / "x.kanim", check=False)
    assert tool.returncode == 2
    assert str(info.value) == "%s: is a .kanim file, expected BVH text" % path
    assert tool.stderr.strip() == "keyanim: " + str(info.value)


def test_fps_and_duration(keyanim, walk, tmp_path):
    assert walk.fps == 1 / 0.0083333 and walk.duration == 343 * 0.0083333
    # One frame, and no frame time: duration 0, fps None.
    still = tmp_path / "still.bvh"
    still.write_text("HIERARCHY\nROOT a\n{\n OFFSET 0 0 0\n CHANNELS 1 Zrotation\n End Site\n {\n  OFFSET 0 1 0\n"
                     " }\n}\nMOTION\nFrames: 1\nFrame Time: 0\n5\n")
    m = keyanim.read_bvh(still)
    assert m.frame_count == 1 and m.duration == 0.0 and m.fps is None
    clip = keyanim.Clip.from_motion(walk)
    assert clip.fps == walk.fps and clip.duration == pytest.approx(walk.duration)


def test_write_bvh_round_trip_and_refusals(keyanim, walk, tmp_path):
    out = tmp_path / "walk.bvh"
    walk.write_bvh(out)
    again = keyanim.read_bvh(out)
    assert np.array_equal(again.channels, walk.channels)
    assert again.joint_names == walk.joint_names and np.array_equal(again.offsets, walk.offsets)
    assert again.frame_time == walk.frame_time
    with pytest.raises(FileExistsError):
        walk.write_bvh(out)
    hop = keyanim.read_bvh(HOP)
    hop.write_bvh(out, overwrite=True)
    assert keyanim.read_bvh(out).frame_count == hop.frame_count
    assert sorted(os.listdir(tmp_path)) == ["walk.bvh"]  # no temporary file left
    with pytest.raises(FileNotFoundError):
        walk.write_bvh(tmp_path / "no" / "dir.bvh")


def test_channels_view_writes_through(keyanim, tmp_path):
    m = keyanim.read_bvh(WALK)
    view = m.channels
    view[10, 5] = 12.5
    assert m.channels[10, 5] == 12.5
    m.write_bvh(tmp_path / "edited.bvh")
    assert keyanim.read_bvh(tmp_path / "edited.bvh").channels[10, 5] == 12.5
    m.channels = np.zeros(view.shape)
    assert not m.channels.any()
    with pytest.raises(ValueError, match="shape"):
        m.channels = np.zeros((3, 3))
    del m  # the view keeps the motion alive
    assert view.sum() == 0.0


def test_world_positions_match_independent_fk(walk, walk_bvh):
    got = walk.world_positions()
    assert got.shape == (344, 38, 3) and got.dtype == np.float64
    np.testing.assert_allclose(got, world_positions(walk_bvh, walk_bvh.values), rtol=0, atol=1e-9)
    assert np.array_equal(walk.world_positions([5, -1]), got[[5, 343]])
    assert walk.world_positions(7).shape == (38, 3)
    assert walk.world_positions(np.array([[1, 2], [3, 4]])).shape == (2, 2, 38, 3)
    with pytest.raises(IndexError):
        walk.world_positions([344])
    with pytest.raises(IndexError):
        walk.world_positions(-345)
    with pytest.raises(TypeError):
        walk.world_positions([0.5])


def test_local_quaternions_match_independent_rotations(walk, walk_bvh):
    q = walk.local_quaternions()
    assert q.shape == (344, 38, 4) and q.dtype == np.float64
    np.testing.assert_allclose(np.linalg.norm(q, axis=-1), 1.0, atol=1e-12)
    np.testing.assert_allclose(quaternion_matrices(q), local_rotations(walk_bvh, walk_bvh.values), atol=1e-12)
    assert np.array_equal(q[:, walk.is_end_site], np.tile([0.0, 0.0, 0.0, 1.0], (344, 7, 1)))
    assert np.array_equal(walk.local_quaternions([3]), q[[3]])
    with pytest.raises(IndexError):
        walk.local_quaternions([0, 344])
    with pytest.raises(TypeError):
        walk.local_quaternions("all")


def test_measure_error(keyanim, walk, walk_bvh, walk_encoded, walk_clip):
    zero = keyanim.measure_error(walk, walk)
    assert zero["max"] == 0.0 and zero["rms"] == 0.0
    decoded = walk_clip.to_motion()
    e = keyanim.measure_error(walk, decoded)
    assert e == walk_encoded[1]["error"]
    size = skeleton_size(walk_bvh)
    assert e["shell"] == pytest.approx(0.02 * size, rel=1e-12) and e["readings"] == ["replace"]
    assert e["max"] == pytest.approx(independent_error(walk_bvh, decoded.channels, e["shell"]), rel=1e-9)
    # shell= as encode's: percent of the original's size, units, or 0 (joints and End Sites).
    assert keyanim.measure_error(walk, decoded, shell="2%") == e
    units = keyanim.measure_error(walk, decoded, shell=4.0)
    assert units["shell"] == 4.0
    assert units["max"] == pytest.approx(independent_error(walk_bvh, decoded.channels, 4.0), rel=1e-9)
    bare = keyanim.measure_error(walk, decoded, shell="0")
    assert bare["shell"] == 0.0 and bare["worst_shell_axis"] is None and bare["worst_point"] == bare["worst_joint"]
    assert bare["max"] == pytest.approx(independent_error(walk_bvh, decoded.channels, 0.0), rel=1e-9)
    assert bare["max"] <= e["max"]
    with pytest.raises(keyanim.Error) as info:
        keyanim.measure_error(walk, keyanim.read_bvh(HOP))
    assert info.value.kind == "invalid_argument"
    for shell in ("-1", "x", -1.0, float("nan")):
        with pytest.raises(keyanim.Error):
            keyanim.measure_error(walk, walk, shell=shell)
    with pytest.raises(TypeError):
        keyanim.measure_error(walk, walk, shell=None)


# A skeleton with position channels below the root, where BVH readers disagree: Blender replaces
# the OFFSET component with the channel's value, three.js adds it.
ARM = """HIERARCHY
ROOT Hips
{
  OFFSET 1 2 3
  CHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation
  JOINT Arm
  {
    OFFSET 0 10 0
    CHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation
    End Site
    {
      OFFSET 0 5 0
    }
  }
}
MOTION
Frames: 4
Frame Time: 0.04
0 0 0 0 0 0 0 10 0 0 0 0
1 2 3 10 20 30 1 9 2 -40 15 5
-1 0.5 2 -30 5 60 0.5 11 -1 70 -20 10
2 1 0 45 -45 90 -2 8 3 5 90 -80
"""


@pytest.fixture
def arm(tmp_path):
    path = tmp_path / "arm.bvh"
    path.write_text(ARM)
    return path


def test_world_positions_position_channels(keyanim, arm):
    m, bvh = keyanim.read_bvh(arm), parse_bvh(arm)
    replace = m.world_positions()
    assert np.array_equal(replace, m.world_positions(position_channels="replace"))
    np.testing.assert_allclose(replace, world_positions(bvh, bvh.values, "replace"), rtol=0, atol=1e-12)
    add = m.world_positions(position_channels="add")
    np.testing.assert_allclose(add, world_positions(bvh, bvh.values, "add"), rtol=0, atol=1e-12)
    assert not np.allclose(add, replace)
    assert np.array_equal(m.world_positions([2], position_channels="add"), add[[2]])
    with pytest.raises(ValueError, match="position_channels"):
        m.world_positions(position_channels="sideways")


def test_measure_error_under_both_readings(keyanim, arm):
    """Position channels below the root: measured under both readings, as verify reports."""
    m, bvh = keyanim.read_bvh(arm), parse_bvh(arm)
    moved = keyanim.read_bvh(arm)
    moved.channels[1, 7] += 0.25  # the Arm's Yposition at frame 1
    moved.channels[2, 10] += 3.0  # the Arm's Xrotation at frame 2
    e = keyanim.measure_error(m, moved, shell=1.0)
    assert e["readings"] == ["replace", "add"] and e["worst_reading"] in ("replace", "add")
    for reading in ("replace", "add"):
        got = np.linalg.norm(world_positions(bvh, bvh.values, reading) - world_positions(bvh, moved.channels, reading),
                             axis=-1).max()
        assert e["max_by_reading"][reading] >= got - 1e-12
    assert e["max"] == max(e["max_by_reading"].values())
    assert e["max"] == pytest.approx(independent_error(bvh, moved.channels, 1.0), rel=1e-12)
    # The encoder measures its clip the same way.
    data, report = keyanim.encode(m, error=0.01, shell=1.0)
    assert report["error"]["readings"] == ["replace", "add"]
    clip = keyanim.Clip(data)
    assert keyanim.measure_error(m, clip.to_motion(), shell=1.0) == report["error"]
    assert independent_error(bvh, clip.to_motion().channels, 1.0) <= 0.01 * (1 + 1e-9)


@pytest.mark.corpus
@pytest.mark.parametrize("path", corpus_files() or [None], ids=lambda p: p.name if p else "none")
def test_corpus_read_exactly(keyanim, path, tmp_path):
    bvh = parse_bvh(path)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # more motion lines than Frames: says, in some files
        m = keyanim.read_bvh(path)
    check_against_text(m, bvh)
    np.testing.assert_allclose(m.world_positions(), world_positions(bvh, bvh.values), rtol=0,
                               atol=1e-9 * max(1.0, np.abs(bvh.offsets).max()))
    np.testing.assert_allclose(quaternion_matrices(m.local_quaternions()), local_rotations(bvh, bvh.values),
                               atol=1e-12)
    out = tmp_path / "again.bvh"
    m.write_bvh(out)
    assert np.array_equal(keyanim.read_bvh(out).channels, m.channels)

