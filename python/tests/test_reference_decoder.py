"""spec/test-vectors/reference_decoder.py on the runtime profile (spec section 9) and the v4
vectors: its XXH64 against xxHash's check values, the v4 JSON against the v3 JSON of the same
clip, and one rejection per rule of 9.1-9.4, each made by breaking that rule alone in a v4
vector (the XXH64 fixed again, so that the rule and not the checksum refuses it).

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


def load_module(name):
    spec = importlib.util.spec_from_file_location(name, VECTORS / f"{name}.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


rd = load_module("reference_decoder")


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
    out = rd.write_json(str(tmp_path / f"{v4}.kanim"))
    assert Path(out).read_bytes() == (VECTORS / f"{v4}.json").read_bytes()


def test_v4_archive_is_v3_rules_with_major_version_4():
    made = load_module("make_v4_archive").v4_archive_bytes(vector("v3_rules.kanim"))
    assert made == vector("v4_archive.kanim")
    assert struct.unpack_from("<HHI", made, 8) == (4, 0, 0)  # Runtime clear
    assert zlib.crc32(made[:-4]) == struct.unpack_from("<I", made, len(made) - 4)[0]


def test_the_vectors_cover_the_image():
    """What the rejections below and Appendix C rely on: block and list curves, fixed
    channels, records without keys, the widest values, a NOTE."""
    def image(name):
        data = vector(f"v4_{name}.kanim")
        content = rd.runtime_sections(data, struct.unpack_from("<I", data, 16)[0])
        F, N, C, rule, frame_time, K = rd.parse_clip(content["CLIP"])
        return content, rd.parse_image(content["IMAG"], F, C, K)
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


# ---- Breaking one rule at a time

class Runtime:
    """A runtime-profile file to break: where its sections, IMAG's arrays and records are."""

    def __init__(self, data):
        self.b = bytearray(data)
        self.count = struct.unpack_from("<I", self.b, 16)[0]
        self.entries = [struct.unpack_from("<4sIQQ", self.b, 24 + 24 * i) for i in range(self.count)]
        self.at, pos = {}, 24 + 24 * self.count
        for tag, _, stored, _ in self.entries:
            self.at[tag.decode()] = pos
            pos += stored
        clip = self.at["CLIP"]
        self.F, _, self.C = struct.unpack_from("<III", self.b, clip)
        imag = self.at["IMAG"]
        self.h = rd.image_header(bytes(self.b[imag:imag + 32]), self.F, self.C)
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
        """Byte offset in the file of record idx (block-major), and its fields' widths."""
        at = self.array["Payload"] + self.get("I", self.entry("Record_Offset", idx, 4))
        curve = idx % self.h["nb"]
        wc = self.get("I", self.entry("Curves", curve, 24) + 16)
        mask, w, wk = struct.unpack_from("<QBB", self.b, at)
        return at, {"m": bin(mask).count("1"), "w": w, "wk": wk, "wc": wc}

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


def set_record_bits_after_fields(r):
    """Sets a bit after the last field of the first record whose bits do not fill its bytes."""
    for idx in range(r.h["R"]):
        _, f = r.record(idx)
        nbits = 80 + 4 * f["wk"] + f["wc"] + (f["m"] + 4) * f["w"]
        if nbits % 8:
            r.record_field(idx, nbits, 1, 1)
            return
    raise AssertionError("every record of the vector fills its bytes")


def swap_context_0_into_1(r):
    _, f = r.record(0)
    r.record_field(0, 80 + f["wk"], f["wk"], r.record_field(0, 80, f["wk"]))  # e_1 = e_0


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


# Cases where keyanim (C++) is known to differ from this decoder (strict: the mark must go when
# the tool changes). None today.
CPP_DIFFERS = {}


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


@pytest.mark.parametrize("case", [pytest.param(c, marks=pytest.mark.xfail(strict=True, reason=CPP_DIFFERS[c]))
                                  if c in CPP_DIFFERS else c for c in STRUCTURE])
def test_keyanim_refuses_the_broken_structure_too(case, tmp_path):
    make, status, _ = STRUCTURE[case]
    cli_refuses(make(), status, tmp_path)


def change_value_field(r, idx, field):
    """Adds 1 (or takes 1) to value field `field` of record idx, within its width."""
    _, f = r.record(idx)
    bit = 80 + 4 * f["wk"] + f["wc"] + field * f["w"]
    old = r.record_field(idx, bit, f["w"])
    r.record_field(idx, bit, f["w"], old + 1 if old + 1 < 1 << f["w"] else old - 1)


def change_context_within_order(r):
    """Moves e_0 of record 0 one frame earlier (still before e_1, within Context_Bits)."""
    _, f = r.record(0)
    old = rd.unzigzag(r.record_field(0, 80, f["wk"]))
    new = rd.zigzag(old - 1)
    assert new < 1 << f["wk"]
    r.record_field(0, 80, f["wk"], new)


def raise_the_lowest_block(r):
    """Adds 1 to the Base of the one record whose keys (not its context) hold a curve's
    smallest q: the curve's Q_Base then lies below every key."""
    for curve in range(r.h["nb"]):
        lows = []
        for b in range(r.h["B"]):
            idx = b * r.h["nb"] + curve
            _, f = r.record(idx)
            base_at = 80 + 4 * f["wk"]
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


@pytest.mark.parametrize("bvh", ["cmu_02_01_walk.bvh", "cmu_131_03_hop.bvh"])
def test_keyanim_runtime_files_of_real_clips_pass_every_check(bvh, tmp_path):
    """The shipped clips, encoded and converted by the tool: the runtime file passes the content
    checks too and holds the archive file's keys, value bits included (hop has records with a
    Value_Bits of 0, which no vector has)."""
    tool = os.environ.get("KEYANIM_CLI")
    if not tool or not os.path.exists(tool):
        pytest.skip("the keyanim tool is not built (KEYANIM_CLI)")
    archive, runtime = tmp_path / "a.kanim", tmp_path / "r.kanim"
    subprocess.run([tool, "-q", "encode", str(REPO / "data" / bvh), "-o", str(archive), "--error", "0.5%"], check=True)
    subprocess.run([tool, "-q", "convert", str(archive), "--runtime", "-o", str(runtime)], check=True)
    a, r = rd.parse(archive.read_bytes()), rd.parse(runtime.read_bytes())
    assert r["version"] == (4, 0) and a["frames"] == r["frames"]
    assert [[rd.f32_bits(v) for v in c] for c in a["values"]] == [[rd.f32_bits(v) for v in c] for c in r["values"]]


def test_runtime_clear_reads_a_runtime_layout_as_an_archive_file_and_refuses_it():
    data = header_flags("v4_rules.kanim", 0)
    with pytest.raises(rd.KanimError):
        rd.parse(data)


def test_an_unknown_major_version_is_refused():
    b = bytearray(vector("v4_rules.kanim"))
    struct.pack_into("<H", b, 8, 5)
    with pytest.raises(rd.KanimError) as e:
        rd.parse(bytes(b))
    assert e.value.status == "unsupported_version"


if __name__ == "__main__":
    sys.exit(pytest.main([__file__, "-q"]))
