"""keyanim.encode: the bytes and report of `keyanim encode`, the tolerance met by independent
forward kinematics, and every way settings can be wrong."""

import warnings

import numpy as np
import pytest

from conftest import HOP, WALK, cli, cli_json, corpus_files, independent_error, parse_bvh, skeleton_size


def test_encode_matches_the_tool(keyanim, walk, walk_encoded, tmp_path):
    data, report = walk_encoded
    out = tmp_path / "walk.kanim"
    tool = cli_json("encode", WALK, "-o", out, "--json")
    assert out.read_bytes() == data
    assert set(report) == set(tool)
    for key in ("frames", "channels", "frame_time", "keys", "bvh_bytes", "raw_f32_bytes", "kanim_bytes",
                "ratio_raw_f32", "error", "tolerance"):
        assert report[key] == tool[key], key
    assert report["input"] == str(WALK) and report["output"] is None
    assert report["encode_ms"] > 0
    assert report["kanim_bytes"] == len(data)


def test_encode_meets_its_tolerance(keyanim, walk_bvh, walk_encoded, walk_clip):
    data, report = walk_encoded
    size = skeleton_size(walk_bvh)
    assert report["tolerance"] == pytest.approx(0.0005 * size, rel=1e-12)
    assert report["error"]["shell"] == pytest.approx(0.02 * size, rel=1e-12)  # --shell's default
    assert report["error"]["readings"] == ["replace"]  # no position channels below the root
    # Every joint, End Site and shell point of the decoded frames, by numpy's own FK.
    err = independent_error(walk_bvh, walk_clip.to_motion().channels, report["error"]["shell"])
    assert err <= report["tolerance"] * (1 + 1e-9)
    assert err == pytest.approx(report["error"]["max"], rel=1e-9)
    assert independent_error(walk_bvh, walk_clip.to_motion().channels, 0.0) <= err


def test_encode_shell_as_the_tool(keyanim, walk, walk_bvh, tmp_path):
    """shell= takes --shell's grammar (D%, D units, 0) and gives the tool's bytes and report."""
    size = skeleton_size(walk_bvh)
    for shell, option, units in (("0", "0", 0.0), ("0%", "0", 0.0), (3.0, "3", 3.0), (0, "0", 0.0),
                                 ("5%", "5%", 0.05 * size)):
        data, report = keyanim.encode(walk, shell=shell)
        out = tmp_path / "s.kanim"
        tool = cli_json("encode", WALK, "-o", out, "-f", "--shell", option, "--json")
        assert out.read_bytes() == data, shell
        assert set(report) == set(tool) and report["error"] == tool["error"], shell
        assert report["error"]["shell"] == pytest.approx(units, rel=1e-12)
        if units == 0.0:
            assert report["error"]["worst_shell_axis"] is None
        err = independent_error(walk_bvh, keyanim.Clip(data).to_motion().channels, units)
        assert err <= report["tolerance"] * (1 + 1e-9)
        assert err == pytest.approx(report["error"]["max"], rel=1e-9)
    # A shell point is measured: the worst point may be one (then its axis is named).
    e = keyanim.encode(walk, shell="5%")[1]["error"]
    assert e["worst_point"] == e["worst_joint"] + ("" if e["worst_shell_axis"] is None else " shell " + e["worst_shell_axis"])


def test_encode_error_in_units_and_percent(keyanim, walk):
    _, coarse = keyanim.encode(walk, error=0.5)
    assert coarse["tolerance"] == 0.5 and coarse["error"]["max"] <= 0.5
    _, pct = keyanim.encode(walk, error="0.5%", threads=1)
    assert pct["keys"] < keyanim.encode(walk)[1]["keys"]
    tool = cli_json("encode", WALK, "-o", "/dev/null", "-f", "--error", "0.5%", "--json")
    assert pct["kanim_bytes"] == tool["kanim_bytes"] and pct["tolerance"] == tool["tolerance"]


@pytest.mark.parametrize("keys,option", [("uniform:10", "uniform:10"), ("curvature", "curvature"),
                                         ([0, 50, 100, 343], "manual:0,50,100,343"),
                                         ("manual:0,50,100", "manual:0,50,100")])
def test_key_modes_match_the_tool(keyanim, walk, tmp_path, keys, option):
    data, report = keyanim.encode(walk, keys=keys)
    out = tmp_path / "k.kanim"
    tool = cli_json("encode", WALK, "-o", out, "--keys", option, "--json")
    assert out.read_bytes() == data
    assert "tolerance" not in report and set(report) == set(tool)
    assert report["error_limit"] == tool["error_limit"]
    assert report["error_limit_met"] == (report["error"]["max"] <= report["error_limit"])


def test_other_settings(keyanim, walk):
    base = keyanim.encode(walk, error="0.5%")[0]
    assert keyanim.encode(walk, error="0.5%", threads=2)[0] == base  # threads never change the bytes
    fitted = keyanim.encode(walk, error="0.5%", tension="fit")[0]
    assert fitted != base
    assert keyanim.Clip(keyanim.encode(walk, error="0.5%", tangent_rule="uniform")[0]).info["tangent_rule"] == "uniform"
    linear = keyanim.Clip(keyanim.encode(walk, error="0.5%", force_linear=True)[0]).info["keys"]
    assert linear["cardinal_channels"] == 0
    assert len(keyanim.encode(walk, error="0.5%", level=1)[0]) >= len(base)
    assert keyanim.encode(walk, error="0.5%", allow_linear=False, tension=0.25)[1]["error"]["max"] > 0


@pytest.mark.parametrize("kwargs,kind", [
    (dict(error="abc"), "invalid_argument"), (dict(error="-1%"), "invalid_argument"),
    (dict(error=0), "invalid_argument"), (dict(error="200%"), "invalid_argument"),
    (dict(error=float("nan")), "invalid_argument"), (dict(keys="bogus"), "invalid_argument"),
    (dict(keys="uniform:0"), "invalid_argument"), (dict(keys="manual:"), "invalid_argument"),
    (dict(keys=[]), "invalid_argument"), (dict(keys=[-1]), "invalid_argument"),
    (dict(tension=2.0), "invalid_argument"), (dict(level=0), "invalid_argument"),
    (dict(threads=-1), "invalid_argument"), (dict(tangent_rule="x"), "invalid_argument"),
    (dict(shell="-1"), "invalid_argument"), (dict(shell="abc"), "invalid_argument"),
    (dict(shell="200%"), "invalid_argument"), (dict(shell=-0.5), "invalid_argument"),
    (dict(shell=float("inf")), "invalid_argument"), (dict(shell=""), "invalid_argument"),
])
def test_bad_settings(keyanim, walk, kwargs, kind):
    with pytest.raises(keyanim.Error) as info:
        keyanim.encode(walk, **kwargs)
    assert info.value.kind == kind and str(info.value)


def test_bad_setting_types(keyanim, walk):
    for kwargs in (dict(error=None), dict(error=True), dict(keys=3.5), dict(tension="tight"), dict(bogus=1),
                   dict(shell=None), dict(shell=True), dict(shell=[2])):
        with pytest.raises(TypeError):
            keyanim.encode(walk, **kwargs)
    # Not a motion nor a path: a TypeError saying what encode takes, not pybind's signature list.
    for bad in (3, None, [1, 2]):
        with pytest.raises(TypeError, match=r"encode\(\) takes a keyanim.Motion .* or the path of a BVH file"):
            keyanim.encode(bad)


def test_encode_takes_a_path(keyanim, walk, tmp_path):
    import pathlib
    from conftest import WALK
    want = keyanim.encode(walk, error="0.5%")
    for path in (str(WALK), pathlib.Path(WALK), bytes(str(WALK), "utf-8")):
        data, report = keyanim.encode(path, error="0.5%")
        assert data == want[0] and report["input"] == str(WALK) and report["bvh_bytes"] == want[1]["bvh_bytes"]
    with pytest.raises(FileNotFoundError):
        keyanim.encode(tmp_path / "missing.bvh")
    (tmp_path / "w.kanim").write_bytes(want[0])
    with pytest.raises(keyanim.Error, match="is a .kanim file, expected BVH text"):
        keyanim.encode(tmp_path / "w.kanim")


def test_manual_frame_beyond_the_motion(keyanim, walk):
    with pytest.raises(keyanim.Error, match="344"):
        keyanim.encode(walk, keys=[0, 344])


def test_motion_the_codec_cannot_take(keyanim):
    m = keyanim.read_bvh(HOP)
    m.channels[3, 4] = np.nan
    with pytest.raises(keyanim.Error):
        keyanim.encode(m)
    m.channels[3, 4] = 1e300
    with pytest.raises(keyanim.Error):
        keyanim.encode(m)


def test_decoded_motion_report_has_no_file(keyanim, walk_clip):
    m = walk_clip.to_motion()
    data, report = keyanim.encode(m)
    assert report["input"] is None and report["bvh_bytes"] is None
    assert keyanim.Clip(data).frame_count == 344


@pytest.mark.corpus
@pytest.mark.parametrize("path", corpus_files() or [None], ids=lambda p: p.name if p else "none")
def test_corpus_encode_within_tolerance(keyanim, path):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        m = keyanim.read_bvh(path)
    data, report = keyanim.encode(m)
    clip = keyanim.Clip(data)
    bvh = parse_bvh(path)
    bvh.values = m.channels  # every line, as read (a few files have more than Frames: says)
    err = independent_error(bvh, clip.to_motion().channels, report["error"]["shell"])
    assert err <= report["tolerance"] * (1 + 1e-9)
    assert err == pytest.approx(report["error"]["max"], rel=1e-9)
    assert report["kanim_bytes"] == len(data) and report["frames"] == m.frame_count
    # The decoded Euler angles of quaternion nodes recompose their stored rotations to about
    # 1e-16: the same error, its sums possibly apart in their last bits.
    assert same_error(keyanim.measure_error(m, clip.to_motion()), report["error"], 1e-12 if clip.quat_nodes else 0.0)
    # With rotations='euler' the decoded values are the encoder's own: the same report, bit for bit.
    data, report = keyanim.encode(m, rotations="euler")
    assert keyanim.measure_error(m, keyanim.Clip(data).to_motion()) == report["error"]


def same_error(a, b, rel):
    """Error reports equal but for floats within `rel` of each other (0: equal)."""
    if isinstance(a, dict) and isinstance(b, dict):
        return a.keys() == b.keys() and all(same_error(a[k], b[k], rel) for k in a)
    if isinstance(a, float) and isinstance(b, float):
        return a == b or abs(a - b) <= rel * max(abs(a), abs(b))
    return type(a) is type(b) and a == b
