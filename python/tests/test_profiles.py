"""The format's two profiles (spec/FORMAT.md section 9) from Python: a clip's runtime_bytes()
load as the runtime profile and sample to the same bits; archive_bytes() give them back; a
damaged runtime file is refused; the spec's vectors of both profiles agree."""

import pathlib
import struct

import numpy as np
import pytest

import keyanim
from conftest import HOP

VECTORS = pathlib.Path(__file__).resolve().parents[2] / "spec" / "test-vectors"


@pytest.fixture(scope="module", params=["quaternion", "euler"])
def hop(request):
    """The hop encoded as encode() does by default (quaternion nodes) and with rotations='euler'."""
    return keyanim.Clip(keyanim.encode(HOP, rotations=request.param)[0])


def same_bits(a, b):
    return np.array_equal(np.asarray(a).view(np.uint32), np.asarray(b).view(np.uint32))


def header(data):
    """(Major_Version, Minor_Version, Runtime flag) of a .kanim (section 2.2)."""
    major, minor, flags = struct.unpack("<HHI", data[8:16])
    return major, minor, flags & 1


def test_runtime_bytes_sample_to_the_same_bits(hop):
    data = hop.runtime_bytes()
    # A clip with quaternion nodes is 5.0 in either profile; without, the runtime profile is 4.0.
    assert header(data) == ((5, 0, 1) if hop.quat_nodes else (4, 0, 1))
    assert bool(hop.quat_nodes) == (hop.info["version"] == "5.0")
    runtime = keyanim.Clip(data)
    assert hop.profile == "archive" and runtime.profile == "runtime"
    assert runtime.quat_nodes == hop.quat_nodes and runtime.info["version"] == "%d.%d" % header(data)[:2]
    times = np.linspace(0, hop.duration, 301)
    assert same_bits(hop.sample(times), runtime.sample(times))
    frames = times / hop.frame_time
    assert same_bits(hop.sample_stored(frames), runtime.sample_stored(frames))
    for t in times[::30]:
        for x, y in zip(hop.local_transforms(float(t)), runtime.local_transforms(float(t))):
            assert same_bits(x, y)
    for c in range(hop.channel_count):
        assert hop.channel(c) == runtime.channel(c)


def test_archive_bytes_give_the_keys_back(hop):
    data = keyanim.Clip(hop.runtime_bytes()).archive_bytes()
    assert header(data) == ((5, 0, 0) if hop.quat_nodes else (3, 0, 0))
    back = keyanim.Clip(data)
    assert back.profile == "archive" and back.quat_nodes == hop.quat_nodes
    times = np.linspace(0, hop.duration, 257)
    assert same_bits(hop.sample(times), back.sample(times))
    assert same_bits(hop.sample_stored(times / hop.frame_time), back.sample_stored(times / hop.frame_time))


def test_a_damaged_runtime_file_is_refused(hop):
    data = bytearray(hop.runtime_bytes())
    data[300] ^= 0x04
    with pytest.raises(keyanim.Error, match="checksum_mismatch"):
        keyanim.Clip(bytes(data))


@pytest.mark.parametrize("name", ["rules", "uniform", "single", "long", "predict", "blocks"])
def test_the_vectors_of_both_profiles_agree(name):
    a = keyanim.Clip(VECTORS / f"v3_{name}.kanim")
    r = keyanim.Clip(VECTORS / f"v4_{name}.kanim")
    assert r.profile == "runtime" and r.runtime_bytes() == (VECTORS / f"v4_{name}.kanim").read_bytes()
    frames = np.linspace(0, a.frame_count - 1, min(2000, 4 * a.frame_count))
    assert same_bits(a.sample_frames(frames), r.sample_frames(frames))
