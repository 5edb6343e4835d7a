"""spec/test-vectors/reference_decoder.py on the runtime profile (spec section 9), the v4 vectors
and version 5 (quaternion nodes, 4.7): its XXH64 against xxHash's check values, the v4 JSON
against the v3 JSON of the same clip and the v5 runtime JSON against the v5 archive JSON, and one
rejection per rule of 9.1-9.4 and of version 5 (4.3, 4.4, 4.7, 8, 9.2), each made by breaking
that rule alone in a vector (the checksum fixed again, so that the rule and not the checksum
refuses it). runtime_writer.py, a writer of the runtime profile from the spec's text, makes the
runtime files no vector holds, and is checked to make the runtime vectors byte for byte.

Where KEYANIM_CLI names the keyanim tool, every broken file is also given to
`keyanim convert --archive`, which checks structure and content (C++, written apart from the
reference decoder), and must refuse it with the same status.

Needs no keyanim module: CTest runs this file on its own (tests/CMakeLists.txt,
reference_decoder), so python/CMakeLists.txt leaves it out of the module's run.
"""

import importlib.util
import json
import os
import struct
import subprocess
import sys
import zlib
from pathlib import Path

import pytest

REPO = Path(os.environ.get("KEYANIM_REPO_DIR", Path(__file__).resolve().parent.parent.parent))
VECTORS = REPO / "spec" / "test-vectors"
NAMES = ["rules", "uniform", "single", "long", "predict", "blocks"]


def load_module(name, directory=VECTORS):
    spec = importlib.util.spec_from_file_location(name, directory / f"{name}.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


rd = load_module("reference_decoder")
writer = load_module("runtime_writer", Path(__file__).resolve().parent)


def vector(name):
    return (VECTORS / name).read_bytes()


# ---- XXH64

def test_xxh64_check_values_of_the_spec():
    assert rd.xxh64_pure(b"") == 0xEF46DB3751D8E999
    assert rd.xxh64_pure(b"123456789") == 0x8CB841DB40E6AE83
    assert rd.xxh64(b"") == 0xEF46DB3751D8E999
    assert rd.xxh64(b"123456789") == 0x8CB841DB40E6AE83


def test_xxh64_pure_equals_the_xxhash_module():
    xxhash = pytest.importorskip("xxhash")  # python3-xxhash; the check values above hold without it
    data = bytes((i * 131 + 7) % 256 for i in range(300))
    for n in list(range(0, 80)) + [255, 256, 300]:  # every tail: 8-, 4- and 1-byte steps, stripes
        assert rd.xxh64_pure(data[:n]) == xxhash.xxh64(data[:n]).intdigest(), n
    for name in NAMES:
        body = vector(f"v4_{name}.kanim")[:-8]
        assert rd.xxh64_pure(body) == xxhash.xxh64(body).intdigest(), name


# ---- The v4 vectors and their JSON

def json_without_name(path):
    """The JSON text of a vector's expected values, less the fields that name its file and
    version: what two files of the same clip share, compared as text (so -0.0 is not 0.0)."""
    d = json.loads(path.read_text())
    assert d.pop("vector") == path.with_suffix(".kanim").name
    version = d.pop("format_version")
    return version, json.dumps(d)


@pytest.mark.parametrize("v4,v3", [(f"v4_{n}", f"v3_{n}") for n in NAMES] + [("v4_archive", "v3_rules")])
def test_v4_json_equals_v3_json(v4, v3):
    version4, text4 = json_without_name(VECTORS / f"{v4}.json")
    version3, text3 = json_without_name(VECTORS / f"{v3}.json")
    assert (version4, version3) == ("4.0", "3.0")
    assert text4 == text3
    assert len(json.loads(text4)["samples"]) >= 9


@pytest.mark.parametrize("v4,v3", [(f"v4_{n}", f"v3_{n}") for n in NAMES] + [("v4_archive", "v3_rules")])
def test_v4_keys_equal_v3_keys(v4, v3):
    """The keys recovered from IMAG (9.3) are the archive file's, value bits included."""
    a, b = rd.parse(vector(f"{v4}.kanim")), rd.parse(vector(f"{v3}.kanim"))
    assert a["version"] == (4, 0) and b["version"] == (3, 0)
    bits = lambda vs: [[rd.f32_bits(v) for v in c] for c in vs]
    for key in ["frame_count", "frame_time", "tangent_rule", "nodes", "interp", "frames", "notes"]:
        assert a[key] == b[key], key
    assert [rd.f32_bits(t) for t in a["tension"]] == [rd.f32_bits(t) for t in b["tension"]]
    assert bits(a["values"]) == bits(b["values"])


@pytest.mark.parametrize("v4", [f"v4_{n}" for n in NAMES] + ["v4_archive"])
def test_v4_json_is_what_the_reference_decoder_writes(v4, tmp_path):
    (tmp_path / f"{v4}.kanim").write_bytes(vector(f"{v4}.kanim"))
    out, what = rd.write_json(str(tmp_path / f"{v4}.kanim"))
    assert what == "wrote" and Path(out).read_bytes() == (VECTORS / f"{v4}.json").read_bytes()


def test_v4_archive_is_v3_rules_with_major_version_4():
    made = load_module("make_v4_archive").v4_archive_bytes(vector("v3_rules.kanim"))
    assert made == vector("v4_archive.kanim")
    assert struct.unpack_from("<HHI", made, 8) == (4, 0, 0)  # Runtime clear
    assert zlib.crc32(made[:-4]) == struct.unpack_from("<I", made, len(made) - 4)[0]


def test_the_vectors_cover_the_image():
    """What the rejections below and Appendix C rely on: block and list curves, fixed
    channels, records without keys, the widest values, a NOTE."""
    def image(name):
        return image_of(vector(f"v4_{name}.kanim"))
    _, rules = image("rules")
    assert rules["header"]["nb"] == 10 and rules["header"]["B"] == 1
    _, predict = image("predict")
    assert predict["header"]["nl"] == 5 and predict["header"]["nb"] == 0
    content, blocks = image("blocks")
    records = [r for rs in blocks["records"].values() for r in rs]
    assert blocks["header"]["nb"] > 0 and blocks["header"]["nl"] > 0
    assert any(not r["frames"] for r in records) and max(r["Value_Bits"] for r in records) == 55
    content, single = image("single")
    assert "NOTE" in content and single["header"]["nc"] == 0


def image_of(data):
    """(sections, parsed IMAG) of a valid runtime-profile file."""
    major = struct.unpack_from("<H", data, 8)[0]
    content = rd.runtime_sections(data, struct.unpack_from("<I", data, 16)[0], major)
    F, N, C, rule, frame_time, K = rd.parse_clip(content["CLIP"])
    nodes = rd.parse_skel(content["SKEL"], N, C)
    return content, rd.parse_image(content["IMAG"], F, C, K, major, nodes if major >= 5 else None)


# ---- Breaking one rule at a time

class Runtime:
    """A runtime-profile file to break: where its sections, IMAG's arrays and records are."""

    def __init__(self, data):
        self.b = bytearray(data)
        self.major = struct.unpack_from("<H", self.b, 8)[0]
        self.count = struct.unpack_from("<I", self.b, 16)[0]
        self.entries = [struct.unpack_from("<4sIQQ", self.b, 24 + 24 * i) for i in range(self.count)]
        self.at, pos = {}, 24 + 24 * self.count
        for tag, _, stored, _ in self.entries:
            self.at[tag.decode()] = pos
            pos += stored
        clip = self.at["CLIP"]
        self.F, self.N, self.C = struct.unpack_from("<III", self.b, clip)
        imag = self.at["IMAG"]
        self.h = rd.image_header(bytes(self.b[imag:imag + 32]), self.F, self.C, self.N, self.major)
        self.tracks = image_of(data)[1]["tracks"]  # each block track's curves (9.2)
        self.array, pos = {}, imag + 32
        for name, fmt, n in rd.image_array_specs(self.h):
            self.array[name] = pos
            pos += rd.pad8(struct.calcsize("<" + fmt) * n if fmt else n)

    def get(self, fmt, at):
        return struct.unpack_from("<" + fmt, self.b, at)[0]

    def put(self, fmt, at, value):
        struct.pack_into("<" + fmt, self.b, at, value)

    def entry(self, name, i, size):
        return self.array[name] + size * i

    def record(self, idx):
        """Byte offset in the file of record idx (block-major), and its fields' widths: of a
        track of one curve (w, wc) or three (ws, wcs; w, wc their sums), the bits before its
        Context (head)."""
        at = self.array["Payload"] + self.get("I", self.entry("Record_Offset", idx, 4))
        curves = self.tracks[idx % self.h["nt"]]
        wcs = [self.get("I", self.entry("Curves", i, 24) + 16) for i in curves]
        mask = self.get("Q", at)
        ws = list(self.b[at + 8:at + 8 + len(curves)])
        wk = self.b[at + 8 + len(curves)]
        return at, {"m": bin(mask).count("1"), "w": sum(ws), "wk": wk, "wc": sum(wcs), "ws": ws, "wcs": wcs,
                    "head": 72 + 8 * len(curves), "curves": curves}

    def record_field(self, idx, bit, width, value=None):
        """Reads (or writes) the bit field of record idx at `bit`, `width` bits wide (9.3)."""
        at, _ = self.record(idx)
        n = (bit + width + 7) // 8
        whole = int.from_bytes(self.b[at:at + n], "little")
        old = (whole >> bit) & ((1 << width) - 1)
        if value is not None:
            whole = whole & ~(((1 << width) - 1) << bit) | (value << bit)
            self.b[at:at + n] = whole.to_bytes(n, "little")
        return old

    def bytes(self, refix=True):
        if refix:
            struct.pack_into("<Q", self.b, len(self.b) - 8, rd.xxh64(bytes(self.b[:-8])))
        return bytes(self.b)


def rules():
    return Runtime(vector("v4_rules.kanim"))


def with_table(data, entries, bodies):
    """A runtime-profile file made of these table entries and section bodies, XXH64 fixed."""
    head = bytearray(data[:24])
    struct.pack_into("<I", head, 16, len(entries))
    table = b"".join(struct.pack("<4sIQQ", *e) for e in entries)
    body = bytes(head) + table + b"".join(bodies)
    return body + struct.pack("<Q", rd.xxh64(body))


def sections(data):
    r = Runtime(data)
    return r.entries, [data[r.at[t.decode()]:r.at[t.decode()] + s] for t, _, s, _ in r.entries]


def set_flags(data, entry, flags):
    entries, bodies = sections(data)
    tag, _, stored, raw = entries[entry]
    entries[entry] = (tag, flags, stored, raw)
    return with_table(data, entries, bodies)


def imag_not_at_entry_1():
    data = vector("v4_rules.kanim")
    entries, bodies = sections(data)
    return with_table(data, [entries[0], entries[2], entries[1]], [bodies[0], bodies[2], bodies[1]])


def append_section(tag, flags, name="v4_rules.kanim"):
    data = vector(name)
    entries, bodies = sections(data)
    return with_table(data, entries + [(tag, flags, 8, 8)], bodies + [b"\0" * 8])


def imag_grown_by_8():
    data = vector("v4_rules.kanim")
    entries, bodies = sections(data)
    tag, flags, stored, raw = entries[1]
    entries[1] = (tag, flags, stored + 8, raw + 8)
    return with_table(data, entries, [bodies[0], bodies[1] + b"\0" * 8, bodies[2]])


def mutate(make):
    """make(Runtime) -> None: the file after it, XXH64 fixed."""
    def build(name="v4_rules.kanim"):
        r = Runtime(vector(name))
        make(r)
        return r.bytes()
    return build


def header_flags(name, flags, refix_crc=False):
    b = bytearray(vector(name))
    struct.pack_into("<I", b, 12, flags)
    if refix_crc:
        struct.pack_into("<I", b, len(b) - 4, zlib.crc32(bytes(b[:-4])))
    else:
        struct.pack_into("<Q", b, len(b) - 8, rd.xxh64(bytes(b[:-8])))
    return bytes(b)


def first_channel(r, n):
    """The first channel with Key_Count n."""
    return next(c for c in range(r.C) if r.get("I", r.entry("Key_Count", c, 4)) == n)


def set_record_bits_after_fields(r, tracks_of=1):
    """Sets a bit after the last field of the first record (of a track of tracks_of curves)
    whose bits do not fill its bytes."""
    for idx in range(r.h["R"]):
        _, f = r.record(idx)
        nbits = f["head"] + 4 * f["wk"] + f["wc"] + (f["m"] + 4) * f["w"]
        if len(f["curves"]) == tracks_of and nbits % 8:
            r.record_field(idx, nbits, 1, 1)
            return
    raise AssertionError("every record of the vector fills its bytes")


def swap_context_0_into_1(r, idx=0):
    _, f = r.record(idx)
    r.record_field(idx, f["head"] + f["wk"], f["wk"], r.record_field(idx, f["head"], f["wk"]))  # e_1 = e_0


def popcount_against_key_count(r):
    c = r.get("I", r.entry("Curve_Channel", 0, 4))
    r.put("I", r.entry("Key_Count", c, 4), r.get("I", r.entry("Key_Count", c, 4)) + 1)
    r.put("Q", r.at["CLIP"] + 24, r.get("Q", r.at["CLIP"] + 24) + 1)  # CLIP's Key_Count with it


def next_f32(x):
    return struct.unpack("<f", struct.pack("<I", struct.unpack("<I", struct.pack("<f", x))[0] + 1))[0]


STRUCTURE = {
    # 9.1: the table and the checksum
    "IMAG compressed": (lambda: set_flags(vector("v4_rules.kanim"), 1, 1), "corrupt", "compressed"),
    "IMAG not at entry 1": (imag_not_at_entry_1, "corrupt", "table entry 1"),
    "CLIP ancillary": (lambda: set_flags(vector("v4_rules.kanim"), 0, 2), "corrupt", "table entry 0"),
    "NOTE critical": (lambda: set_flags(vector("v4_single.kanim"), 3, 0), "corrupt", "NOTE must be ancillary"),
    "NOTE twice": (lambda: append_section(b"NOTE", 2, "v4_single.kanim"), "corrupt", "appear once"),
    "no SKEL": (lambda: with_table(vector("v4_rules.kanim"), *[x[:2] for x in sections(vector("v4_rules.kanim"))]),
                "corrupt", "fewer than CLIP, IMAG, SKEL"),
    "a CHAN section": (lambda: append_section(b"CHAN", 0), "corrupt", "CHAN in a runtime-profile file"),
    "an ancillary KVAL section": (lambda: append_section(b"KVAL", 2), "corrupt", "KVAL in a runtime-profile file"),
    "an unknown critical section": (lambda: append_section(b"ZZZZ", 0), "reserved_bits_set", "unknown critical"),
    "a reserved section flag": (lambda: set_flags(vector("v4_rules.kanim"), 2, 4), "reserved_bits_set", "section flags"),
    "a damaged byte": (lambda: bytes([b ^ (i == 200) for i, b in enumerate(vector("v4_rules.kanim"))]),
                       "checksum_mismatch", "XXH64"),
    "a byte more": (lambda: vector("v4_rules.kanim") + b"\0", "trailing_bytes", "after checksum"),
    "a byte less": (lambda: vector("v4_rules.kanim")[:-1], "truncated", "sections"),
    # 4.1: bit 1 is Member (10.5.1: corrupt in a file read by itself), bit 2 Bank, bits 3-15 reserved
    "Header_Flags bit 1 (Member) by itself": (lambda: header_flags("v4_rules.kanim", 3), "corrupt",
                                              "Member set in a file read by itself"),
    "Header_Flags bit 3": (lambda: header_flags("v4_rules.kanim", 9), "reserved_bits_set", "Header_Flags"),
    "Member in a 3.0 file": (lambda: header_flags("v3_rules.kanim", 2, refix_crc=True), "reserved_bits_set", "Header_Flags"),
    "Runtime in a 3.0 file": (lambda: header_flags("v3_rules.kanim", 1, refix_crc=True), "reserved_bits_set", "header"),
    "IMAG longer than its arrays": (imag_grown_by_8, "corrupt", "Raw_Size against the arrays"),
    # 9.2: IMAG's header and tables
    "Block_Shift 7": (mutate(lambda r: r.put("I", r.at["IMAG"], 7)), "corrupt", "Block_Shift"),
    "Block_Count + 1": (mutate(lambda r: r.put("I", r.at["IMAG"] + 12, r.h["B"] + 1)), "corrupt", "Block_Count"),
    "Image_Reserved": (mutate(lambda r: r.put("I", r.at["IMAG"] + 28, 1)), "reserved_bits_set", "Image_Reserved"),
    "a Pad byte": (mutate(lambda r: r.put("B", r.array["Interpolation"] + r.C, 1)), "corrupt", "Interpolation's Pad"),
    "Interpolation 2": (mutate(lambda r: r.put("B", r.array["Interpolation"], 2)), "reserved_bits_set", "Interpolation[0]"),
    "Tension 1.5": (mutate(lambda r: r.put("f", r.array["Tension"], 1.5)), "corrupt", "Tension[0]"),
    "Key_Count sum": (mutate(lambda r: r.put("I", r.entry("Key_Count", first_channel(r, 0), 4), 1)),
                      "corrupt", "Key_Count sum"),
    "Curve_Of": (mutate(lambda r: r.put("I", r.entry("Curve_Of", first_channel(r, 0), 4), 0)), "corrupt", "Curve_Of"),
    "Fixed_Value of a channel without keys": (
        mutate(lambda r: r.put("f", r.entry("Fixed_Value", first_channel(r, 0), 4), -0.0)), "corrupt", "Fixed_Value"),
    "Fixed_Frame >= F": (mutate(lambda r: r.put("I", r.entry("Fixed_Frame", first_channel(r, 1), 4), r.F)),
                         "corrupt", "Fixed_Frame"),
    "Fixed_Channels": (mutate(lambda r: r.put("I", r.array["Fixed_Channels"], r.C)), "corrupt", "Fixed_Channels"),
    "Q_Base beyond 2^53": (mutate(lambda r: r.put("q", r.entry("Curves", 0, 24), 2 ** 53 + 1)), "corrupt", "Q_Base"),
    "Step 0": (mutate(lambda r: r.put("d", r.entry("Curves", 0, 24) + 8, 0.0)), "corrupt", "Step"),
    "Base_Bits 56": (mutate(lambda r: r.put("I", r.entry("Curves", 0, 24) + 16, 56)), "corrupt", "Base_Bits"),
    "Curve_Reserved": (mutate(lambda r: r.put("I", r.entry("Curves", 0, 24) + 20, 1)), "reserved_bits_set", "Curve_Reserved"),
    "Curve_S": (mutate(lambda r: r.put("I", r.array["Curve_S"], r.get("I", r.array["Curve_S"]) ^ 1)), "corrupt", "Curve_S[0]"),
    "a padding lane": (mutate(lambda r: r.put("f", r.entry("Last_Frame", r.h["L"] - 1, 4), 0.0)), "corrupt", "padding lane"),
    "Curve_Linear": (mutate(lambda r: r.put("I", r.array["Curve_Linear"], ~r.get("I", r.array["Curve_Linear"]) & 0xFFFFFFFF)),
                     "corrupt", "Curve_Linear[0]"),
    "Curve_Channel": (mutate(lambda r: r.put("I", r.array["Curve_Channel"], r.C)), "corrupt", "Curve_Channel"),
    "First_Frame of a block curve": (mutate(lambda r: r.put("f", r.array["First_Frame"], r.get("f", r.array["First_Frame"]) + 1)),
                                     "corrupt", "First_Frame[0]"),
    # 9.3 / 9.4: the records
    "a Record_Offset": (mutate(lambda r: r.put("I", r.entry("Record_Offset", 1, 4), r.get("I", r.entry("Record_Offset", 1, 4)) + 1)),
                        "corrupt", "Record_Offset[1]"),
    "a Record_Offset past the records": (mutate(lambda r: r.put("I", r.entry("Record_Offset", r.h["R"], 4), 1)),
                                         "corrupt", "the 8 entries after"),
    "a byte after the records": (mutate(lambda r: r.put("B", r.array["Payload"] + r.h["P"] + 3, 1)),
                                 "corrupt", "bytes after the records"),
    "Value_Bits 56": (mutate(lambda r: r.put("B", r.record(0)[0] + 8, 56)), "corrupt", "Value_Bits 56 > 55"),
    "Context_Bits 32": (mutate(lambda r: r.put("B", r.record(0)[0] + 9, 32)), "corrupt", "Context_Bits 32 > 31"),
    "a Mask bit beyond Frame_Count": (mutate(lambda r: r.put("Q", r.record(0)[0], r.get("Q", r.record(0)[0]) | 1 << 25)),
                                      "corrupt", "Mask bit of a frame >= Frame_Count"),
    "a bit after a record's fields": (mutate(set_record_bits_after_fields), "corrupt", "bits after its last field"),
    "a window out of order": (mutate(swap_context_0_into_1), "corrupt", "window frames out of order"),
    "popcounts against Key_Count": (mutate(popcount_against_key_count), "corrupt", "popcounts"),
}

PREDICT_LISTS = {  # v4_predict: every curve is a list curve
    "List_Frames not increasing": (lambda r: r.put("I", r.entry("List_Frames", 1, 4), r.get("I", r.array["List_Frames"])),
                                   "List_Frames[1]"),
    "List_Values against List_Q": (lambda r: r.put("f", r.entry("List_Values", 1, 4), next_f32(r.get("f", r.entry("List_Values", 1, 4)))),
                                   "List_Values[1]"),
    "List_Q beyond 2^53": (lambda r: r.put("q", r.entry("List_Q", 1, 8), -(2 ** 53) - 1), "List_Q[1]"),
    "Lists First": (lambda r: r.put("I", r.array["Lists"], 1), "Lists[0]"),
    "List_Key_Count": (lambda r: r.put("I", r.at["IMAG"] + 16, r.h["M"] - 1), "Raw_Size against the arrays"),
    "Last_Value of a list curve": (lambda r: r.put("f", r.array["Last_Value"], next_f32(r.get("f", r.array["Last_Value"]))),
                                   "Last_Value[0]"),
}
for _name, (_make, _message) in PREDICT_LISTS.items():
    STRUCTURE[_name] = ((lambda make: lambda: mutate(make)("v4_predict.kanim"))(_make), "corrupt", _message)


def cli_refuses(data, status, tmp_path):
    """The C++ tool (KEYANIM_CLI) refuses the same file with the same status."""
    tool = os.environ.get("KEYANIM_CLI")
    if not tool or not os.path.exists(tool):
        pytest.skip("the keyanim tool is not built (KEYANIM_CLI)")
    path = tmp_path / "broken.kanim"
    path.write_bytes(data)
    r = subprocess.run([tool, "-q", "convert", str(path), "--archive", "-o", str(tmp_path / "out.kanim")],
                       capture_output=True, text=True)
    assert r.returncode != 0 and f": {status}:" in r.stderr, r.stderr
    assert not (tmp_path / "out.kanim").exists()


@pytest.mark.parametrize("case", list(STRUCTURE))
def test_a_broken_structure_rule_is_refused(case, tmp_path):
    make, status, message = STRUCTURE[case]
    data = make()
    with pytest.raises(rd.KanimError) as e:
        rd.parse(data, check_content=False)  # a structure rule: refused without the content checks
    assert e.value.status == status, str(e.value)
    assert message in str(e.value)


@pytest.mark.parametrize("case", list(STRUCTURE))
def test_keyanim_refuses_the_broken_structure_too(case, tmp_path):
    make, status, _ = STRUCTURE[case]
    cli_refuses(make(), status, tmp_path)


def change_value_field(r, idx, field, curve=0):
    """Adds 1 (or takes 1) to value field `field` of record idx, of its curve `curve` (0, 1, 2
    in a track of three), within its width."""
    _, f = r.record(idx)
    bit = f["head"] + 4 * f["wk"] + f["wc"] + (f["m"] + 4) * sum(f["ws"][:curve]) + field * f["ws"][curve]
    width = f["ws"][curve]
    old = r.record_field(idx, bit, width)
    r.record_field(idx, bit, width, old + 1 if old + 1 < 1 << width else old - 1)


def change_base(r, idx, curve):
    """Adds 1 (or takes 1) to the Base of curve `curve` of record idx, within its width."""
    _, f = r.record(idx)
    bit, width = f["head"] + 4 * f["wk"] + sum(f["wcs"][:curve]), f["wcs"][curve]
    old = r.record_field(idx, bit, width)
    r.record_field(idx, bit, width, old + 1 if old + 1 < 1 << width else old - 1)


def change_context_within_order(r):
    """Moves e_0 of record 0 one frame earlier (still before e_1, within Context_Bits)."""
    _, f = r.record(0)
    old = rd.unzigzag(r.record_field(0, f["head"], f["wk"]))
    new = rd.zigzag(old - 1)
    assert new < 1 << f["wk"]
    r.record_field(0, f["head"], f["wk"], new)


def raise_the_lowest_block(r):
    """Adds 1 to the Base of the one record whose keys (not its context) hold a curve's
    smallest q: the curve's Q_Base then lies below every key."""
    for curve in range(r.h["nb"]):
        lows = []
        for b in range(r.h["B"]):
            idx = b * r.h["nb"] + curve
            _, f = r.record(idx)
            base_at = f["head"] + 4 * f["wk"]
            base = r.record_field(idx, base_at, f["wc"])
            keys = [r.record_field(idx, base_at + f["wc"] + j * f["w"], f["w"]) for j in range(2, f["m"] + 2)]
            if keys:
                lows.append((base + min(keys), idx, base_at, f["wc"], base))
        low = min(lows)
        if [x[0] for x in lows].count(low[0]) == 1 and low[4] + 1 < 1 << low[3]:
            _, idx, base_at, wc, base = low
            r.record_field(idx, base_at, wc, base + 1)
            return
    raise AssertionError("no curve of the vector has its smallest q in one record")


CONTENT = {
    "a context value field": (lambda r: change_value_field(r, 0, 0), "record of block 0, curve 0: Values"),
    # The block's first key is the curve's first: its new q no longer gives First_Value.
    "the first key's value field": (lambda r: change_value_field(r, 0, 2), "First_Value[0]"),
    "a context frame": (change_context_within_order, "record of block 0, curve 0: Context"),
    "First_Value of a block curve": (lambda r: r.put("f", r.array["First_Value"], next_f32(r.get("f", r.array["First_Value"]))),
                                     "First_Value[0]"),
    # Every q one lower, consistently: only the curve's ends tell.
    "Q_Base one lower": (lambda r: r.put("q", r.entry("Curves", 0, 24), r.get("q", r.entry("Curves", 0, 24)) - 1),
                         "First_Value[0]"),
    "Q_Base above no key": ("v4_long.kanim", lambda r: raise_the_lowest_block(r), "Q_Base is not the curve's smallest q"),
}


@pytest.mark.parametrize("case", list(CONTENT))
def test_a_broken_content_rule_is_refused_by_the_content_check(case, tmp_path):
    name, change, message = CONTENT[case] if len(CONTENT[case]) == 3 else ("v4_rules.kanim",) + CONTENT[case]
    data = mutate(change)(name)
    clip = rd.parse(data, check_content=False)  # every structure rule holds
    assert clip["version"] == (4, 0)
    with pytest.raises(rd.KanimError) as e:
        rd.parse(data)
    assert e.value.status == "corrupt" and message in str(e.value), str(e.value)


@pytest.mark.parametrize("case", list(CONTENT))
def test_keyanim_convert_refuses_the_broken_content_too(case, tmp_path):
    name, change, _ = CONTENT[case] if len(CONTENT[case]) == 3 else ("v4_rules.kanim",) + CONTENT[case]
    cli_refuses(mutate(change)(name), "corrupt", tmp_path)


def test_what_9_1_allows_is_accepted():
    """Unknown ancillary sections after SKEL, before or after NOTE, are skipped."""
    rules, single = vector("v4_rules.kanim"), vector("v4_single.kanim")
    (e, b), (se, sb) = sections(rules), sections(single)
    other = [(b"ZZZZ", 2, 8, 8)], [b"\1" * 8]
    for data, like in [(with_table(rules, e + other[0], b + other[1]), "v3_rules"),
                       (with_table(single, se + other[0], sb + other[1]), "v3_single"),
                       (with_table(single, se[:3] + other[0] + se[3:], sb[:3] + other[1] + sb[3:]), "v3_single")]:
        clip, want = rd.parse(data), rd.parse(vector(f"{like}.kanim"))
        assert clip["values"] == want["values"] and clip["notes"] == want["notes"]
        assert like == "v3_rules" or clip["notes"].startswith("encoder=")


@pytest.mark.parametrize("bvh,rotations", [("cmu_02_01_walk.bvh", "euler"), ("cmu_131_03_hop.bvh", "euler"),
                                           ("cmu_02_01_walk.bvh", "quaternion"), ("cmu_131_03_hop.bvh", "quaternion")])
def test_keyanim_runtime_files_of_real_clips_pass_every_check(bvh, rotations, tmp_path):
    """The shipped clips, encoded and converted by the tool: the runtime file passes the content
    checks too and holds the archive file's keys, value bits included (hop has records with a
    Value_Bits of 0, which no vector has). With Euler angles the files are of versions 3 and 4;
    with quaternion nodes (the encoder's default) of version 5, the runtime file's quaternion
    tracks laid out as 9.2 says."""
    tool = os.environ.get("KEYANIM_CLI")
    if not tool or not os.path.exists(tool):
        pytest.skip("the keyanim tool is not built (KEYANIM_CLI)")
    archive, runtime = tmp_path / "a.kanim", tmp_path / "r.kanim"
    subprocess.run([tool, "-q", "encode", str(REPO / "data" / bvh), "-o", str(archive), "--error", "0.5%",
                    "--rotations", rotations], check=True)
    subprocess.run([tool, "-q", "convert", str(archive), "--runtime", "-o", str(runtime)], check=True)
    a, r = rd.parse(archive.read_bytes()), rd.parse(runtime.read_bytes())
    major = 5 if rotations == "quaternion" else 4
    assert a["version"][0] == (5 if major == 5 else 3) and r["version"] == (major, 0) and a["frames"] == r["frames"]
    assert [[rd.f32_bits(v) for v in c] for c in a["values"]] == [[rd.f32_bits(v) for v in c] for c in r["values"]]
    assert a["quat_nodes"] == r["quat_nodes"] and (len(a["quat_nodes"]) > 0) == (major == 5)
    assert writer.runtime_file(archive.read_bytes()) == runtime.read_bytes()  # the spec's image, byte for byte


def test_runtime_clear_reads_a_runtime_layout_as_an_archive_file_and_refuses_it():
    data = header_flags("v4_rules.kanim", 0)
    with pytest.raises(rd.KanimError):
        rd.parse(data)


def test_an_unknown_major_version_is_refused():
    b = bytearray(vector("v4_rules.kanim"))
    struct.pack_into("<H", b, 8, 6)
    with pytest.raises(rd.KanimError) as e:
        rd.parse(bytes(b))
    assert e.value.status == "unsupported_version" and "major 6" in str(e.value)


# ---- Version 5: quaternion nodes (4.7) in both profiles

V5 = ["v5_quat", "v5_blocks", "v5_quat_runtime", "v5_blocks_runtime"]


@pytest.mark.parametrize("name", V5)
def test_v5_json_is_what_the_reference_decoder_writes(name, tmp_path):
    (tmp_path / f"{name}.kanim").write_bytes(vector(f"{name}.kanim"))
    out, what = rd.write_json(str(tmp_path / f"{name}.kanim"))
    assert what == "wrote" and Path(out).read_bytes() == (VECTORS / f"{name}.json").read_bytes()
    assert rd.write_json(str(tmp_path / f"{name}.kanim")) == (out, "unchanged")  # left as it is


def test_write_json_does_not_overwrite_other_values(tmp_path):
    """A published vector's values never change (Appendix C): other bytes are an error."""
    (tmp_path / "v5_quat.kanim").write_bytes(vector("v5_quat.kanim"))
    (tmp_path / "v5_quat.json").write_text("{}\n")
    with pytest.raises(rd.KanimError) as e:
        rd.write_json(str(tmp_path / "v5_quat.kanim"))
    assert e.value.status == "json_differs" and (tmp_path / "v5_quat.json").read_text() == "{}\n"


def test_only_version_5_json_has_quaternion_fields():
    for name in ["v3_rules", "v4_rules", "v4_archive"]:
        d = json.loads((VECTORS / f"{name}.json").read_text())
        assert "quat_nodes" not in d and all("rotations" not in x for x in d["samples"]), name
    for name in V5:
        d = json.loads((VECTORS / f"{name}.json").read_text())
        assert d["format_version"] == "5.0" and d["quat_nodes"], name
        assert all(len(x["rotations"]) == len(d["quat_nodes"]) for x in d["samples"]), name


@pytest.mark.parametrize("name", ["v5_quat", "v5_blocks"])
def test_v5_runtime_json_equals_archive_json(name):
    """The runtime profile holds the same clip: the same JSON, less the fields naming the file."""
    version_r, text_r = json_without_name(VECTORS / f"{name}_runtime.json")
    version_a, text_a = json_without_name(VECTORS / f"{name}.json")
    assert version_r == version_a == "5.0" and text_r == text_a


@pytest.mark.parametrize("name", ["v5_quat", "v5_blocks"])
def test_v5_runtime_keys_equal_archive_keys(name):
    a, r = rd.parse(vector(f"{name}.kanim")), rd.parse(vector(f"{name}_runtime.kanim"))
    assert a["version"] == r["version"] == (5, 0)
    bits = lambda vs: [[rd.f32_bits(v) for v in c] for c in vs]
    for key in ["frame_count", "frame_time", "tangent_rule", "nodes", "interp", "frames", "notes", "quat_nodes"]:
        assert a[key] == r[key], key
    assert bits(a["values"]) == bits(r["values"])


@pytest.mark.parametrize("source,made", [(f"v3_{n}", f"v4_{n}") for n in NAMES] +
                         [("v5_quat", "v5_quat_runtime"), ("v5_blocks", "v5_blocks_runtime")])
def test_the_runtime_writer_makes_the_runtime_vectors(source, made):
    """runtime_writer.py (9.2, 9.3 from the text) and keyanim write the same bytes: for version 5,
    the quaternion tracks' curves component-major, their nodes first in Quat_Node, the records
    of three curves."""
    assert writer.runtime_file(vector(f"{source}.kanim")) == vector(f"{made}.kanim")


def test_the_v5_vectors_cover_the_quaternion_rules():
    """What the rejections below rely on."""
    quat = rd.parse(vector("v5_quat.kanim"))
    assert [q["node"] for q in quat["quat_nodes"]] == [1, 2, 3, 5]
    assert [len(quat["frames"][q["column"]]) for q in quat["quat_nodes"]] == [81, 5, 1, 0]  # tracks, fixed, zero
    assert quat["nodes"][6]["channels"][1] == "Xposition" and len(quat["nodes"][7]["channels"]) == 2
    # A stored x that is a Zrotation channel: x, y, z are the rotation channels in their order.
    assert quat["nodes"][1]["channels"] == ["Zrotation", "Xrotation", "Yrotation"]
    _, image = image_of(vector("v5_quat_runtime.kanim"))
    assert image["header"]["T"] == 2 and image["tracks"][:2] == [[0, 2, 4], [1, 3, 5]]
    _, image = image_of(vector("v5_blocks_runtime.kanim"))
    assert image["header"]["T"] == 1 and image["header"]["Q"] == 2 and image["header"]["LQ"] == 4  # padding lanes
    assert image["arrays"]["Curve_Of"][7:10] == [7, 8, 9]  # node 2's x, y, z: list curves


def swap_the_quaternion_nodes_keys(clip):
    """v5_blocks with the keys of node 1's x, y, z (channels 4-6, block curves) and node 2's
    (channels 7-9, list curves) exchanged: node 2 becomes the quaternion track, node 1 not."""
    for key in ["frames", "q", "values", "step", "interp", "tension"]:
        clip[key][4:7], clip[key][7:10] = clip[key][7:10], clip[key][4:7]


def test_a_quaternion_track_after_a_node_without_one():
    """9.2: Quat_Node lists the quaternion tracks' nodes first, whatever their index: here
    [2, 1]. The decoder reads the file to the clip it was made from, its quaternion nodes in
    node order (as QUAT lists them)."""
    clip = rd.parse(vector("v5_blocks.kanim"))
    swap_the_quaternion_nodes_keys(clip)
    data = writer.runtime_file(vector("v5_blocks.kanim"), clip_change=swap_the_quaternion_nodes_keys)
    content, image = image_of(data)
    assert image["arrays"]["Quat_Node"] == [2, 1] and image["header"]["T"] == 1
    assert image["arrays"]["Curve_Channel"][:4] == [7, 8, 9, 0]  # the track's x, y, z, then channel 0
    r = rd.parse(data)
    assert r["frames"] == clip["frames"] and r["values"] == clip["values"]
    assert [q["node"] for q in r["quat_nodes"]] == [1, 2]
    # In node order, Quat_Node would break 9.2's order.
    bad = writer.runtime_file(vector("v5_blocks.kanim"), clip_change=swap_the_quaternion_nodes_keys,
                              change=lambda header, a: swap_lanes_0_and_1(a))
    with pytest.raises(rd.KanimError) as e:
        rd.parse(bad)
    assert e.value.status == "corrupt" and "has no block curves before a node with" in str(e.value), str(e.value)


def swap_lanes_0_and_1(a):
    """Quaternion nodes 0 and 1 of an image's parts exchanged in Quat_Node, Quat_Column and
    Quat_Reference (four arrays of 4 lanes here)."""
    for name in ["Quat_Node", "Quat_Column"]:
        a[name][0], a[name][1] = a[name][1], a[name][0]
    lanes = a["Quat_Reference"]
    for k in range(4):
        lanes[4 * k], lanes[4 * k + 1] = lanes[4 * k + 1], lanes[4 * k]


def test_keyanim_reads_a_quaternion_track_after_a_node_without_one(tmp_path):
    """The same file given to keyanim: it converts it to an archive file of the same clip."""
    tool = os.environ.get("KEYANIM_CLI")
    if not tool or not os.path.exists(tool):
        pytest.skip("the keyanim tool is not built (KEYANIM_CLI)")
    path, out = tmp_path / "r.kanim", tmp_path / "a.kanim"
    path.write_bytes(writer.runtime_file(vector("v5_blocks.kanim"), clip_change=swap_the_quaternion_nodes_keys))
    r = subprocess.run([tool, "-q", "convert", str(path), "--archive", "-o", str(out)], capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    a, want = rd.parse(out.read_bytes()), rd.parse(path.read_bytes())
    assert a["version"] == (5, 0) and a["frames"] == want["frames"] and a["values"] == want["values"]
    assert a["quat_nodes"] == want["quat_nodes"]


def test_the_hamilton_product_is_r_times_s():
    """4.7: q = r s. Rz(90 deg) Rx(90 deg) takes x to y, y to z, z to x: (1/2, 1/2, 1/2, 1/2);
    s r would be (1/2, -1/2, 1/2, 1/2)."""
    h = 0.5 ** 0.5
    assert [round(x, 12) for x in rd.hamilton((0, 0, h, h), (h, 0, 0, h))] == [0.5, 0.5, 0.5, 0.5]
    assert rd.quat_rotation([0, 0, 23170], h, 0, 0) == pytest.approx([0.5, 0.5, 0.5, 0.5], abs=3e-5)  # r of int16s


def test_the_rotations_of_the_json_are_the_stored_values_under_the_reference():
    """An identity reference: the rotation is (sx, sy, sz, w) itself; a reference r: r s, unit."""
    d = json.loads((VECTORS / "v5_quat.json").read_text())
    quats = rd.parse(vector("v5_quat.kanim"))["quat_nodes"]
    assert d["quat_nodes"] == [{"node": q["node"], "reference": q["reference"]} for q in quats]
    for sample in d["samples"]:
        sx, sy, sz = sample["values"][6:9]  # node 1, reference (0, 0, 0)
        w = max(0.0, 1 - (sx * sx + sy * sy + sz * sz)) ** 0.5
        norm = (sx * sx + sy * sy + sz * sz + w * w) ** 0.5
        assert sample["rotations"][0] == pytest.approx([sx / norm, sy / norm, sz / norm, w / norm], abs=1e-15)
        for rotation in sample["rotations"]:
            assert sum(x * x for x in rotation) == pytest.approx(1.0, abs=1e-14)
    # Node 5 has no keys: its rotation is its reference's.
    X, Y, Z = quats[3]["reference"]
    r = [X / 32768, Y / 32768, Z / 32768, (1 - (X * X + Y * Y + Z * Z) / 2 ** 30) ** 0.5]
    assert d["samples"][0]["rotations"][3] == pytest.approx(r, abs=1e-15)


# -- The archive profile of version 5: QUAT, CHAN's rule, KTIM's shared key frames, section 8

def archive_parts(data):
    """[[tag, flags, content]] of an archive-profile file's sections, decompressed (Compressed
    cleared), in table order."""
    count = struct.unpack_from("<I", data, 16)[0]
    out, pos = [], 24 + 24 * count
    for i in range(count):
        tag, flags, stored, raw = struct.unpack_from("<4sIQQ", data, 24 + 24 * i)
        body = data[pos:pos + stored]
        out.append([tag.decode(), flags & ~1, bytearray(rd.zstd_decompress(body) if flags & 1 else body)])
        pos += stored
    return out


def archive_file(parts, like):
    """An archive-profile file of these sections, uncompressed (any section MAY be, 3.2.5),
    with the header of file `like` and its CRC-32 fixed."""
    head = bytearray(like[:24])
    struct.pack_into("<I", head, 16, len(parts))
    table = b"".join(struct.pack("<4sIQQ", tag.encode(), flags, len(body), len(body)) for tag, flags, body in parts)
    body = bytes(head) + table + b"".join(bytes(p[2]) for p in parts)
    return body + struct.pack("<I", zlib.crc32(body))


def part(parts, tag):
    return next(p[2] for p in parts if p[0] == tag)


def archive_change(change, name="v5_quat.kanim"):
    """Vector `name` uncompressed, its sections changed by change(parts) (in place)."""
    def build():
        parts = archive_parts(vector(name))
        change(parts)
        return archive_file(parts, vector(name))
    return build


def quat_entry(j, node=None, reference=None):
    def change(parts):
        quat = part(parts, "QUAT")
        if node is not None:
            struct.pack_into("<I", quat, 4 + 10 * j, node)
        if reference is not None:
            struct.pack_into("<3h", quat, 8 + 10 * j, *reference)
    return change


def channel_types_at(skel, node):
    """Offset in SKEL's content (4.2) of node `node`'s Channel_Types."""
    pos = 0
    for _ in range(node):
        pos += 4 + struct.unpack_from("<I", skel, pos)[0] + 29
        pos += 1 + skel[pos]
    return pos + 4 + struct.unpack_from("<I", skel, pos)[0] + 30


def neck_about_two_axes(skel):
    """Node 5 (Neck: Zrotation, Xrotation, Yrotation) made Zrotation, Xrotation, Xrotation."""
    at = channel_types_at(skel, 5)
    assert list(skel[at:at + 3]) == [5, 3, 4]
    skel[at + 2] = 3


def swap_quat_entries(parts):
    quat = part(parts, "QUAT")
    quat[4:24] = quat[14:24] + quat[4:14]


def chan_field(offset_of, fmt, value):
    """CHAN's entry at offset_of(C) set to value(old)."""
    def change(parts):
        chan = part(parts, "CHAN")
        C = len(chan) // 19
        at = offset_of(C)
        struct.pack_into("<" + fmt, chan, at, value(struct.unpack_from("<" + fmt, chan, at)[0]))
    return change


def varint(v):
    out = bytearray()
    while True:
        out.append(v & 0x7F | (0x80 if v > 0x7F else 0))
        v >>= 7
        if not out[-1] & 0x80:
            return bytes(out)


def ktim_of_every_channel(parts):
    """KTIM as a version 3 file would hold it: varints for every channel, a quaternion node's y and
    z too (K varints instead of T)."""
    clip = rd.parse(vector("v5_quat.kanim"))
    out = b""
    for k in clip["frames"]:
        out += b"".join(varint(x if i == 0 else x - k[i - 1] - 1) for i, x in enumerate(k))
    part(parts, "KTIM")[:] = out


def move_quat_after_chan(parts):
    i = next(i for i, p in enumerate(parts) if p[0] == "QUAT")
    quat = parts.pop(i)
    parts.insert(next(i for i, p in enumerate(parts) if p[0] == "CHAN") + 1, quat)


def clip_counts(frames, keys, name="v5_quat.kanim"):
    """Vector `name` (its bytes as they are: CLIP is stored uncompressed) with CLIP's
    Frame_Count and Key_Count set to frames, keys(file size), CRC-32 fixed."""
    def build():
        b = bytearray(vector(name))
        count = struct.unpack_from("<I", b, 16)[0]
        assert b[24:28] == b"CLIP" and not struct.unpack_from("<I", b, 28)[0] & 1
        at = 24 + 24 * count
        struct.pack_into("<I", b, at, frames)
        struct.pack_into("<Q", b, at + 24, keys(len(b)))
        struct.pack_into("<I", b, len(b) - 4, zlib.crc32(bytes(b[:-4])))
        return bytes(b)
    return build


def with_quat_section(name, flags):
    """Vector `name` (version 3 or 4) with a QUAT section after SKEL."""
    def change(parts):
        parts.insert(2, ["QUAT", flags, bytearray(4)])
    return archive_change(change, name)


V5_ARCHIVE = {
    # 4.7: QUAT (v5_quat: nodes 1, 2, 3, 5; node 6 has Zrotation, Xposition, Xrotation, Yrotation,
    # node 7 two rotation channels, N = 9)
    "QUAT: a node whose rotation channels are not consecutive": (
        archive_change(quat_entry(3, node=6)), "corrupt", "are not three consecutive rotation channels"),
    "QUAT: a node with two rotation channels": (
        archive_change(quat_entry(3, node=7)), "corrupt", "are not three consecutive rotation channels"),
    "QUAT: a node with no rotation channel": (
        archive_change(quat_entry(3, node=8)), "corrupt", "are not three consecutive rotation channels"),
    "QUAT: a node with three rotation channels about two axes": (
        archive_change(lambda p: neck_about_two_axes(part(p, "SKEL"))), "corrupt", "are not three consecutive rotation channels"),
    "QUAT: nodes not increasing": (archive_change(swap_quat_entries), "corrupt", "not above the entry before"),
    "QUAT: Node = Node_Count": (archive_change(quat_entry(3, node=9)), "corrupt", "not < Node_Count 9"),
    "QUAT: a reference beyond the unit ball": (
        archive_change(quat_entry(1, reference=(32767, 32767, 0))), "corrupt", "X^2 + Y^2 + Z^2 > 2^30"),
    "QUAT: a reference just beyond the unit ball": (
        archive_change(quat_entry(1, reference=(-32768, 1, 0))), "corrupt", "X^2 + Y^2 + Z^2 > 2^30"),
    "QUAT: Raw_Size 4 + 10 Q + 2": (archive_change(lambda p: part(p, "QUAT").extend(b"\0\0")), "corrupt",
                                   "!= 4 + 10 x Quat_Count"),
    "QUAT: Quat_Count > Node_Count": (archive_change(lambda p: struct.pack_into("<I", part(p, "QUAT"), 0, 10)),
                                      "corrupt", "Quat_Count 10 > Node_Count 9"),
    # 3.2.3: QUAT between SKEL and CHAN, once, critical; unknown before version 5
    "no QUAT in version 5": (archive_change(lambda p: p.remove(next(x for x in p if x[0] == "QUAT"))), "corrupt",
                             "critical sections"),
    "QUAT after CHAN": (archive_change(move_quat_after_chan), "corrupt", "critical sections"),
    "QUAT ancillary": (archive_change(lambda p: next(x for x in p if x[0] == "QUAT").__setitem__(1, 2)), "corrupt",
                       "QUAT marked ancillary"),
    "a critical QUAT in a version 3 file": (with_quat_section("v3_rules.kanim", 0), "reserved_bits_set",
                                            "unknown critical section QUAT"),
    "a critical QUAT in a version 4 archive file": (with_quat_section("v4_archive.kanim", 0), "reserved_bits_set",
                                                   "unknown critical section QUAT"),
    # 4.3: a quaternion node's x, y, z (node 1: channels 6, 7, 8) share Interpolation, Tension, Key_Count
    "CHAN: y's Key_Count unlike x's": (archive_change(chan_field(lambda C: 13 * C + 4 * 7, "I", lambda v: v + 1)),
                                      "corrupt", "channel 7's Interpolation, Tension or Key_Count"),
    "CHAN: z's Tension one bit from x's": (archive_change(chan_field(lambda C: C + 4 * 8, "I", lambda v: v ^ 1)),
                                          "corrupt", "channel 8's Interpolation, Tension or Key_Count"),
    "CHAN: y's Interpolation unlike x's": (archive_change(chan_field(lambda C: 7, "B", lambda v: v ^ 1)),
                                          "corrupt", "channel 7's Interpolation, Tension or Key_Count"),
    # 4.4: no varints for a quaternion node's y and z (read as the next channels' key frames,
    # they put a frame past Frame_Count or leave varints over)
    "KTIM with varints for y and z": (archive_change(ktim_of_every_channel), "corrupt", ("key frame", "KTIM size")),
    # 8: K at most 98304 x the file's size in version 5
    "Key_Count > 98304 x the file's size": (clip_counts(2 ** 24, lambda size: 98304 * size + 1), "corrupt",
                                            "98304 x the file's"),
}


@pytest.mark.parametrize("case", list(V5_ARCHIVE))
def test_a_broken_version_5_archive_rule_is_refused(case):
    make, status, message = V5_ARCHIVE[case]
    with pytest.raises(rd.KanimError) as e:
        rd.parse(make())
    assert e.value.status == status, str(e.value)
    assert any(m in str(e.value) for m in (message if isinstance(message, tuple) else (message,))), str(e.value)


@pytest.mark.parametrize("case", list(V5_ARCHIVE))
def test_keyanim_refuses_the_broken_version_5_archive_too(case, tmp_path):
    make, status, _ = V5_ARCHIVE[case]
    cli_refuses(make(), status, tmp_path)


def test_the_uncompressed_v5_archive_decodes_as_the_vector():
    """What the cases above start from: the vector, its sections stored uncompressed."""
    a, b = rd.parse(archive_change(lambda parts: None)()), rd.parse(vector("v5_quat.kanim"))
    assert a["values"] == b["values"] and a["frames"] == b["frames"] and a["quat_nodes"] == b["quat_nodes"]


def test_what_version_5_allows_in_the_archive_profile_is_accepted():
    """A reference on the unit sphere (X^2 + Y^2 + Z^2 = 2^30: rw = 0), an ancillary QUAT before
    version 5 (an unknown ancillary section, skipped), and a Key_Count above 32768 but within
    98304 times the file's size (refused by CHAN's sum, not by section 8's bound)."""
    clip = rd.parse(archive_change(quat_entry(1, reference=(-32768, 0, 0)))())
    assert clip["quat_nodes"][1]["reference"] == [-32768, 0, 0]
    rotation = rd.rotations_at(clip, [rd.channel_value(clip, c, 3.5) for c in range(25)])[1]
    assert sum(x * x for x in rotation) == pytest.approx(1.0)
    assert rd.parse(with_quat_section("v3_rules.kanim", 2)())["values"] == rd.parse(vector("v3_rules.kanim"))["values"]
    with pytest.raises(rd.KanimError) as e:
        rd.parse(clip_counts(2 ** 24, lambda size: 32768 * size + 1)())
    assert e.value.status == "corrupt" and "Key_Count sum" in str(e.value), str(e.value)


# -- The runtime profile of version 5: IMAG's quaternion nodes, tracks, records of three curves

def lane_of(r, j, k):
    """File offset of component k (rx, ry, rz, rw) of quaternion node j's Quat_Reference lane."""
    return r.entry("Quat_Reference", k * r.h["LQ"] + j, 4)


def swap_quat_nodes(r, i, j):
    """Quat_Node entries i and j swapped, with their Quat_Column and reference lanes."""
    for name in ["Quat_Node", "Quat_Column"]:
        a, b = r.get("I", r.entry(name, i, 4)), r.get("I", r.entry(name, j, 4))
        r.put("I", r.entry(name, i, 4), b)
        r.put("I", r.entry(name, j, 4), a)
    for k in range(4):
        a, b = r.get("I", lane_of(r, i, k)), r.get("I", lane_of(r, j, k))
        r.put("I", lane_of(r, i, k), b)
        r.put("I", lane_of(r, j, k), a)


def key_count_of_y(r):
    """Node 1's stored y (channel 7) one key more than its x, with CLIP's Key_Count."""
    r.put("I", r.entry("Key_Count", 7, 4), r.get("I", r.entry("Key_Count", 7, 4)) + 1)
    r.put("Q", r.at["CLIP"] + 24, r.get("Q", r.at["CLIP"] + 24) + 1)


def curve_order_by_channel(r):
    """Curves 1 and 2 (track 1's x, track 0's y) swapped in Curve_Channel and Curve_Of, as if
    block curves were in channel order."""
    a, b = r.get("I", r.entry("Curve_Channel", 1, 4)), r.get("I", r.entry("Curve_Channel", 2, 4))
    r.put("I", r.entry("Curve_Channel", 1, 4), b)
    r.put("I", r.entry("Curve_Channel", 2, 4), a)
    r.put("I", r.entry("Curve_Of", a, 4), 2)
    r.put("I", r.entry("Curve_Of", b, 4), 1)


def one_track_fewer_declared(header, a):
    """Quat_Track_Count one less, Record_Offset sized to match (R = B x (nb - 2T))."""
    header["Quat_Track_Count"] -= 1
    R = header["Block_Count"] * (header["Block_Curve_Count"] - 2 * header["Quat_Track_Count"])
    a["Record_Offset"] = a["Record_Offset"][:R] + [0] * 8


def first_three_curve_record(r):
    return next(idx for idx in range(r.h["R"]) if len(r.record(idx)[1]["curves"]) == 3)


def middle_list_frame_of_y(r):
    """v5_blocks: node 2's stored y (channel 8, a list curve of 3 keys) with its middle key one
    frame later than its x's (still increasing, the ends unchanged)."""
    start, count = r.get("I", r.entry("Lists", r.get("I", r.entry("Curve_Of", 8, 4)) - r.h["nb"], 8)), 3
    assert r.get("I", r.entry("Key_Count", 8, 4)) == count
    at = r.entry("List_Frames", start + 1, 4)
    r.put("I", at, r.get("I", at) + 1)


V5_RUNTIME = {
    # 9.2: the header
    "Quat_Count > Node_Count": ("v5_quat_runtime", lambda r: r.put("I", r.at["IMAG"] + 24, r.N + 1), "Quat_Count 10 > Node_Count 9"),
    "Quat_Track_Count > Quat_Count": ("v5_blocks_runtime", lambda r: r.put("I", r.at["IMAG"] + 28, 3), "Quat_Track_Count 3 > Quat_Count 2"),
    "Quat_Track_Count one less (the arrays sized to it)": (lambda: writer.runtime_file(
        vector("v5_quat.kanim"), change=one_track_fewer_declared), None, "Quat_Track_Count 1 is not the 2"),
    # 9.2: Quat_Node (v5_quat: 1, 2 with block curves; 3, 5 without), Quat_Column, Quat_Reference
    "Quat_Node: a node whose rotation channels are not consecutive": (
        "v5_quat_runtime", lambda r: r.put("I", r.entry("Quat_Node", 3, 4), 6), "are not three consecutive rotation channels"),
    "Quat_Node: a node with two rotation channels": (
        "v5_quat_runtime", lambda r: r.put("I", r.entry("Quat_Node", 3, 4), 7), "are not three consecutive rotation channels"),
    "Quat_Node: a node with three rotation channels about two axes": (
        "v5_quat_runtime", lambda r: neck_about_two_axes(memoryview(r.b)[r.at["SKEL"]:]),
        "are not three consecutive rotation channels"),
    "Quat_Node = Node_Count": ("v5_quat_runtime", lambda r: r.put("I", r.entry("Quat_Node", 3, 4), 9), "not < Node_Count 9"),
    "Quat_Node: the nodes without tracks not increasing": (
        "v5_quat_runtime", lambda r: swap_quat_nodes(r, 2, 3), "not above the entry before"),
    "Quat_Node: the tracks' nodes not increasing": (
        "v5_quat_runtime", lambda r: swap_quat_nodes(r, 0, 1), "not above the entry before"),
    "Quat_Node in node order, a node without a track first": (
        "v5_blocks_runtime", lambda r: swap_quat_nodes(r, 0, 1), "has no block curves before a node with"),
    "Quat_Column": ("v5_quat_runtime", lambda r: r.put("I", r.entry("Quat_Column", 1, 4), 10), "Quat_Column[1]"),
    "Quat_Reference: rx not an int16 x 2^-15": (
        "v5_quat_runtime", lambda r: r.put("f", lane_of(r, 1, 0), 0.1), "not int16 x 2^-15"),
    "Quat_Reference: rx of 1.0 (X = 32768)": (
        "v5_quat_runtime", lambda r: r.put("f", lane_of(r, 0, 0), 1.0), "not int16 x 2^-15"),
    "Quat_Reference beyond the unit ball": (
        "v5_quat_runtime", lambda r: [r.put("f", lane_of(r, 1, k), 32767 / 32768) for k in range(3)], "X^2 + Y^2 + Z^2 > 2^30"),
    "Quat_Reference: rw one ulp off": (
        "v5_quat_runtime", lambda r: r.put("f", lane_of(r, 1, 3), next_f32(r.get("f", lane_of(r, 1, 3)))), "lane 1 is not the reference"),
    "Quat_Reference: rx -0.0 for X = 0": (
        "v5_quat_runtime", lambda r: r.put("f", lane_of(r, 0, 0), -0.0), "lane 0 is not the reference (0, 0, 0)"),
    "Quat_Reference: a padding lane": (
        "v5_blocks_runtime", lambda r: r.put("f", lane_of(r, 3, 3), 0.0), "padding lane 3 is not (0, 0, 0, 1)"),
    # 9.4: a quaternion node's x, y, z alike, and their shared key frames
    "y's Key_Count unlike x's": ("v5_quat_runtime", key_count_of_y, "channel 7's Interpolation, Tension or Key_Count"),
    "z's Tension one bit from x's": (
        "v5_quat_runtime", lambda r: r.put("I", r.entry("Tension", 8, 4), r.get("I", r.entry("Tension", 8, 4)) ^ 1),
        "channel 8's Interpolation, Tension or Key_Count"),
    "y's Interpolation unlike x's": (
        "v5_quat_runtime", lambda r: r.put("B", r.entry("Interpolation", 7, 1), r.get("B", r.entry("Interpolation", 7, 1)) ^ 1),
        "channel 7's Interpolation, Tension or Key_Count"),
    "a fixed y's Fixed_Frame unlike x's": (
        "v5_quat_runtime", lambda r: r.put("I", r.entry("Fixed_Frame", 14, 4), r.get("I", r.entry("Fixed_Frame", 13, 4)) + 1),
        "Fixed_Frame[14] is not its quaternion node's stored x's"),
    "a list y's List_Frames unlike x's": ("v5_blocks_runtime", middle_list_frame_of_y, "List_Frames are not its quaternion node's"),
    # 9.2: the curves' order (the tracks' x's, y's, z's first)
    "the curves in channel order": ("v5_quat_runtime", curve_order_by_channel, "Curve_Of"),
    # 9.3: records of three curves
    "a quaternion track's record: z's Value_Bits 56": (
        "v5_quat_runtime", lambda r: r.put("B", r.record(0)[0] + 10, 56), "Value_Bits 56 > 55"),
    "a quaternion track's record: y's Value_Bits 56": (
        "v5_quat_runtime", lambda r: r.put("B", r.record(0)[0] + 9, 56), "Value_Bits 56 > 55"),
    "a quaternion track's record: Context_Bits 32": (
        "v5_quat_runtime", lambda r: r.put("B", r.record(0)[0] + 11, 32), "Context_Bits 32 > 31"),
    "a quaternion track's record: a bit after its fields": (
        "v5_quat_runtime", lambda r: set_record_bits_after_fields(r, tracks_of=3), "bits after its last field"),
    "a quaternion track's record: its window out of order": (
        "v5_quat_runtime", lambda r: swap_context_0_into_1(r, first_three_curve_record(r)), "window frames out of order"),
    # 9.1.2: no QUAT in the runtime profile of version 5
    "a QUAT section": (lambda: with_table(vector("v5_quat_runtime.kanim"), *[a + b for a, b in zip(
        sections(vector("v5_quat_runtime.kanim")), [[(b"QUAT", 0, 4, 4)], [bytes(4)]])]), None, "QUAT in a runtime-profile file"),
    "an ancillary QUAT section": (lambda: with_table(vector("v5_quat_runtime.kanim"), *[a + b for a, b in zip(
        sections(vector("v5_quat_runtime.kanim")), [[(b"QUAT", 2, 4, 4)], [bytes(4)]])]), None, "QUAT in a runtime-profile file"),
}
V5_STRUCTURE = {}
for _name, (_source, _change, _message) in V5_RUNTIME.items():
    _make = _source if callable(_source) else (lambda s, c: lambda: mutate(c)(f"{s}.kanim"))(_source, _change)
    V5_STRUCTURE[f"v5: {_name}"] = (_make, "corrupt", _message)
# Version 4: Quat_Count is reserved (Image_Reserved), QUAT an unknown tag.
V5_STRUCTURE["v4: Quat_Count"] = (mutate(lambda r: r.put("I", r.at["IMAG"] + 24, 1)), "reserved_bits_set", "Image_Reserved")
V5_STRUCTURE["v4: a critical QUAT section"] = (lambda: append_section(b"QUAT", 0), "reserved_bits_set", "unknown critical")


@pytest.mark.parametrize("case", list(V5_STRUCTURE))
def test_a_broken_version_5_structure_rule_is_refused(case):
    make, status, message = V5_STRUCTURE[case]
    with pytest.raises(rd.KanimError) as e:
        rd.parse(make(), check_content=False)  # a structure rule: refused without the content checks
    assert e.value.status == status, str(e.value)
    assert message in str(e.value), str(e.value)


@pytest.mark.parametrize("case", list(V5_STRUCTURE))
def test_keyanim_refuses_the_broken_version_5_structure_too(case, tmp_path):
    make, status, _ = V5_STRUCTURE[case]
    cli_refuses(make(), status, tmp_path)


def test_version_4_skips_an_ancillary_quat_section():
    """QUAT is a tag of version 5: a version 4 file may hold an ancillary one, unknown to it."""
    assert rd.parse(append_section(b"QUAT", 2))["values"] == rd.parse(vector("v4_rules.kanim"))["values"]


V5_CONTENT = {
    # Track 0 is node 1's: curves 0, 2, 4 (T = 2). A context value of its y, and the Base of its z.
    "a quaternion track's y context value": (lambda r: change_value_field(r, 0, 0, curve=1),
                                             "record of block 0, curve 2: Values"),
    "a quaternion track's z Base": (lambda r: change_base(r, 0, 2), "First_Value[4]"),
}


@pytest.mark.parametrize("case", list(V5_CONTENT))
def test_a_broken_version_5_content_rule_is_refused_by_the_content_check(case):
    change, message = V5_CONTENT[case]
    data = mutate(change)("v5_quat_runtime.kanim")
    assert rd.parse(data, check_content=False)["version"] == (5, 0)  # every structure rule holds
    with pytest.raises(rd.KanimError) as e:
        rd.parse(data)
    assert e.value.status == "corrupt" and message in str(e.value), str(e.value)


@pytest.mark.parametrize("case", list(V5_CONTENT))
def test_keyanim_convert_refuses_the_broken_version_5_content_too(case, tmp_path):
    cli_refuses(mutate(V5_CONTENT[case][0])("v5_quat_runtime.kanim"), "corrupt", tmp_path)


if __name__ == "__main__":
    sys.exit(pytest.main([__file__, "-q"]))


# ---- 4.7's bound on a quaternion node's stored values (a content rule of the runtime profile)

@pytest.mark.parametrize("bound", [16.0, 16.5])
def test_a_stored_quaternion_value_beyond_16_is_refused(bound, tmp_path):
    """v5_blocks_runtime's curve 0 (its quaternion track's x) with its Step scaled so that its
    largest key is `bound`, its end values made to match: 16 decodes, 16.5 is refused by the
    content checks (and by keyanim's converter, which checks content), not by the structure's."""
    data = vector("v5_blocks_runtime.kanim")
    image = image_of(data)[1]
    assert len(image["tracks"][0]) == 3  # track 0: a quaternion track's x, y, z (curves 0, QT, 2QT)
    frames, qs, values = image["keys"][0]
    assert max(abs(v) for v in values) <= 1
    top = max(abs(q) for q in qs)
    step = bound / top
    r = Runtime(data)
    r.put("d", r.entry("Curves", 0, 24) + 8, step)
    r.put("f", r.entry("First_Value", 0, 4), rd.f32(qs[0] * step))
    r.put("f", r.entry("Last_Value", 0, 4), rd.f32(qs[-1] * step))
    broken = r.bytes()
    clip = rd.parse(broken, check_content=False)
    x = image["arrays"]["Curve_Channel"][0]
    assert max(abs(v) for v in clip["values"][x]) == bound
    if bound <= 16:
        rd.parse(broken, check_content=True)
        return
    with pytest.raises(rd.KanimError) as e:
        rd.parse(broken, check_content=True)
    assert e.value.status == "corrupt" and "16" in str(e.value)
    cli_refuses(broken, "corrupt", tmp_path)
