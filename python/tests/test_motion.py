"""keyanim.read_bvh and keyanim.Motion, against an independent reading of the same files."""

import os
import pathlib
import warnings

import numpy as np
import pytest

from conftest import FIXTURES, HOP, WALK, cli, corpus_files, local_rotations, parse_bvh, quaternion_matrices, world_positions


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


def test_measure_error(keyanim, walk, walk_encoded, walk_clip):
    zero = keyanim.measure_error(walk, walk)
    assert zero["max"] == 0.0 and zero["rms"] == 0.0
    e = keyanim.measure_error(walk, walk_clip.to_motion())
    assert e == walk_encoded[1]["error"]
    with pytest.raises(keyanim.Error) as info:
        keyanim.measure_error(walk, keyanim.read_bvh(HOP))
    assert info.value.kind == "invalid_argument"


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

