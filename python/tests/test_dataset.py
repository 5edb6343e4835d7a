"""keyanim.Dataset: windows counted and sampled as documented, over .kanim and BVH files."""

import math
import pickle
import shutil
import warnings

import numpy as np
import pytest

from conftest import HOP, WALK, assert_decoded_is_sampled, corpus_files, frames_at_rate


@pytest.fixture(scope="module")
def library(tmp_path_factory, keyanim):
    """A directory with the walk as .kanim and the hop as BVH, in a subfolder."""
    root = tmp_path_factory.mktemp("library")
    (root / "a").mkdir()
    (root / "a" / "walk.kanim").write_bytes(keyanim.encode(keyanim.read_bvh(WALK))[0])
    shutil.copy(HOP, root / "hop.bvh")
    (root / "notes.txt").write_text("not a clip")
    return root


def expected_windows(frames, window, stride):
    return 0 if frames < window else (frames - window) // stride + 1


def test_windows_at_source_rate(keyanim, library):
    ds = keyanim.Dataset(library, window=64)
    assert [p.split("/")[-1] for p in ds.paths] == ["walk.kanim", "hop.bvh"]  # a/ sorts before hop.bvh
    walk, hop = ds.clips
    assert len(ds) == expected_windows(344, 64, 64) + expected_windows(1102, 64, 64) == 5 + 17
    x = ds[0]
    assert x.shape == (64, 96) and x.dtype == np.float32
    assert np.array_equal(x, walk.sample_frames(np.arange(64.0)))
    assert np.array_equal(ds[6], hop.sample_frames(np.arange(64.0, 128.0)))
    assert np.array_equal(ds[-1], ds[len(ds) - 1])
    assert ds.locate(5) == (1, 0) and ds.locate(21) == (1, 16 * 64)
    assert repr(ds) == "<keyanim.Dataset: 22 windows of 64 frames over 2 clips>"


def test_bvh_windows_are_the_files_values(keyanim, library):
    ds = keyanim.Dataset([library / "hop.bvh"], window=100, stride=37)
    m = keyanim.read_bvh(HOP)
    assert len(ds) == expected_windows(1102, 100, 37)
    for i in (0, 5, len(ds) - 1):
        _, first = ds.locate(i)
        got = ds[i].astype(np.float64)
        want = m.channels[first:first + 100]
        diff = (got - want + 180.0) % 360.0 - 180.0  # angles are unwrapped
        assert np.abs(diff).max() <= np.abs(m.channels).max() * 2.0 ** -23


def test_windows_at_another_rate(keyanim, library):
    ds = keyanim.Dataset(library, fps=30, window=16, stride=8)
    walk, hop = ds.clips
    n_walk = math.floor(343 * walk.frame_time * 30 + 1e-6) + 1
    n_hop = math.floor(1101 * hop.frame_time * 30 + 1e-6) + 1
    assert len(ds) == expected_windows(n_walk, 16, 8) + expected_windows(n_hop, 16, 8)
    # The windows are rows of Clip.to_motion(fps): the same positions, the same values (a
    # quaternion node's rotation channels: Euler angles of the same rotations, see
    # assert_decoded_is_sampled), and sample_frames at those positions bit for bit.
    rows = walk.to_motion(fps=30).channels
    assert walk.quat_nodes
    for i in range(expected_windows(n_walk, 16, 8)):
        _, first = ds.locate(i)
        at = walk.frame_positions_at(30, np.arange(first, first + 16))
        assert np.array_equal(ds.positions(i), at)
        assert np.array_equal(ds[i], walk.sample_frames(at))
        assert_decoded_is_sampled(walk, rows[first:first + 16], ds[i])


def test_windows_of_euler_clips_at_another_rate(keyanim, tmp_path):
    """Clips encoded with rotations='euler': the windows are rows of to_motion(fps), every value."""
    (tmp_path / "walk.kanim").write_bytes(keyanim.encode(keyanim.read_bvh(WALK), rotations="euler")[0])
    ds = keyanim.Dataset(tmp_path, fps=30, window=16, stride=8)
    walk, = ds.clips
    assert walk.quat_nodes == []
    rows = walk.to_motion(fps=30).channels
    for i in range(len(ds)):
        _, first = ds.locate(i)
        assert np.array_equal(ds[i].astype(np.float64), rows[first:first + 16])


def test_windows_at_the_clips_own_rate(keyanim, library):
    # 120 fps on clips that store Frame Time .0083333: the same windows as the source rate.
    at_rate, own = keyanim.Dataset(library, fps=120, window=16), keyanim.Dataset(library, window=16)
    assert len(at_rate) == len(own)
    for i in (0, len(own) // 2, len(own) - 1):
        assert np.array_equal(at_rate[i], own[i])


def test_outputs(keyanim, library):
    ds = keyanim.Dataset(library, window=10, output=("channels", "local_quaternions", "local_translations",
                                                      "world_positions"))
    c, q, t, w = ds[3]
    clip = ds.clips[0]
    frames = np.arange(30.0, 40.0)
    assert np.array_equal(c, clip.sample_frames(frames))
    q2, t2 = clip.local_transforms(frames=frames)
    assert np.array_equal(q, q2) and np.array_equal(t, t2)
    assert np.array_equal(w, clip.world_positions(frames=frames))
    assert q.shape == (10, 38, 4) and w.shape == (10, 38, 3)
    one = keyanim.Dataset(library, window=10, output="world_positions", position_channels="add")
    assert np.array_equal(one[3], clip.world_positions(frames=frames, position_channels="add"))


def test_pickles_for_worker_processes(keyanim, library):
    ds = keyanim.Dataset(library, fps=60, window=32, output=("channels", "world_positions"))
    again = pickle.loads(pickle.dumps(ds))
    assert len(again) == len(ds)
    for i in (0, len(ds) - 1):
        for a, b in zip(ds[i], again[i]):
            assert np.array_equal(a, b)


def test_clips_shorter_than_a_window(keyanim, library):
    ds = keyanim.Dataset(library, window=400)
    assert len(ds) == expected_windows(1102, 400, 400)
    assert ds.locate(0)[0] == 1
    with pytest.raises(IndexError):
        keyanim.Dataset(library, window=5000)[0]


def test_bad_arguments(keyanim, library, tmp_path):
    for kwargs in (dict(window=0), dict(window=2.5), dict(stride=0), dict(fps=0), dict(fps=-30),
                   dict(fps=float("nan")), dict(output="velocities"), dict(output=()),
                   dict(position_channels="x")):
        with pytest.raises(ValueError):
            keyanim.Dataset(library, **kwargs)
    with pytest.raises(ValueError, match="no .kanim, .kbank or .bvh"):
        keyanim.Dataset(tmp_path)
    ds = keyanim.Dataset(library, window=64)
    for bad in (len(ds), -len(ds) - 1):
        with pytest.raises(IndexError):
            ds[bad]
    with pytest.raises(TypeError):
        ds[1.0]
    with pytest.raises(FileNotFoundError):
        keyanim.Dataset([tmp_path / "missing.bvh"])
    broken = tmp_path / "broken.kanim"
    broken.write_bytes(b"\x89KAN\r\n\x1a\n")
    with pytest.raises(keyanim.Error) as info:
        keyanim.Dataset([broken])
    assert info.value.section and info.value.file == str(broken)
    bad_bvh = tmp_path / "bad.bvh"
    bad_bvh.write_text("HIERARCHY\nROOT x\n{\n")
    with pytest.raises(keyanim.Error) as info:
        keyanim.Dataset(tmp_path, window=4)
    assert info.value.line > 0


@pytest.mark.corpus
def test_corpus_dataset(keyanim, tmp_path):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        ds = keyanim.Dataset(corpus_files(), fps=30, window=32, output=("channels", "world_positions"))
    total = 0
    for clip in ds.clips:
        total += expected_windows(frames_at_rate(clip.frame_count, clip.frame_time, 30), 32, 32)
    assert len(ds) == total > 0
    rng = np.random.default_rng(1)
    for i in rng.integers(0, len(ds), 50):
        c, w = ds[int(i)]
        clip = ds.clips[ds.locate(int(i))[0]]
        assert c.shape == (32, clip.channel_count) and w.shape == (32, len(clip.joint_names), 3)
        assert np.isfinite(c).all() and np.isfinite(w).all()
