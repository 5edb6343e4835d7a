"""keyanim.Bank and keyanim.write_bank (spec/FORMAT.md section 10), and Dataset over banks.

Banks are written with write_bank from clips loaded from their own .kanim files; the index is
read again here with struct from the spec's tables (10.1 to 10.3), not through the module, and
every clip of a bank is compared with the same clip loaded from its own file."""

import os
import pickle
import warnings
import stat
import struct

import numpy as np
import pytest

import keyanim
from conftest import CORPUS, HOP, WALK, corpus_files
from test_hostile import run_bounded

SIGNATURE = b"\x89KAN"


def chain_bvh(path, frames=200):
    """A third skeleton, of another shape than the CMU ones: a root with 6 channels and two
    joints with 3 (12 channels), moving smoothly."""
    lines = ["HIERARCHY", "ROOT Base", "{", "  OFFSET 0 0 0",
             "  CHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation",
             "  JOINT Arm", "  {", "    OFFSET 0 10 0", "    CHANNELS 3 Zrotation Xrotation Yrotation",
             "    JOINT Hand", "    {", "      OFFSET 0 8 0", "      CHANNELS 3 Zrotation Xrotation Yrotation",
             "      End Site", "      {", "        OFFSET 0 3 0", "      }", "    }", "  }", "}",
             "MOTION", "Frames: %d" % frames, "Frame Time: 0.033333"]
    t = np.arange(frames) / 30.0
    for x in t:
        row = [np.sin(x), 0.5 * x, 0.0, 20 * np.sin(2 * x), 10 * np.cos(x), 5.0,
               30 * np.sin(3 * x), 0.0, 12 * np.cos(x), 45 * np.sin(x), 3.0, -7 * x]
        lines.append(" ".join("%.6f" % v for v in row))
    path.write_text("\n".join(lines) + "\n")
    return path


@pytest.fixture(scope="module")
def library(tmp_path_factory):
    """Clips in their own .kanim files (two of the walk's skeleton, one of the hop's, one of a
    12-channel chain, one with a name that is not UTF-8), and banks of them: archive and runtime."""
    root = tmp_path_factory.mktemp("bank")
    walk, hop = keyanim.read_bvh(WALK), keyanim.read_bvh(HOP)
    chain = keyanim.read_bvh(chain_bvh(root / "chain.bvh"))
    data = {"walk": keyanim.encode(walk)[0], "walk/coarse": keyanim.encode(walk, error="0.5%")[0],
            "hop": keyanim.encode(hop)[0], "rigs/chain": keyanim.encode(chain)[0],
            "caf\udce9": keyanim.encode(walk, error="1%")[0]}  # the name's byte 0xE9 is not UTF-8
    files = {}
    for i, (name, d) in enumerate(data.items()):
        files[name] = root / ("clip%d.kanim" % i)
        files[name].write_bytes(d)
    clips = {name: keyanim.Clip(path) for name, path in files.items()}
    archive = root / "lib.kbank"
    report = keyanim.write_bank(archive, clips)
    runtime = root / "runtime.kbank"
    keyanim.write_bank(runtime, list(clips.items()), runtime=True)
    return dict(root=root, files=files, archive=archive, runtime=runtime, report=report, names=list(data))


def read_index(path):
    """Section 10.2 and 10.3, read with struct: the header's counts and flags, and per clip
    (name bytes, offset, size, frame time, frame count, skeleton); the name order."""
    b = path.read_bytes()
    assert b[:4] == SIGNATURE
    major, minor, flags, clips, skeletons, names_size, dictionary = struct.unpack_from("<HHIIIQQ", b, 8)
    table = 40 + 32 * skeletons
    entries = []
    for i in range(clips):
        offset, size, frame_time, frames, skeleton, name_offset, name_size = struct.unpack_from("<QQdIIII", b, table + 40 * i)
        pool = table + 40 * clips + 4 * clips
        entries.append(dict(name=b[pool + name_offset:pool + name_offset + name_size], offset=offset, size=size,
                            frame_time=frame_time, frames=frames, skeleton=skeleton))
    order = struct.unpack_from("<%dI" % clips, b, table + 40 * clips)
    return dict(major=major, minor=minor, flags=flags, clips=clips, skeletons=skeletons, dictionary=dictionary,
                entries=entries, order=order)


def bank_version(clips):
    """Section 10.2: a bank holding a clip with quaternion nodes (format 5.0) is 5.0, else 4.1."""
    return (5, 0) if any(clip.quat_nodes for clip in clips) else (4, 1)


def same_bits(a, b):
    return a.shape == b.shape and np.array_equal(np.asarray(a).view(np.uint32), np.asarray(b).view(np.uint32))


def test_the_index_as_the_spec_lays_it_out(library):
    for path, runtime in ((library["archive"], False), (library["runtime"], True)):
        bank, index = keyanim.Bank(path), read_index(path)
        members = [keyanim.Clip(p) for p in library["files"].values()]
        assert bank_version(members) == (5, 0)  # encode()'s default stores quaternion nodes
        assert (index["major"], index["minor"]) == bank_version(members)
        assert index["flags"] & 4 and bool(index["flags"] & 1) == runtime
        assert len(bank) == index["clips"] == 5 and bank.skeleton_count == index["skeletons"] == 3
        assert bank.profile == ("runtime" if runtime else "archive")
        assert bank.names == library["names"] == list(bank)
        assert bank.dictionary_bytes == index["dictionary"] and bank.size_bytes == path.stat().st_size
        assert bank.file == str(path)
        for i, (got, want) in enumerate(zip(bank.entries, index["entries"])):
            assert got["name"].encode("utf-8", "surrogateescape") == want["name"]
            assert (got["index"], got["frames"], got["skeleton"]) == (i, want["frames"], want["skeleton"])
            assert (got["offset"], got["bytes"]) == (want["offset"], want["size"])
            assert got["frame_time"] == want["frame_time"]
            assert got["duration"] == bank.clip(i).duration
            assert bank.entry(got["name"]) == got == bank.entry(i)
        # The name order: byte order of the names (10.3); find goes through it.
        names = [e["name"] for e in index["entries"]]
        assert list(index["order"]) == sorted(range(len(names)), key=lambda i: names[i])
        for i, name in enumerate(bank.names):
            assert bank.find(name) == i and bank.find(name.encode("utf-8", "surrogateescape")) == i
            assert name in bank
        skeleton = [e["skeleton"] for e in bank.entries]
        assert skeleton[0] == skeleton[1] == skeleton[4] != skeleton[2] != skeleton[3] != skeleton[0]


@pytest.mark.parametrize("runtime", [False, True])
def test_a_bank_of_euler_clips_is_4_1(library, tmp_path, runtime):
    """Clips encoded with rotations='euler' make a 4.1 bank, which decoders of 4.1 read; one
    clip with quaternion nodes among them makes it 5.0."""
    walk, hop = keyanim.read_bvh(WALK), keyanim.read_bvh(HOP)
    euler = {"walk": keyanim.Clip(keyanim.encode(walk, error="0.5%", rotations="euler")[0]),
             "hop": keyanim.Clip(keyanim.encode(hop, error="0.5%", rotations="euler")[0])}
    assert bank_version(euler.values()) == (4, 1)
    keyanim.write_bank(tmp_path / "euler.kbank", euler, runtime=runtime)
    index = read_index(tmp_path / "euler.kbank")
    assert (index["major"], index["minor"]) == (4, 1) and bool(index["flags"] & 1) == runtime
    bank = keyanim.Bank(tmp_path / "euler.kbank")
    for name, clip in euler.items():
        member = bank.clip(name)
        assert member.quat_nodes == [] and member.info["version"] == "4.1"  # a member of version 4 (10.5)
        frames = np.linspace(0, clip.frame_count - 1, 3 * clip.frame_count)
        assert same_bits(member.sample_frames(frames), clip.sample_frames(frames))
    mixed = dict(euler, quat=keyanim.Clip(library["files"]["hop"]))
    assert mixed["quat"].quat_nodes and bank_version(mixed.values()) == (5, 0)
    keyanim.write_bank(tmp_path / "mixed.kbank", mixed, runtime=runtime)
    index = read_index(tmp_path / "mixed.kbank")
    assert (index["major"], index["minor"]) == (5, 0)
    bank = keyanim.Bank(tmp_path / "mixed.kbank")
    assert bank.clip("quat").quat_nodes == mixed["quat"].quat_nodes and bank.clip("walk").quat_nodes == []
    # A member has a version of its own (10.5): 5.0 with quaternion nodes, else 4.1.
    assert bank.clip("quat").info["version"] == "5.0" and bank.clip("walk").info["version"] == "4.1"
    frames = np.linspace(0, euler["walk"].frame_count - 1, 1000)
    assert same_bits(bank.clip("walk").sample_frames(frames), euler["walk"].sample_frames(frames))


def test_write_bank_reports_what_it_wrote(library):
    r = library["report"]
    assert r["file"] == str(library["archive"]) and r["bytes"] == library["archive"].stat().st_size
    assert (r["clips"], r["skeletons"], r["profile"]) == (5, 3, "archive")
    assert r["dictionary_bytes"] == keyanim.Bank(library["archive"]).dictionary_bytes
    assert r["skeletons"] == keyanim.Bank(library["archive"]).skeleton_count


@pytest.mark.parametrize("which", ["archive", "runtime"])
def test_every_clip_equals_its_own_file(library, which):
    bank = keyanim.Bank(library[which])
    for name, path in library["files"].items():
        alone, member = keyanim.Clip(path), bank.clip(name)
        assert member.profile == bank.profile and member.file == "%s:%s" % (library[which], name)
        assert (member.frame_count, member.frame_time, member.channel_count) == \
               (alone.frame_count, alone.frame_time, alone.channel_count)
        assert member.joint_names == alone.joint_names and member.channel_names == alone.channel_names
        assert member.rig_hash == alone.rig_hash and member.total_keys == alone.total_keys
        frames = np.linspace(0, alone.frame_count - 1, 4 * alone.frame_count)
        assert same_bits(member.sample_frames(frames), alone.sample_frames(frames))
        for x, y in zip(member.local_transforms(frames=frames[::7]), alone.local_transforms(frames=frames[::7])):
            assert same_bits(x, y)
        assert same_bits(member.sample_stored(frames), alone.sample_stored(frames))
        assert member.quat_nodes == alone.quat_nodes
        for c in range(0, alone.channel_count, 5):
            assert member.channel(c) == alone.channel(c)
            for x, y in zip(member.channel_keys(c), alone.channel_keys(c)):
                assert np.array_equal(x, y)
        m, want = bank.to_motion(name, fps=30), alone.to_motion(fps=30)
        assert m.frame_count == want.frame_count and np.array_equal(m.channels, want.channels)


def test_clips_of_one_skeleton_share_its_rig(library):
    bank = keyanim.Bank(library["archive"])
    walk, coarse, hop = bank.clip("walk"), bank.clip("walk/coarse"), bank.clip("hop")
    assert walk.shares_rig(coarse) and not walk.shares_rig(hop)
    assert walk.skeleton_bytes == coarse.skeleton_bytes


def test_clips_by_index_and_name(library):
    bank = keyanim.Bank(library["archive"])
    assert bank.clip(-1).file == bank.clip(4).file == "%s:caf\udce9" % library["archive"]
    assert bank.clip(b"caf\xe9").frame_count == bank.clip("caf\udce9").frame_count
    assert b"hop" in bank and "nope" not in bank and 3 not in bank and bank.find("nope") is None
    with pytest.raises(KeyError, match="nope"):
        bank.clip("nope")
    with pytest.raises(KeyError):
        bank.to_motion("walk/")
    for bad in (5, -6, 2 ** 40):
        with pytest.raises(IndexError, match="out of range for a bank of 5 clips"):
            bank.clip(bad)
    assert bank.clip(np.int64(2)).frame_count == 1102  # numpy integers are indices
    for bad in (1.0, True, None):
        with pytest.raises(TypeError):
            bank.clip(bad)
    assert repr(bank) == "<keyanim.Bank: 5 clips, 3 skeletons, archive>"


def test_a_damaged_clip_is_named_and_the_others_load(library, tmp_path):
    data = bytearray(library["archive"].read_bytes())
    hop = read_index(library["archive"])["entries"][2]
    data[hop["offset"] + hop["size"] // 2] ^= 0x10
    damaged = tmp_path / "damaged.kbank"
    damaged.write_bytes(bytes(data))
    for bank in (keyanim.Bank(damaged), keyanim.Bank(bytes(data))):
        with pytest.raises(keyanim.Error) as info:
            bank.clip("hop")
        e = info.value
        assert "clip hop (2)" in str(e) and e.section.startswith("clip hop (2)")
        assert hop["offset"] <= e.offset < hop["offset"] + hop["size"]
        assert e.file == (str(damaged) if bank.file else None)
        for name in ("walk", "walk/coarse", "rigs/chain"):
            assert bank.clip(name).frame_count > 0
    # The index itself is covered by the bank's checksum: a changed frame count is refused at open.
    data = bytearray(library["archive"].read_bytes())
    skeletons = struct.unpack_from("<I", data, 20)[0]
    data[40 + 32 * skeletons + 24] ^= 1
    with pytest.raises(keyanim.Error, match="checksum_mismatch"):
        keyanim.Bank(bytes(data))


def test_what_is_not_a_bank(library, tmp_path):
    with pytest.raises(keyanim.Error, match=r"not a bank.*keyanim\.Clip\(path\)"):
        keyanim.Bank(library["files"]["walk"])
    with pytest.raises(keyanim.Error, match="signature"):
        keyanim.Bank(WALK)
    with pytest.raises(keyanim.Error, match="truncated"):
        keyanim.Bank(library["archive"].read_bytes()[:1000])
    with pytest.raises(FileNotFoundError):
        keyanim.Bank(tmp_path / "missing.kbank")
    with pytest.raises(IsADirectoryError):
        keyanim.Bank(tmp_path)
    with pytest.raises(TypeError):
        keyanim.Bank(3)
    # bytes are a bank's content, as for Clip (a bytes path is os.fsdecode(path) away).
    with pytest.raises(keyanim.Error, match="signature"):
        keyanim.Bank(os.fsencode(library["archive"]))


def test_bytes_and_views(library):
    data = library["archive"].read_bytes()
    for source in (data, bytearray(data), memoryview(data)):
        assert keyanim.Bank(source).names == library["names"]
    # A view that is not C-contiguous is copied in order (as bytes(view)), never read past.
    spaced = bytes(b for byte in data for b in (byte, 0xAA))
    bank = keyanim.Bank(memoryview(spaced)[::2])
    assert bank.file is None and bank.clip("hop").file is None
    assert same_bits(bank.clip("hop").sample_frames([0.0, 10.5]), keyanim.Bank(data).clip("hop").sample_frames([0.0, 10.5]))
    with pytest.raises(keyanim.Error, match="signature"):
        keyanim.Bank(memoryview(data)[::-1])


def test_a_fifo_or_a_device_is_refused_without_waiting(tmp_path):
    os.mkfifo(tmp_path / "pipe.kbank")
    code = ("import keyanim\nfor p in ('pipe.kbank', '/dev/zero', '/dev/null'):\n"
            "    try:\n        keyanim.Bank(p)\n    except keyanim.Error as e:\n        print(e)\n")
    r = run_bounded(code, tmp_path)
    assert r.returncode == 0, r.stderr
    assert r.stdout.splitlines() == ["%s: not a regular file (a bank is mapped into memory)" % p
                                     for p in ("pipe.kbank", "/dev/zero", "/dev/null")]
    assert stat.S_ISFIFO(os.lstat(tmp_path / "pipe.kbank").st_mode)


def test_write_bank_follows_the_output_rules(library, tmp_path):
    clips = {"walk": keyanim.Clip(library["files"]["walk"])}
    out = tmp_path / "one.kbank"
    keyanim.write_bank(out, clips)
    with pytest.raises(FileExistsError):
        keyanim.write_bank(out, {"other": clips["walk"]})
    assert keyanim.Bank(out).names == ["walk"]
    keyanim.write_bank(out, {"other": clips["walk"]}, overwrite=True)
    assert keyanim.Bank(out).names == ["other"]
    for bad in ("", "a//b", "../up", "a/./b", "/abs", "x\0y", "n" * 1025):
        with pytest.raises(keyanim.Error):
            keyanim.write_bank(tmp_path / "bad.kbank", {bad: clips["walk"]})
    with pytest.raises(keyanim.Error, match="twice|two|same|duplicate"):
        keyanim.write_bank(tmp_path / "bad.kbank", [("a", clips["walk"]), ("a", clips["walk"])])
    with pytest.raises(TypeError, match="keyanim.Clip"):
        keyanim.write_bank(tmp_path / "bad.kbank", {"m": keyanim.read_bvh(WALK)})
    with pytest.raises(TypeError):
        keyanim.write_bank(tmp_path / "bad.kbank", {3: clips["walk"]})
    with pytest.raises(ValueError, match="dictionary"):
        keyanim.write_bank(tmp_path / "bad.kbank", clips, dictionary="maybe")
    assert sorted(os.listdir(tmp_path)) == ["one.kbank"]  # no temporary file, nothing half-written


def test_the_dictionary_settings(library, tmp_path):
    clips = [(name, keyanim.Clip(path)) for name, path in library["files"].items()]
    never = keyanim.write_bank(tmp_path / "never.kbank", clips, dictionary="never")
    always = keyanim.write_bank(tmp_path / "always.kbank", clips, dictionary="always")
    assert never["dictionary_bytes"] == 0 and never["bytes_without_dictionary"] is None
    assert keyanim.Bank(tmp_path / "always.kbank").dictionary_bytes == always["dictionary_bytes"]
    assert always["bytes_without_dictionary"] == never["bytes"]  # what the same bank is without it
    assert always["dictionary_bytes"] > 0  # zstd trained one on these sections
    # 'auto' keeps the smaller of the two, and then says what the other would have been.
    auto = library["report"]
    assert auto["bytes"] == min(never["bytes"], always["bytes"])
    assert (auto["dictionary_bytes"] > 0) == (always["bytes"] < never["bytes"])
    if auto["dictionary_bytes"]:
        assert auto["bytes_without_dictionary"] == never["bytes"]
    bank = keyanim.Bank(tmp_path / "always.kbank")
    for name, clip in clips:
        frames = np.arange(0.0, clip.frame_count, 0.5)[: 2 * clip.frame_count - 1]
        assert same_bits(bank.clip(name).sample_frames(frames), clip.sample_frames(frames))


# ---- Dataset over banks.

def expected_windows(frames, window, stride):
    return 0 if frames < window else (frames - window) // stride + 1


def test_dataset_over_a_bank_and_per_skeleton(library):
    ds = keyanim.Dataset(library["archive"], window=64)
    files = keyanim.Dataset([library["files"][n] for n in library["names"]], window=64)
    assert ds.names == library["names"] and ds.paths == [str(library["archive"])] * 5
    assert ds.files == [str(library["archive"])]
    assert len(ds) == len(files) == sum(expected_windows(c.frame_count, 64, 64) for c in files.clips)
    for i in range(0, len(ds), 3):
        assert ds.locate(i) == files.locate(i) and same_bits(ds[i], files[i])
    # Three skeletons: walk and hop share a shape (96 channels) but not a rig; the chain has 12.
    walk, hop, chain = (keyanim.Clip(library["files"][n]).rig_hash for n in ("walk", "hop", "rigs/chain"))
    assert ds.skeletons == [walk, hop, chain]
    shapes = {}
    for h in ds.skeletons:
        one = keyanim.Dataset(library["archive"], window=64, skeleton=h)
        assert one.skeleton == h and {c.rig_hash for c in one.clips} == {h}
        assert one.skeletons == ds.skeletons
        shapes[h] = {one[i].shape for i in range(len(one))}
        assert len(shapes[h]) == 1
        kept = [n for n, c in zip(ds.names, ds.clips) if c.rig_hash == h]
        assert one.names == kept
        assert len(one) == sum(expected_windows(c.frame_count, 64, 64) for c in ds.clips if c.rig_hash == h)
    assert shapes == {walk: {(64, 96)}, hop: {(64, 96)}, chain: {(64, 12)}}
    again = pickle.loads(pickle.dumps(keyanim.Dataset(library["archive"], window=64, skeleton=chain)))
    assert again.skeleton == chain and len(again) == len(keyanim.Dataset(library["archive"], window=64, skeleton=chain))
    with pytest.raises(ValueError, match="no clip has the skeleton"):
        keyanim.Dataset(library["archive"], skeleton=12345)
    for bad in ("walk", 1.5, True):
        with pytest.raises(ValueError, match="skeleton must be"):
            keyanim.Dataset(library["archive"], skeleton=bad)


def test_dataset_batches_of_one_skeleton_stack(library):
    ds = keyanim.Dataset(library["archive"], window=32, stride=16, output=("channels", "world_positions"))
    rig = [ds.clips[ds.locate(i)[0]].rig_hash for i in range(len(ds))]
    for shuffle, drop_last in ((False, False), (True, False), (True, True)):
        batches = ds.batches(8, shuffle=shuffle, drop_last=drop_last, seed=3)
        got = list(batches)
        assert len(got) == len(batches)
        for batch in got:
            assert len({rig[i] for i in batch}) == 1 and 1 <= len(batch) <= 8
            assert not drop_last or len(batch) == 8
            # What a DataLoader's default collate does: stack each output over the batch.
            channels = np.stack([ds[i][0] for i in batch])
            positions = np.stack([ds[i][1] for i in batch])
            assert channels.shape[:2] == positions.shape[:2] == (len(batch), 32)
        seen = sorted(i for b in got for i in b)
        if drop_last:
            assert len(seen) == len(set(seen)) and len(seen) > len(ds) - 8 * len(ds.skeletons)
        else:
            assert seen == list(range(len(ds)))  # every window once
    plain = list(ds.batches(8))
    assert plain[0] == list(range(8))  # in order: the walk's windows first
    a, b = ds.batches(8, shuffle=True, seed=5), ds.batches(8, shuffle=True, seed=5)
    first = list(a)
    assert first == list(b) != plain  # seeded: the same order from the same seed
    second = list(a)
    assert second != first and sorted(map(sorted, second)) != sorted(map(sorted, first))  # a new order each pass
    with pytest.raises(ValueError, match="batch_size"):
        ds.batches(0)


def test_dataset_over_a_folder_of_banks_and_files(library, tmp_path):
    (tmp_path / "sub").mkdir()
    os.symlink(library["runtime"], tmp_path / "sub" / "runtime.kbank")
    os.symlink(WALK, tmp_path / "walk.bvh")
    os.mkfifo(tmp_path / "stuck.kbank")  # left out: not a regular file
    ds = keyanim.Dataset(tmp_path, window=64)
    assert [os.path.basename(p) for p in ds.files] == ["runtime.kbank", "walk.bvh"]
    assert ds.names == library["names"] + [None]
    assert all(c.profile == "runtime" for c in ds.clips[:5])
    walk = keyanim.Clip(library["files"]["walk"])
    assert ds.clips[0].rig_hash == walk.rig_hash == ds.clips[5].rig_hash  # one skeleton, from a bank and a BVH
    assert same_bits(ds[0], walk.sample_frames(np.arange(64.0), continuous=True))


@pytest.mark.corpus
def test_the_corpus_in_one_bank(tmp_path):
    """The issue's case: the corpus's clips have many skeletons (windows of (64, 6) to (64, 132)).
    Packed into one bank (every frame a key, Clip.from_motion), its dataset gives the folder's
    windows, and batches() and skeleton= give arrays that stack."""
    files = corpus_files()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        folder = keyanim.Dataset(files, window=64)
    names = [os.path.relpath(p, CORPUS) for p in folder.paths]
    keyanim.write_bank(tmp_path / "corpus.kbank", dict(zip(names, folder.clips)))
    ds = keyanim.Dataset(tmp_path / "corpus.kbank", window=64)
    assert ds.names == names and len(ds) == len(folder)
    assert ds.skeletons == folder.skeletons and len(ds.skeletons) == len({c.rig_hash for c in folder.clips}) > 1
    rng = np.random.default_rng(7)
    for i in rng.integers(0, len(ds), 40):
        assert same_bits(ds[int(i)], folder[int(i)])
    shapes = set()
    for batch in ds.batches(32):
        shapes.add(np.stack([ds[i] for i in batch]).shape[1:])
    assert len(shapes) > 1 and (64, 96) in shapes
    one = keyanim.Dataset(tmp_path / "corpus.kbank", window=64, skeleton=folder.clips[0].rig_hash)
    assert np.stack([one[i] for i in range(len(one))]).shape == (len(one), 64, folder.clips[0].channel_count)
