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


@pytest.fixture(scope="module")
def hop():
    return keyanim.Clip(keyanim.encode(HOP)[0])


def same_bits(a, b):
    return np.array_equal(np.asarray(a).view(np.uint32), np.asarray(b).view(np.uint32))


def test_runtime_bytes_sample_to_the_same_bits(hop):
    data = hop.runtime_bytes()
    major, minor, flags = struct.unpack("<HHI", data[8:16])
    assert (major, minor, flags & 1) == (4, 0, 1)
    runtime = keyanim.Clip(data)
    assert hop.profile == "archive" and runtime.profile == "runtime"
    times = np.linspace(0, hop.duration, 301)
    assert same_bits(hop.sample(times), runtime.sample(times))
    for t in times[::30]:
        for x, y in zip(hop.local_transforms(float(t)), runtime.local_transforms(float(t))):
            assert same_bits(x, y)
    for c in range(hop.channel_count):
        a, b = hop.channel(c), runtime.channel(c)
        assert a["key_count"] == b["key_count"]


def test_archive_bytes_give_the_keys_back(hop):
    back = keyanim.Clip(keyanim.Clip(hop.runtime_bytes()).archive_bytes())
    assert back.profile == "archive"
    times = np.linspace(0, hop.duration, 257)
    assert same_bits(hop.sample(times), back.sample(times))


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
