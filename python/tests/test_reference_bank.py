"""spec/test-vectors/reference_decoder.py on banks (spec section 10, versions 4.1 and 5.0).

The banks are made here by BankWriter, a small writer written from section 10's text (a test
helper, not shipped): it turns the existing test vectors into members (SKEL taken out, into
the bank's skeletons, each distinct skeleton once, stored as the vector stored it, zstd or not;
Major_Version 4 and the Member bit set;
the member's own checksum recomputed) and lays out header, tables, name order, names,
dictionary, skeletons, Bank_Checksum and members as 10.1 says. Every clip must decode to the
keys and the expected values (.json) of the standalone vector it came from; then one rule of
section 10 at a time is broken and must be refused with its status, a member's failure naming
the clip while the others still decode. Banks of version 5.0 hold members of version 5 (clips
with quaternion nodes) beside members of version 4; a member of version 5 in a bank of version
4 is refused.

The dictionary case trains a zstd dictionary on the vectors' sections with the `zstd` program
(`zstd --train`), and recompresses the members' compressed sections with it.

Needs no keyanim module: CTest runs this file on its own (tests/CMakeLists.txt, reference_bank).
"""

import functools
import importlib.util
import json
import os
import struct
import subprocess
import sys
import tempfile
import tracemalloc
import zlib
from pathlib import Path

import pytest

REPO = Path(os.environ.get("KEYANIM_REPO_DIR", Path(__file__).resolve().parent.parent.parent))
VECTORS = REPO / "spec" / "test-vectors"
DECODER = VECTORS / "reference_decoder.py"

_spec = importlib.util.spec_from_file_location("reference_decoder", DECODER)
rd = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(rd)

SIGNATURE = bytes.fromhex("894B414E0D0A1A0A")
MEMBER, BANK, RUNTIME = 2, 4, 1


def vector(name):
    return (VECTORS / name).read_bytes()


def zstd(args, data):
    """The zstd program on `data` given as a file (so that a compressed frame declares its
    content size, 3.2.5)."""
    with tempfile.TemporaryDirectory() as d:
        src = Path(d) / "in"
        src.write_bytes(data)
        return subprocess.run(["zstd", "-q", "-c", *args, str(src)], check=True, stdout=subprocess.PIPE).stdout


def pad8(n):
    return -(-n // 8) * 8


# ---- The writer (section 10, from its text)

def table_of(data):
    """[(tag, flags, stored, raw, body)] of a clip file (3.1)."""
    count = struct.unpack_from("<I", data, 16)[0]
    pos, out = 24 + 24 * count, []
    for i in range(count):
        tag, flags, stored, raw = struct.unpack_from("<4sIQQ", data, 24 + 24 * i)
        out.append((tag, flags, stored, raw, data[pos:pos + stored]))
        pos += stored
    return out


def with_checksum(body, runtime):
    """A clip file's (or member's) bytes with its checksum appended: XXH64 in the runtime
    profile (9.1.3), CRC-32 in the archive profile (3.3)."""
    if runtime:
        return body + struct.pack("<Q", rd.xxh64(body))
    return body + struct.pack("<I", zlib.crc32(body))


_MEMBERS = {}


def as_member(data, dictionary=None, minor=None, keep_skel=False):
    """as_member_uncached, once per arguments (each zstd run is a process)."""
    key = (data, dictionary and Path(dictionary).read_bytes(), minor, keep_skel)
    if key not in _MEMBERS:
        _MEMBERS[key] = as_member_uncached(data, dictionary, minor, keep_skel)
    return _MEMBERS[key]


def as_member_uncached(data, dictionary=None, minor=None, keep_skel=False):
    """(member bytes, skeleton, CLIP's Frame_Time, CLIP's Frame_Count) of clip file `data`
    (10.5): version 4.`minor` (default 4.1), or 5.`minor` for a file of version 5 (default
    5.0), Member set, no SKEL (kept, to break 10.5.2, with keep_skel),
    compressed sections recompressed with the bank's dictionary (a file) when there is one.
    skeleton: {raw: SKEL's content, stored: its bytes in the file, flags: Compressed or 0},
    stored in the bank as the file stores it (a zstd frame made without any dictionary)."""
    flags = struct.unpack_from("<I", data, 12)[0]
    runtime = bool(flags & RUNTIME)
    entries, skel = [], None
    for tag, sflags, stored, raw, body in table_of(data):
        plain = zstd(["-d"], body) if sflags & 1 else body
        if tag == b"SKEL":
            skel = {"raw": plain, "stored": body, "flags": sflags & 1}
            if not keep_skel:
                continue
        elif sflags & 1 and dictionary is not None:
            body = zstd(["-19", "-D", dictionary], plain)
        entries.append((tag, sflags, len(body), raw, body))
    clip = next(e[4] for e in entries if e[0] == b"CLIP")
    major = 5 if struct.unpack_from("<H", data, 8)[0] >= 5 else 4
    if minor is None:
        minor = 1 if major == 4 else 0
    head = SIGNATURE + struct.pack("<HHIII", major, minor, flags | MEMBER, len(entries), 0)
    table = b"".join(struct.pack("<4sIQQ", t, f, s, r) for t, f, s, r, _ in entries)
    member = with_checksum(head + table + b"".join(e[4] for e in entries), runtime)
    frame_count, = struct.unpack_from("<I", clip, 0)
    return member, skel, struct.unpack_from("<d", clip, 16)[0], frame_count


class BankWriter:
    """A bank of clips: add() them (name, clip file bytes), then build(). Each distinct SKEL
    content becomes one skeleton. The fields of build() can be overridden to break a rule;
    `at` tells where each part was put."""

    def __init__(self, runtime=False, dictionary=None):
        self.runtime, self.dictionary = runtime, dictionary
        self.skeletons, self.clips = [], []

    def add(self, name, data, **member_args):
        member, skel, frame_time, frame_count = as_member(data, dictionary=self.dict_path(), **member_args)
        raws = [x["raw"] for x in self.skeletons]
        if skel["raw"] not in raws:  # each distinct skeleton (its content) once
            self.skeletons.append(dict(skel))
            raws.append(skel["raw"])
        self.clips.append({"name": name, "member": member, "frame_time": frame_time,
                           "frame_count": frame_count, "skeleton": raws.index(skel["raw"])})
        return self

    def dict_path(self):
        if self.dictionary is None:
            return None
        if not hasattr(self, "_dict_file"):
            self._dict_dir = tempfile.TemporaryDirectory()
            self._dict_file = str(Path(self._dict_dir.name) / "dict")
            Path(self._dict_file).write_bytes(self.dictionary)
        return self._dict_file

    def build(self, order=None, pool=None, name_at=None, flags=None, major=None, minor=None, clip_count=None,
              skeleton_count=None, names_size=None, dictionary_size=None):
        """The bank's bytes (10.1-10.4). order: the name order (default: the clips by name);
        pool, name_at: the name pool and each clip's Name_Offset (default: the names one after
        the other); major, minor: the version (default 5.0 when a member is of version 5, else
        4.1)."""
        if major is None:
            major = max([4] + [struct.unpack_from("<H", c["member"], 8)[0] for c in self.clips])
        if minor is None:
            minor = 1 if major == 4 else 0
        names = [c["name"] for c in self.clips]
        if pool is None:
            pool, name_at = b"".join(names), [sum(map(len, names[:i])) for i in range(len(names))]
        if order is None:
            order = sorted(range(len(names)), key=lambda i: names[i])
        dictionary = self.dictionary or b""
        n_clips, n_skel = len(self.clips), len(self.skeletons)
        self.at = {"clip_table": 40 + 32 * n_skel, "order": 40 + 32 * n_skel + 40 * n_clips}
        self.at["names"] = self.at["order"] + 4 * n_clips
        pos = self.at["names"] + len(pool)
        self.at["dictionary"] = pad8(pos)
        pos = self.at["dictionary"] + len(dictionary)
        skel_at = []
        for s in self.skeletons:
            skel_at.append(pad8(pos))
            pos = skel_at[-1] + len(s["stored"])
        self.at["checksum"] = pad8(pos)
        pos = self.at["checksum"] + 8
        member_at = []
        for c in self.clips:
            member_at.append(pad8(pos))
            pos = member_at[-1] + len(c["member"])
        self.at["skeletons"], self.at["members"] = skel_at, member_at
        header = SIGNATURE + struct.pack(
            "<HHIIIQQ", major, minor, (BANK | (RUNTIME if self.runtime else 0)) if flags is None else flags,
            n_clips if clip_count is None else clip_count, n_skel if skeleton_count is None else skeleton_count,
            len(pool) if names_size is None else names_size, len(dictionary) if dictionary_size is None else dictionary_size)
        out = bytearray(header)
        out += b"".join(struct.pack("<QQQII", skel_at[j], len(s["stored"]), s.get("raw_size", len(s["raw"])), s["flags"], 0)
                        for j, s in enumerate(self.skeletons))
        out += b"".join(struct.pack("<QQdIIII", member_at[i], len(c["member"]), c["frame_time"], c["frame_count"],
                                    c["skeleton"], name_at[i], len(c["name"])) for i, c in enumerate(self.clips))
        out += struct.pack(f"<{len(order)}I", *order) + pool
        for at, part in [(self.at["dictionary"], dictionary)] + list(zip(skel_at, [x["stored"] for x in self.skeletons])):
            out += bytes(at - len(out)) + part
        out += bytes(self.at["checksum"] - len(out))
        out += struct.pack("<Q", rd.xxh64(bytes(out)))
        for at, c in zip(member_at, self.clips):
            out += bytes(at - len(out)) + c["member"]
        return bytes(out)

    def refix(self, data):
        """`data` (this bank, changed) with Bank_Checksum recomputed over the changed bytes."""
        b = bytearray(data)
        struct.pack_into("<Q", b, self.at["checksum"], rd.xxh64(bytes(b[:self.at["checksum"]])))
        return bytes(b)

    def entry(self, i):
        return self.at["clip_table"] + 40 * i

    def skeleton_entry(self, j):
        return 40 + 32 * j


# ---- The banks of the tests

def slow_rules():
    """v3_rules with Frame_Time doubled, as a file of its own: another clip of the same
    skeleton."""
    out = bytearray(vector("v3_rules.kanim"))
    clip_at = 24 + 24 * struct.unpack_from("<I", out, 16)[0]
    struct.pack_into("<d", out, clip_at + 16, 2 * struct.unpack_from("<d", out, clip_at + 16)[0])
    struct.pack_into("<I", out, len(out) - 4, zlib.crc32(bytes(out[:-4])))
    return bytes(out)


# name in the bank -> the standalone file it comes from, and the .json of its expected values
ARCHIVE_CLIPS = {
    b"walk/rules": ("v3_rules.kanim", "v3_rules.json"),
    b"uniform": ("v3_uniform.kanim", "v3_uniform.json"),
    b"walk/rules v4": ("v4_archive.kanim", "v4_archive.json"),  # v3_rules' skeleton again
    b"single": ("v3_single.kanim", "v3_single.json"),
    b"long/clip": ("v3_long.kanim", "v3_long.json"),
    b"predict": ("v3_predict.kanim", "v3_predict.json"),
    b"walk/rules/slow": (slow_rules, None),  # v3_rules' skeleton, another Frame_Time
    b"blocks": ("v3_blocks.kanim", "v3_blocks.json"),
}
RUNTIME_CLIPS = {name.encode(): (f"v4_{name}.kanim", f"v4_{name}.json")
                 for name in ["rules", "uniform", "single", "long", "predict", "blocks"]}


def source(entry):
    return entry() if callable(entry) else vector(entry)


def make_bank(clips, runtime=False, dictionary=None):
    w = BankWriter(runtime, dictionary)
    for name, (src, _) in clips.items():
        w.add(name, source(src))
    return w


@pytest.fixture(scope="module")
def archive():
    w = make_bank(ARCHIVE_CLIPS)
    return w, w.build()


@pytest.fixture(scope="module")
def runtime():
    w = make_bank(RUNTIME_CLIPS, runtime=True)
    return w, w.build()


@functools.lru_cache(maxsize=None)
def trained_dictionary(max_size):
    """A zstd dictionary trained by the zstd program on the v3 vectors' sections."""
    with tempfile.TemporaryDirectory() as d:
        n = 0
        for p in sorted(VECTORS.glob("v3_*.kanim")):
            for tag, flags, _, _, body in table_of(p.read_bytes()):
                (Path(d) / f"s{n:02d}").write_bytes(zstd(["-d"], body) if flags & 1 else body)
                n += 1
        out = Path(d) / "dict"
        subprocess.run(["zstd", "-q", "-q", "--train", *sorted(str(x) for x in Path(d).glob("s*")), f"--maxdict={max_size}",
                        "-o", str(out)], check=True)
        return out.read_bytes()


@pytest.fixture(scope="module")
def dictionary_bank():
    w = make_bank({k: v for k, v in ARCHIVE_CLIPS.items() if k != b"blocks"}, dictionary=trained_dictionary(4096))
    return w, w.build()


def compare_with_standalone(clip, src):
    want = rd.parse(source(src))
    for key in ["frame_count", "frame_time", "tangent_rule", "nodes", "interp", "frames", "notes"]:
        assert clip[key] == want[key], key
    bits = lambda vs: [[rd.f32_bits(v) for v in c] for c in vs]
    assert [rd.f32_bits(t) for t in clip["tension"]] == [rd.f32_bits(t) for t in want["tension"]]
    assert bits(clip["values"]) == bits(want["values"])


def json_less_names(text):
    d = json.loads(text)
    for key in ["vector", "clip", "format_version"]:
        d.pop(key, None)
    return json.dumps(d)


def check_bank_decodes(w, data, clips):
    bank = rd.open_bank(data)
    assert [c["name"] for c in bank["clips"]] == list(clips)
    for i, (name, (src, expected_json)) in enumerate(clips.items()):
        assert rd.find_clip(bank, name) == i
        clip = rd.decode_member(bank, i)
        assert clip["version"] == ((5, 0) if rd.parse(source(src))["version"][0] == 5 else (4, 1))
        compare_with_standalone(clip, src)
        if expected_json:
            text = rd.json_text(rd.expected_values(clip, "bank.kbank", name.decode()))
            assert json_less_names(text) == json_less_names((VECTORS / expected_json).read_text()), name
    return bank


# ---- Valid banks

def test_an_archive_bank_decodes_each_clip_as_its_standalone_vector(archive):
    w, data = archive
    bank = check_bank_decodes(w, data, ARCHIVE_CLIPS)
    assert not bank["runtime"] and bank["dictionary"] is None
    assert [s["flags"] for s in bank["skeletons"]] == [1, 0, 1, 1, 0, 1]  # zstd and plain skeletons
    # two skeletons fewer than clips: v3_rules' is shared by three clips
    assert len(bank["skeletons"]) == len(ARCHIVE_CLIPS) - 2
    assert [c["skeleton"] for c in bank["clips"]][:3] == [0, 1, 0]
    assert bank["order"] != list(range(len(ARCHIVE_CLIPS)))  # the name order is not the table's


def test_a_runtime_bank_decodes_each_clip_as_its_standalone_vector(runtime):
    w, data = runtime
    bank = check_bank_decodes(w, data, RUNTIME_CLIPS)
    assert bank["runtime"]
    for c in bank["clips"]:  # IMAG's content 8-aligned from the bank's first byte (10.5)
        member = data[c["offset"]:c["offset"] + c["size"]]
        count = struct.unpack_from("<I", member, 16)[0]
        assert (c["offset"] + 24 + 24 * count + 32) % 8 == 0 and c["offset"] % 8 == 0


def test_a_bank_with_a_dictionary_decodes_each_clip(dictionary_bank):
    w, data = dictionary_bank
    bank = check_bank_decodes(w, data, {k: v for k, v in ARCHIVE_CLIPS.items() if k != b"blocks"})
    assert bank["dictionary"] == w.dictionary and w.dictionary[:4] == bytes.fromhex("37A430EC")
    # The frames were made with the dictionary: they name its ID, and need it.
    dict_id = struct.unpack_from("<I", w.dictionary, 4)[0]
    member = w.clips[0]["member"]
    compressed = [body for _, flags, _, _, body in table_of(member) if flags & 1]
    assert compressed
    for body in compressed:
        assert body[4] & 3 == 3 and struct.unpack_from("<I", body, 5 + (0 if body[4] & 0x20 else 1))[0] == dict_id
        with pytest.raises(rd.KanimError) as e:
            rd.zstd_decompress(body)
        assert e.value.status == "zstd_error"


def test_an_empty_bank_opens_with_no_clip():
    w = BankWriter()
    bank = rd.open_bank(w.build())
    assert bank["clips"] == [] and bank["skeletons"] == [] and rd.find_clip(bank, b"a") is None


def test_find_by_name_over_many_clips():
    names = [f"set{i % 7}/clip{i:03d}".encode() for i in range(0, 300, 7)] + [b"a", b"a/b", b"ab", b"\xff"]
    w = BankWriter()
    for n in names:
        w.add(n, vector("v3_single.kanim"))
    bank = rd.open_bank(w.build())
    for i, n in enumerate(names):
        assert rd.find_clip(bank, n) == i
    for absent in [b"", b"\x00", b"a/", b"a/c", b"set0", b"set0/clip000x", b"zzz", b"\xff\xff"]:
        assert rd.find_clip(bank, absent) is None
    assert rd.decode_member(bank, len(names) - 1)["frame_count"] == 1


def test_names_may_share_bytes_of_the_pool():
    w = BankWriter()
    w.add(b"walk/rules", vector("v3_rules.kanim")).add(b"walk", vector("v3_single.kanim"))
    data = w.build(pool=b"walk/rules", name_at=[0, 0])
    bank = rd.open_bank(data)
    assert [c["name"] for c in bank["clips"]] == [b"walk/rules", b"walk"] and bank["order"] == [1, 0]
    assert rd.find_clip(bank, b"walk") == 1


def test_a_member_of_minor_version_0_decodes():
    w = BankWriter()
    w.add(b"rules", vector("v3_rules.kanim"), minor=0)
    assert rd.decode_member(rd.open_bank(w.build()), 0)["version"] == (4, 0)


# ---- Banks of version 5.0: members of version 5 beside members of version 4

ARCHIVE_CLIPS_V5 = {
    b"quat": ("v5_quat.kanim", "v5_quat.json"),
    b"walk/rules": ("v3_rules.kanim", "v3_rules.json"),  # a member of version 4 (3.0's layout)
    b"blocks/quat": ("v5_blocks.kanim", "v5_blocks.json"),
    b"walk/rules v4": ("v4_archive.kanim", "v4_archive.json"),  # v3_rules' skeleton again
}
RUNTIME_CLIPS_V5 = {
    b"quat": ("v5_quat_runtime.kanim", "v5_quat_runtime.json"),
    b"rules": ("v4_rules.kanim", "v4_rules.json"),
    b"blocks/quat": ("v5_blocks_runtime.kanim", "v5_blocks_runtime.json"),
}


@pytest.mark.parametrize("runtime", [False, True])
def test_a_version_5_bank_decodes_each_clip_as_its_standalone_vector(runtime):
    clips = RUNTIME_CLIPS_V5 if runtime else ARCHIVE_CLIPS_V5
    w = make_bank(clips, runtime=runtime)
    data = w.build()
    assert struct.unpack_from("<HH", data, 8) == (5, 0) and rd.is_bank(data)
    bank = check_bank_decodes(w, data, clips)
    assert bank["version"] == (5, 0) and bank["runtime"] == runtime
    quat = rd.decode_member(bank, 0)
    assert [q["node"] for q in quat["quat_nodes"]] == [1, 2, 3, 5]


def test_a_version_5_bank_of_version_4_members_only_decodes():
    """A bank of version 5.0 may hold members of version 4 alone (10.5: a member's major version
    at most its bank's)."""
    w = make_bank({b"rules": ("v3_rules.kanim", "v3_rules.json")})
    bank = rd.open_bank(w.build(major=5))
    assert bank["version"] == (5, 0) and rd.decode_member(bank, 0)["version"] == (4, 1)


def v5_member_change(change):
    """Clip 0's member (v5_quat's) with its table changed by change([(tag, flags, stored, raw,
    body)]) and its CRC-32 fixed."""
    def make(c):
        member = c["member"]
        entries = table_of(member)
        change(entries)
        head = bytearray(member[:24])
        struct.pack_into("<I", head, 16, len(entries))
        table = b"".join(struct.pack("<4sIQQ", t, f, s, r) for t, f, s, r, _ in entries)
        return with_checksum(bytes(head) + table + b"".join(e[4] for e in entries), False)
    return make


def drop_quat(entries):
    entries.pop(next(i for i, x in enumerate(entries) if x[0] == b"QUAT"))


def v5_bank(runtime=False, member=None, major=None):
    """A bank of ARCHIVE_CLIPS_V5 (or RUNTIME_CLIPS_V5) with clip 0's member remade by
    member(writer clip), and its header's Major_Version `major` (default: the writer's, 5)."""
    def make():
        w = make_bank(RUNTIME_CLIPS_V5 if runtime else ARCHIVE_CLIPS_V5, runtime=runtime)
        if member:
            w.clips[0]["member"] = member(w.clips[0])
        return w, w.build(major=major)
    return make


V5_MEMBER_RULES = {
    # (how, status, message); the member refused is clip 0, v5_quat's
    "a member of version 5 in a bank of version 4": (v5_bank(major=4), "corrupt",
                                                     "a member of version 5 in a bank of version 4"),
    "a runtime member of version 5 in a bank of version 4": (v5_bank(runtime=True, major=4), "corrupt",
                                                             "a member of version 5 in a bank of version 4"),
    "a member of version 6": (v5_bank(member=lambda c: member_header(major=6)(c), major=5), "unsupported_version",
                              "major 6"),
    "a member of version 5 without QUAT": (v5_bank(member=v5_member_change(drop_quat)), "corrupt", "critical sections"),
    "a member of version 5 with its SKEL": (v5_bank(member=lambda c: as_member(vector("v5_quat.kanim"), keep_skel=True)[0]),
                                            "corrupt", "a SKEL section in a bank's member"),
}


@pytest.mark.parametrize("case", list(V5_MEMBER_RULES))
def test_a_broken_version_5_member_is_refused_by_name(case):
    """The member refused by name; the bank's other members of its version or below decode."""
    make, status, message = V5_MEMBER_RULES[case]
    w, data = make()
    bank = rd.open_bank(data)
    check_member_refused(w, data, 0, status, message, others_decode=False)
    for i, c in enumerate(w.clips[1:], 1):
        if struct.unpack_from("<H", c["member"], 8)[0] <= bank["version"][0]:
            rd.decode_member(bank, i)
        else:  # a bank of version 4: every member of version 5 is refused
            check_member_refused(w, data, i, status, message, others_decode=False)


# ---- The command line

def run(*args):
    return subprocess.run([sys.executable, str(DECODER), *map(str, args)], capture_output=True, text=True)


def test_the_command_line_lists_a_bank_and_prints_a_clip(archive, tmp_path):
    w, data = archive
    path = tmp_path / "walk.kbank"
    path.write_bytes(data)
    r = run(path)
    assert r.returncode == 0, r.stderr
    index = json.loads(r.stdout)
    assert index["format_version"] == "4.1" and index["profile"] == "archive"
    assert [c["name"] for c in index["clips"]] == [n.decode() for n in ARCHIVE_CLIPS]
    for i, c in enumerate(index["clips"]):
        assert (c["offset"], c["size"], c["skeleton"]) == (w.at["members"][i], len(w.clips[i]["member"]), w.clips[i]["skeleton"])
        assert (c["frame_count"], c["frame_time"]) == (w.clips[i]["frame_count"], w.clips[i]["frame_time"])
    r = run(path, "long/clip")
    assert r.returncode == 0, r.stderr
    assert json.loads(r.stdout)["clip"] == "long/clip" and json.loads(r.stdout)["vector"] == "walk.kbank"
    assert json_less_names(r.stdout) == json_less_names((VECTORS / "v3_long.json").read_text())
    r = run(path, "long")
    assert r.returncode == 1 and "no clip named 'long'" in r.stderr


def test_the_command_line_reads_bank_colon_name_as_a_kanim(archive, tmp_path):
    """LIB.kbank:NAME (keyanim's form) prints the values at positions, as FILE.kanim does."""
    w, data = archive
    path = tmp_path / "a:b.kbank"  # a ':' in the bank's own path too
    path.write_bytes(data)
    r, want = run(f"{path}:walk/rules", 0, 2.5, 19), run(VECTORS / "v3_rules.kanim", 0, 2.5, 19)
    assert r.returncode == 0 and want.returncode == 0, r.stderr
    assert r.stdout == want.stdout and len(r.stdout.splitlines()) == 3
    r = run(f"{path}:walk")
    assert r.returncode == 1 and "no clip named 'walk'" in r.stderr


def test_the_command_line_names_a_damaged_clip(archive, tmp_path):
    w, data = archive
    b = bytearray(data)
    b[w.at["members"][4] - 5] ^= 1  # the last byte of "single"'s sections
    path = tmp_path / "walk.kbank"
    path.write_bytes(bytes(b))
    r = run(path, "single")
    assert r.returncode == 1 and "checksum_mismatch" in r.stderr and "'single'" in r.stderr and str(path) in r.stderr
    assert run(path, "uniform").returncode == 0
    assert run(path).returncode == 0  # the index does not read members


# ---- Breaking one rule of section 10 at a time: the bank refused when opened

def patch(fmt, at_of, value, refix=True):
    """A change to the archive bank: struct `fmt` at at_of(writer) set to value(writer, old)."""
    def make(w, data):
        b = bytearray(data)
        at = at_of(w)
        old = struct.unpack_from("<" + fmt, b, at)[0]
        struct.pack_into("<" + fmt, b, at, value(w, old) if callable(value) else value)
        return w.refix(bytes(b)) if refix else bytes(b)
    return make


def rebuilt(change_writer=None, **build_args):
    """The archive bank built again with some writer inputs or build() fields changed."""
    def make(w, data):
        w2 = make_bank(ARCHIVE_CLIPS)
        if change_writer:
            change_writer(w2)
        out = w2.build(**build_args)
        w.at = w2.at
        return out
    return make


def renamed(i, name):
    def change(w):
        w.clips[i]["name"] = name
    return change


def clip_field(i, offset):
    return lambda w: w.entry(i) + offset


OPEN_RULES = {
    # 10.2: the header
    "a bad signature": (lambda w, d: b"\x89KAM" + d[4:], "bad_signature", "signature"),
    "the header cut": (lambda w, d: d[:39], "truncated", "bank header"),
    "Major_Version 6": (patch("H", lambda w: 8, 6), "unsupported_version", "major 6"),
    "a reserved Header_Flags bit": (patch("I", lambda w: 12, BANK | 8), "reserved_bits_set", "Header_Flags bits 3-15"),
    "Member set in a bank": (patch("I", lambda w: 12, BANK | MEMBER), "corrupt", "Member bit is set"),
    "Runtime with a dictionary": (rebuilt(flags=BANK | RUNTIME, dictionary_size=8), "corrupt", "Dictionary_Size with Runtime"),
    # 10.1: sizes that fit, offsets equal to the computed ones, padding, the file's end
    "2^32-1 clips": (patch("I", lambda w: 16, 2 ** 32 - 1), "truncated", "4294967295 clips"),
    "2^32-1 skeletons": (patch("I", lambda w: 20, 2 ** 32 - 1), "truncated", "4294967295 skeletons"),
    "Names_Size 2^64-1": (patch("Q", lambda w: 24, 2 ** 64 - 1), "truncated", "Names_Size 18446744073709551615"),
    "Dictionary_Size past the end": (patch("Q", lambda w: 32, 2 ** 40), "corrupt", "skeleton table entry 0: Offset"),
    "a skeleton Offset 8 later": (patch("Q", lambda w: 40, lambda w, old: old + 8), "corrupt", "skeleton table entry 0: Offset"),
    "a skeleton of Stored_Size 0": (rebuilt(lambda w: w.skeletons.__setitem__(1, {"raw": b"", "stored": b"", "flags": 0})),
                                    "corrupt", "skeleton table entry 1: Stored_Size 0"),
    "a clip Offset outside the file": (patch("Q", clip_field(2, 0), lambda w, old: old + 2 ** 20), "corrupt",
                                       "clip table entry 2: Offset"),
    "two clips overlapping": (patch("Q", clip_field(3, 0), lambda w, old: w.at["members"][2]), "corrupt",
                              "clip table entry 3: Offset"),
    "a member Size 8 more": (patch("Q", clip_field(7, 8), lambda w, old: old + 8), "truncated", "the last part ends"),
    "a member Size 1 less": (patch("Q", clip_field(7, 8), lambda w, old: old - 1), "trailing_bytes", "1 bytes after"),
    "a byte more": (lambda w, d: d + b"\0", "trailing_bytes", "1 bytes after the last part"),
    "a byte less": (lambda w, d: d[:-1], "truncated", "the last part ends"),
    "padding before the dictionary": (patch("B", lambda w: w.at["dictionary"] - 1, 1), "corrupt", "padding bytes"),
    "padding before the checksum": (patch("B", lambda w: w.at["checksum"] - 1, 1), "corrupt", "padding bytes"),
    # 10.3: the skeleton table (skeleton 0 is v3_rules' SKEL, zstd; 1 v3_uniform's, uncompressed)
    "Skeleton_Flags bit 1": (patch("I", lambda w: w.skeleton_entry(0) + 24, lambda w, old: old | 2), "reserved_bits_set",
                             "Skeleton_Flags bits 1-15"),
    "Skeleton_Reserved": (patch("I", lambda w: w.skeleton_entry(1) + 28, 1), "reserved_bits_set", "Skeleton_Reserved"),
    "Raw_Size 0": (patch("Q", lambda w: w.skeleton_entry(0) + 16, 0), "corrupt", "skeleton table entry 0: Raw_Size 0"),
    "an uncompressed skeleton's Raw_Size": (patch("Q", lambda w: w.skeleton_entry(1) + 16, lambda w, old: old + 1), "corrupt",
                                            "not Compressed, Raw_Size"),
    "Raw_Size past 32768 x Stored_Size": (patch("Q", lambda w: w.skeleton_entry(0) + 16,
                                                lambda w, old: 32768 * len(w.skeletons[0]["stored"]) + 1),
                                          "zstd_error", "> 32768 x Stored_Size"),
    "a frame declaring another Raw_Size": (patch("Q", lambda w: w.skeleton_entry(0) + 16, lambda w, old: old + 1),
                                           "zstd_error", "skeleton 0 (bytes"),
    "Compressed on bytes that are no zstd frame": (patch("I", lambda w: w.skeleton_entry(1) + 24, 1), "zstd_error",
                                                   "skeleton 1 (bytes"),
    # 10.3: the clip table
    "Skeleton = Skeleton_Count": (patch("I", clip_field(0, 28), lambda w, old: len(w.skeletons)), "corrupt",
                                  "Skeleton 6 >= Skeleton_Count 6"),
    "Name_Size 0": (rebuilt(renamed(1, b"")), "corrupt", "Name_Size 0"),
    "Name_Size 1025": (rebuilt(renamed(1, b"x" * 1025)), "corrupt", "Name_Size 1025"),
    "a name past Names_Size": (patch("I", clip_field(7, 32), lambda w, old: old + 2), "corrupt", "ends past Names_Size"),
    # 10.3: names and their order
    "a name '..'": (rebuilt(renamed(1, b"..")), "corrupt", "a part '..'"),
    "a part '..'": (rebuilt(renamed(1, b"walk/../../etc")), "corrupt", "a part '..'"),
    "a part '.'": (rebuilt(renamed(1, b"./uniform")), "corrupt", "a part '.'"),
    "an empty part": (rebuilt(renamed(1, b"walk//uniform")), "corrupt", "a part ''"),
    "a leading /": (rebuilt(renamed(1, b"/uniform")), "corrupt", "a part ''"),
    "a trailing /": (rebuilt(renamed(1, b"uniform/")), "corrupt", "a part ''"),
    "a byte 0": (rebuilt(renamed(1, b"uni\0form")), "corrupt", "a byte 0"),
    "two clips of one name": (rebuilt(renamed(1, b"walk/rules")), "corrupt", "share the name b'walk/rules'"),
    "the name order out of order": (rebuilt(order=list(range(8))), "corrupt", "are out of order"),
    "a clip twice in the name order": (rebuilt(order=[5, 3, 1, 1, 0, 2, 6, 4]), "corrupt", "name order entry 3: clip 1 listed twice"),
    "a clip index out of range": (rebuilt(order=[5, 3, 1, 8, 0, 2, 6, 4]), "corrupt", "name order entry 3: clip 8 out of range"),
    # 10.4: the checksum
    "a damaged name": (lambda w, d: d[:w.at["names"]] + b"W" + d[w.at["names"] + 1:], "checksum_mismatch", "Bank_Checksum"),
    "a damaged skeleton": (patch("B", lambda w: w.at["skeletons"][2] + 4, lambda w, old: old ^ 1, refix=False),
                           "checksum_mismatch", "Bank_Checksum"),
    "a damaged Bank_Checksum": (patch("B", lambda w: w.at["checksum"], lambda w, old: old ^ 0x80, refix=False),
                                "checksum_mismatch", "Bank_Checksum"),
}


@pytest.mark.parametrize("case", list(OPEN_RULES))
def test_a_broken_bank_rule_is_refused_when_the_bank_opens(case, archive):
    w0, data = archive
    w = make_bank(ARCHIVE_CLIPS)
    assert w.build() == data  # the writer is deterministic: `at` below is this bank's
    make, status, message = OPEN_RULES[case]
    broken = make(w, data)
    assert broken != data
    with pytest.raises(rd.KanimError) as e:
        rd.open_bank(broken)
    assert e.value.status == status, str(e.value)
    assert message in str(e.value), str(e.value)
    assert e.value.clip is None and e.value.offset is not None


def test_padding_before_a_member_refuses_that_member_only(archive):
    """10.1, 10.5: the padding before a member is checked when the member is opened."""
    w = make_bank(ARCHIVE_CLIPS)
    data = w.build()
    ends = [at + len(c["member"]) for at, c in zip(w.at["members"], w.clips)]
    i = next(i for i in range(1, len(ends)) if w.at["members"][i] > ends[i - 1])
    b = bytearray(data)
    b[w.at["members"][i] - 1] = 1
    check_member_refused(w, bytes(b), i, "corrupt", "the padding before its member")


def test_a_skeleton_made_with_the_dictionary_is_refused(dictionary_bank):
    """10.3: a compressed skeleton is a frame made without the bank's dictionary."""
    w0, _ = dictionary_bank
    w = BankWriter(dictionary=w0.dictionary)
    w.clips, w.skeletons = w0.clips, [dict(x) for x in w0.skeletons]
    w.skeletons[0].update(stored=zstd(["-19", "-D", w.dict_path()], w.skeletons[0]["raw"]), flags=1)
    with pytest.raises(rd.KanimError) as e:
        rd.open_bank(w.build())
    assert e.value.status == "zstd_error" and "skeleton 0" in str(e.value), str(e.value)


def test_the_skeletons_raw_size_sum_is_held_to_the_limit_before_inflating():
    """10.3: the sum of Raw_Size against the decoder's limit of decompressed bytes (1 GiB here,
    keyanim's), each within 32768 x Stored_Size; refused without inflating (peak memory)."""
    w = BankWriter()
    w.skeletons = [{"raw": b"", "raw_size": 32768 * 33000, "stored": bytes(33000), "flags": 1}]
    data = w.build()
    tracemalloc.start()
    try:
        with pytest.raises(rd.KanimError) as e:
            rd.open_bank(data)
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert e.value.status == "limit_exceeded" and "Raw_Size sum 1081344000" in str(e.value), str(e.value)
    assert peak < 64 * 1024, peak


def test_a_bad_dictionary_magic_is_refused(dictionary_bank):
    w, data = dictionary_bank
    b = bytearray(data)
    b[w.at["dictionary"]] ^= 1
    with pytest.raises(rd.KanimError) as e:
        rd.open_bank(w.refix(bytes(b)))
    assert e.value.status == "corrupt" and "37 A4 30 EC" in str(e.value) and e.value.offset == w.at["dictionary"]


@pytest.mark.parametrize("field,at,value", [("Clip_Count", 16, "<I"), ("Skeleton_Count", 20, "<I"),
                                            ("Names_Size", 24, "<Q")])
def test_huge_declared_counts_are_refused_before_anything_is_allocated(field, at, value):
    """10.1: a bank of N bytes declares fewer than N / 44 clips; the tables and names must fit
    before anything they size is allocated. Peak memory of the refusal, not time."""
    w = BankWriter()
    w.add(b"single", vector("v3_single.kanim"))
    b = bytearray(w.build())
    struct.pack_into(value, b, at, 2 ** (8 * struct.calcsize(value)) - 1)
    data = bytes(b)
    tracemalloc.start()
    try:
        with pytest.raises(rd.KanimError) as e:
            rd.open_bank(data)
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert e.value.status == "truncated", str(e.value)
    assert peak < 64 * 1024, peak


def test_a_bank_is_not_read_as_a_clip_file(archive):
    """A 4.1 single-file decoder refuses a bank (rather than reading Clip_Count as a
    Section_Count), and a 4.0 decoder would see a reserved bit (10.2)."""
    with pytest.raises(rd.KanimError) as e:
        rd.parse(archive[1])
    assert e.value.status == "corrupt" and "Bank set" in str(e.value)
    assert rd.is_bank(archive[1]) and not rd.is_bank(vector("v4_rules.kanim"))
    assert rd.is_bank(vector("b50_archive.kbank")) and not rd.is_bank(vector("v5_quat_runtime.kanim"))


def test_a_member_by_itself_is_refused(archive):
    """10.5.1: a file read by itself with Member set is corrupt."""
    w, data = archive
    member = w.clips[1]["member"]
    with pytest.raises(rd.KanimError) as e:
        rd.parse(member)
    assert e.value.status == "corrupt" and "Member set in a file read by itself" in str(e.value)


# ---- Breaking one rule of 10.5: the member refused by name, the others still decode

def member_change(i, make_member=None, table=None, bank_flags=None):
    """The archive bank with clip i's member remade by make_member(writer clip), or its clip
    table entry changed by table(entry bytes)."""
    def make():
        w = make_bank(ARCHIVE_CLIPS)
        if make_member:
            c = w.clips[i]
            c["member"] = make_member(c)
        data = w.build()
        if table:
            b = bytearray(data)
            table(b, w.entry(i), w)
            data = w.refix(bytes(b))
        return w, data
    return make


def remember(src, **member_args):
    return lambda c: as_member(source(src), **member_args)[0]


def set_table(fmt, offset, value):
    def change(b, entry, w):
        struct.pack_into("<" + fmt, b, entry + offset, value(struct.unpack_from("<" + fmt, b, entry + offset)[0]))
    return change


def member_bytes(change):
    """A member with its bytes changed by change(bytearray), its own checksum not refixed."""
    def make(c):
        b = bytearray(c["member"])
        change(b)
        return bytes(b)
    return make


def member_without_member_bit(c):
    b = bytearray(c["member"])
    struct.pack_into("<I", b, 12, struct.unpack_from("<I", b, 12)[0] & ~MEMBER)
    return with_checksum(bytes(b[:-4]), False)


def member_header(major=None, flags_or=0):
    """A member with Major_Version or Header_Flags changed, its CRC-32 recomputed."""
    def make(c):
        b = bytearray(c["member"])
        if major is not None:
            struct.pack_into("<H", b, 8, major)
        struct.pack_into("<I", b, 12, struct.unpack_from("<I", b, 12)[0] | flags_or)
        return with_checksum(bytes(b[:-4]), False)
    return make


def runtime_member_in_archive_bank(c):
    return as_member(vector("v4_uniform.kanim"))[0]


MEMBER_RULES = {
    # (clip index, how, status, message)
    "Member clear": (1, member_change(1, member_without_member_bit), "corrupt", "without the Member bit"),
    "Runtime unlike the bank's": (1, member_change(1, runtime_member_in_archive_bank), "corrupt", "Runtime differs"),
    "Bank set in a member": (1, member_change(1, member_header(flags_or=BANK)), "corrupt", "Header_Flags has Bank set"),
    "a member of version 3": (1, member_change(1, member_header(major=3)), "reserved_bits_set", "Header_Flags"),
    "a SKEL in the member": (1, member_change(1, remember("v3_uniform.kanim", keep_skel=True)), "corrupt",
                             "a SKEL section in a bank's member"),
    "a damaged member": (3, member_change(3, member_bytes(lambda b: b.__setitem__(-6, b[-6] ^ 4))),
                         "checksum_mismatch", "crc"),
    "a member cut short": (7, member_change(7, member_bytes(lambda b: b.__delitem__(slice(-9, None)))), "truncated", ""),
    "Frame_Count against CLIP": (4, member_change(4, table=set_table("I", 24, lambda v: v + 1)), "corrupt",
                                 "Frame_Count 241 is not CLIP's 240"),
    "Frame_Time -0.0 against CLIP's +0.0": (3, member_change(3, table=set_table("d", 16, lambda v: -0.0)), "corrupt",
                                            "Frame_Time -0.0 is not CLIP's 0.0, bit for bit"),
    "the skeleton of another clip": (1, member_change(1, table=set_table("I", 28, lambda v: 0)), "corrupt", "SKEL"),
}


def check_member_refused(w, data, i, status, message, others_decode=True):
    bank = rd.open_bank(data)  # the index does not read members: the bank opens
    with pytest.raises(rd.KanimError) as e:
        rd.decode_member(bank, i)
    name = w.clips[i]["name"]
    assert e.value.status == status, str(e.value)
    assert message in str(e.value), str(e.value)
    assert e.value.clip == (i, name) and f"clip {i} {name.decode()!r}" in str(e.value)
    entry = (w.entry(i), w.entry(i) + 40)
    member = (w.at["members"][i] - 7, w.at["members"][i] + len(w.clips[i]["member"]))
    # (the member's padding before it; truncated: the place is the end of the member)
    assert entry[0] <= e.value.offset < entry[1] or member[0] <= e.value.offset <= member[1], e.value.offset
    for j in range(len(w.clips) if others_decode else 0):  # the other clips still decode
        if j != i:
            rd.decode_member(bank, j)


@pytest.mark.parametrize("case", list(MEMBER_RULES))
def test_a_broken_member_is_refused_by_name_and_the_others_decode(case):
    i, make, status, message = MEMBER_RULES[case]
    w, data = make()
    check_member_refused(w, data, i, status, message)


def test_a_member_whose_frames_need_a_dictionary_the_bank_lacks(tmp_path):
    w = make_bank({k: v for k, v in ARCHIVE_CLIPS.items() if k != b"blocks"})
    other = BankWriter(dictionary=trained_dictionary(2048))
    w.clips[4]["member"] = as_member(vector("v3_long.kanim"), dictionary=other.dict_path())[0]
    check_member_refused(w, w.build(), 4, "zstd_error", "zstd")


def test_a_member_decoded_with_another_dictionary(dictionary_bank):
    """The bank's dictionary replaced by another (magic and size kept): the frames name the
    first one's ID, and zstd refuses them (10.4)."""
    w, _ = dictionary_bank
    other = trained_dictionary(4096)
    other = other[:4] + struct.pack("<I", struct.unpack_from("<I", other, 4)[0] ^ 1) + other[8:]
    w2 = BankWriter(dictionary=other)
    w2.clips, w2.skeletons = w.clips, w.skeletons
    check_member_refused(w2, w2.build(), 0, "zstd_error", "Dictionary mismatch", others_decode=False)


def test_a_runtime_member_with_a_skel_is_refused():
    w = make_bank(RUNTIME_CLIPS, runtime=True)
    w.clips[0]["member"] = as_member(vector("v4_rules.kanim"), keep_skel=True)[0]
    check_member_refused(w, w.build(), 0, "corrupt", "a SKEL section in a bank's member")


def test_a_damaged_runtime_member_is_refused_by_its_xxh64():
    w = make_bank(RUNTIME_CLIPS, runtime=True)
    b = bytearray(w.clips[3]["member"])
    b[200] ^= 1  # inside IMAG
    w.clips[3]["member"] = bytes(b)
    check_member_refused(w, w.build(), 3, "checksum_mismatch", "XXH64")


if __name__ == "__main__":
    sys.exit(pytest.main([__file__, "-q"]))


# ---- The same banks through keyanim (C++, written apart from this decoder), where KEYANIM_CLI
# names the tool: it must read the writer's banks to the same clips, and refuse each broken
# bank or member with the same status.

def tool():
    path = os.environ.get("KEYANIM_CLI")
    if not path or not os.path.exists(path):
        pytest.skip("the keyanim tool is not built (KEYANIM_CLI)")
    return path


def tool_status(args):
    """(exit code, status name in keyanim's error line, stderr)."""
    r = subprocess.run([tool(), *map(str, args)], capture_output=True, text=True, errors="surrogateescape")
    found = [s for s in ["bad_signature", "truncated", "unsupported_version", "reserved_bits_set", "corrupt",
                         "checksum_mismatch", "trailing_bytes", "limit_exceeded", "zstd_error"] if f": {s}: " in r.stderr]
    if "(bad signature)" in r.stderr:  # keyanim words this one status as a sentence
        found.append("bad_signature")
    return r.returncode, found, r.stderr


@pytest.mark.parametrize("kind", ["archive", "runtime", "dictionary"])
def test_keyanim_unpacks_the_writers_banks_to_the_standalone_clips(kind, archive, runtime, dictionary_bank, tmp_path):
    (w, data), clips = {"archive": (archive, ARCHIVE_CLIPS), "runtime": (runtime, RUNTIME_CLIPS),
                        "dictionary": (dictionary_bank, {k: v for k, v in ARCHIVE_CLIPS.items() if k != b"blocks"})}[kind]
    bank = tmp_path / "b.kbank"
    bank.write_bytes(data)
    code, _, err = tool_status(["-q", "unpack", bank, "-o", tmp_path / "out"])
    assert code == 0, err
    for name, (src, _) in clips.items():
        compare_with_standalone(rd.parse((tmp_path / "out" / (name.decode() + ".kanim")).read_bytes()), src)


# Files that break two rules, which section 7 lets a decoder report with either status.
EITHER = {"Dictionary_Size past the end": {"corrupt", "truncated"}}  # offsets, and the file's end


@pytest.mark.parametrize("case", list(OPEN_RULES))
def test_keyanim_refuses_the_broken_bank_too(case, archive, tmp_path):
    w = make_bank(ARCHIVE_CLIPS)
    data = w.build()
    make, status, _ = OPEN_RULES[case]
    path = tmp_path / "b.kbank"
    path.write_bytes(make(w, data))
    code, found, err = tool_status(["list", path])
    assert code != 0 and set(found) & EITHER.get(case, {status}), err


@pytest.mark.parametrize("case", list(MEMBER_RULES))
def test_keyanim_refuses_the_broken_member_too(case, tmp_path):
    i, make, status, _ = MEMBER_RULES[case]
    w, data = make()
    path = tmp_path / "b.kbank"
    path.write_bytes(data)
    name = w.clips[i]["name"].decode()
    code, found, err = tool_status(["convert", f"{path}:{name}", "--archive", "-o", tmp_path / "out.kanim"])
    assert code != 0 and status in found and name in err, err
    assert not (tmp_path / "out.kanim").exists()
    other = w.clips[(i + 1) % len(w.clips)]["name"].decode()  # another clip of the bank still converts
    code, _, err = tool_status(["-q", "convert", f"{path}:{other}", "--archive", "-o", tmp_path / "other.kanim"])
    assert code == 0, err


# ---- The b41_* vectors (keyanim pack, Appendix C): each clip, named after its vector, decodes
# to that vector's expected values; b41_damaged's v3_uniform fails alone.

@pytest.mark.parametrize("name", ["b41_archive", "b41_dictionary", "b41_runtime", "b41_damaged"])
def test_the_b41_vectors_decode_to_their_clips_vectors(name):
    bank = rd.open_bank(vector(f"{name}.kbank"))
    assert len(bank["clips"]) == (6 if name == "b41_runtime" else 7)
    assert (bank["dictionary"] is not None) == (name == "b41_dictionary")
    assert bank["runtime"] == (name == "b41_runtime")
    for c in bank["clips"]:
        clip_name = c["name"].decode()
        assert rd.find_clip(bank, c["name"]) == c["index"]
        if name == "b41_damaged" and clip_name == "v3_uniform":
            with pytest.raises(rd.KanimError) as e:
                rd.decode_member(bank, c["index"])
            assert e.value.status == "checksum_mismatch" and e.value.clip == (c["index"], c["name"])
            continue
        clip = rd.decode_member(bank, c["index"])
        text = rd.json_text(rd.expected_values(clip, f"{name}.kbank", clip_name))
        assert json_less_names(text) == json_less_names((VECTORS / f"{clip_name}.json").read_text()), clip_name


# ---- The b50_* vectors (keyanim pack, make_b50.sh): banks of version 5.0 whose members of
# version 5 (v5_quat, v5_blocks) sit beside members of version 4 (v3_rules, v3_long); each clip
# decodes to its vector's expected values, in both profiles.

@pytest.mark.parametrize("name", ["b50_archive", "b50_runtime"])
def test_the_b50_vectors_decode_to_their_clips_vectors(name):
    bank = rd.open_bank(vector(f"{name}.kbank"))
    assert bank["version"] == (5, 0) and bank["runtime"] == (name == "b50_runtime") and bank["dictionary"] is None
    assert [c["name"] for c in bank["clips"]] == [b"v5_quat", b"v5_blocks", b"v3_rules", b"v3_long"]
    versions = []
    for c in bank["clips"]:
        clip_name = c["name"].decode()
        assert rd.find_clip(bank, c["name"]) == c["index"]
        clip = rd.decode_member(bank, c["index"])
        versions.append(clip["version"][0])
        text = rd.json_text(rd.expected_values(clip, f"{name}.kbank", clip_name))
        assert json_less_names(text) == json_less_names((VECTORS / f"{clip_name}.json").read_text()), clip_name
    assert versions == [5, 5, 4, 4]


def test_the_b50_vectors_are_what_keyanim_pack_writes():
    """make_b50.sh with the tool: it checks the vectors that exist hold the bytes it makes."""
    r = subprocess.run(["bash", str(VECTORS / "make_b50.sh"), tool()], capture_output=True, text=True)
    assert r.returncode == 0 and "wrote" not in r.stdout, r.stdout + r.stderr


def test_the_command_line_lists_a_version_5_bank():
    r = run(VECTORS / "b50_runtime.kbank")
    assert r.returncode == 0, r.stderr
    index = json.loads(r.stdout)
    assert index["format_version"] == "5.0" and index["profile"] == "runtime" and len(index["clips"]) == 4
    r = run(VECTORS / "b50_archive.kbank", "v5_quat")
    assert r.returncode == 0, r.stderr
    assert json_less_names(r.stdout) == json_less_names((VECTORS / "v5_quat.json").read_text())


@pytest.mark.parametrize("case", list(V5_MEMBER_RULES))
def test_keyanim_refuses_the_broken_version_5_member_too(case, tmp_path):
    make, status, _ = V5_MEMBER_RULES[case]
    w, data = make()
    path = tmp_path / "b.kbank"
    path.write_bytes(data)
    name = w.clips[0]["name"].decode()
    code, found, err = tool_status(["convert", f"{path}:{name}", "--archive", "-o", tmp_path / "out.kanim"])
    assert code != 0 and status in found and name in err, err
    assert not (tmp_path / "out.kanim").exists()
    other = w.clips[1]["name"].decode()  # a member of version 4: it converts
    code, _, err = tool_status(["-q", "convert", f"{path}:{other}", "--archive", "-o", tmp_path / "other.kanim"])
    assert code == 0, err


@pytest.mark.parametrize("runtime", [False, True])
def test_keyanim_unpacks_a_version_5_bank_to_the_standalone_clips(runtime, tmp_path):
    clips = RUNTIME_CLIPS_V5 if runtime else ARCHIVE_CLIPS_V5
    bank = tmp_path / "b.kbank"
    bank.write_bytes(make_bank(clips, runtime=runtime).build())
    code, _, err = tool_status(["-q", "unpack", bank, "-o", tmp_path / "out"])
    assert code == 0, err
    for name, (src, _) in clips.items():
        compare_with_standalone(rd.parse((tmp_path / "out" / (name.decode() + ".kanim")).read_bytes()), src)
