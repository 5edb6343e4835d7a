"""A writer of the runtime profile (spec section 9), written from 9.1-9.3's text for the tests
of spec/test-vectors/reference_decoder.py (a test helper, not shipped; not a test module).

It turns an archive-profile file into the runtime profile of the same clip: CLIP as it is,
IMAG built from the clip's keys as 9.2 and 9.3 define it, SKEL and NOTE uncompressed, and the
XXH64. The tests check it against keyanim's runtime vectors byte for byte (v3_* -> v4_*,
v5_* -> v5_*_runtime), and use it for files no vector is: a clip changed before its image is
built (a quaternion track's node after a node without one), an image with a count changed
together with the arrays it sizes.

`image_parts` gives the header and arrays before they are laid out, so that a test can change
one (a count, an entry) and lay the image out again with `image_bytes`.
"""

import importlib.util
import os
import struct
from pathlib import Path

REPO = Path(os.environ.get("KEYANIM_REPO_DIR", Path(__file__).resolve().parent.parent.parent))
VECTORS = REPO / "spec" / "test-vectors"

_spec = importlib.util.spec_from_file_location("reference_decoder", VECTORS / "reference_decoder.py")
rd = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(rd)

ARRAY_ORDER = ["Interpolation", "Tension", "Key_Count", "Curve_Of", "Fixed_Value", "Fixed_Frame", "Fixed_Channels",
               "Curves", "Curve_S", "First_Frame", "Last_Frame", "First_Value", "Last_Value", "Curve_Linear",
               "Curve_Channel", "Quat_Node", "Quat_Column", "Quat_Reference", "Lists", "List_Frames",
               "List_Values", "List_Q", "Record_Offset", "Payload"]
FORMATS = {"Interpolation": "B", "Tension": "f", "Key_Count": "I", "Curve_Of": "I", "Fixed_Value": "f",
           "Fixed_Frame": "I", "Fixed_Channels": "I", "Curves": "qdII", "Curve_S": "f", "First_Frame": "f",
           "Last_Frame": "f", "First_Value": "f", "Last_Value": "f", "Curve_Linear": "I", "Curve_Channel": "I",
           "Quat_Node": "I", "Quat_Column": "I", "Quat_Reference": "f", "Lists": "II",
           "List_Frames": "I", "List_Values": "f", "List_Q": "q", "Record_Offset": "I", "Payload": None}
HEADER = ["Block_Shift", "Curve_Count", "Block_Curve_Count", "Block_Count", "List_Key_Count", "Payload_Size",
          "Quat_Count", "Quat_Track_Count"]


def pack_record(fields_of_curves, mask, wcs):
    """One record (9.3) of a track of one curve or three: Mask, each curve's Value_Bits,
    Context_Bits, the Context, each curve's Base, then each curve's Values, bit-packed from the
    least significant bit; the size rounded up to whole bytes."""
    first = fields_of_curves[0]
    wk, ctx = first["Context_Bits"], first["Context"]
    out = struct.pack("<Q", mask) + bytes(f["Value_Bits"] for f in fields_of_curves) + bytes([wk])
    bits, p = 0, 8 * len(out)
    widths = ([(wk, x) for x in ctx] + [(wc, f["Base"]) for wc, f in zip(wcs, fields_of_curves)] +
              [(f["Value_Bits"], x) for f in fields_of_curves for x in f["Values"]])
    for width, value in widths:
        assert 0 <= value < 1 << width or (width == 0 and value == 0), (width, value)
        bits |= value << p
        p += width
    size = (p + 7) // 8
    return (int.from_bytes(out, "little") | bits).to_bytes(size, "little")


def image_parts(clip, major):
    """(header {name: value}, arrays {name: [entries]}) of the image of `clip` (a dict of
    reference_decoder's decode_archive: frames, q, step, values, interp, tension, quat_nodes,
    frame_count), for Major_Version `major` (4: no quaternion node)."""
    F, C = clip["frame_count"], len(clip["frames"])
    frames, qs, values = clip["frames"], clip["q"], clip["values"]
    n = [len(k) for k in frames]
    blocks_of_f = (F + 63) // 64
    curves = [c for c in range(C) if n[c] >= 2]
    lists = [c for c in curves if 4 * n[c] < blocks_of_f]
    quats = clip["quat_nodes"] if major >= 5 else []  # in node order
    # The quaternion tracks: the quaternion nodes whose x, y, z are block curves, listed first.
    track_quats = [q for q in quats if q["column"] in curves and q["column"] not in lists]
    quats = track_quats + [q for q in quats if q not in track_quats]
    track_x = [q["column"] for q in track_quats]
    T = len(track_x)
    in_tracks = {x + k for x in track_x for k in range(3)}
    # 9.2: the tracks' x's, y's, z's, then the other block curves, then the list curves.
    order = (track_x + [x + 1 for x in track_x] + [x + 2 for x in track_x] +
             [c for c in curves if c not in lists and c not in in_tracks] + lists)
    nc, nb = len(order), len(order) - len(lists)
    L = 4 * ((nc + 3) // 4)
    Q = len(quats)
    LQ = 4 * ((Q + 3) // 4)
    tracks = [[t, T + t, 2 * T + t] for t in range(T)] + [[i] for i in range(3 * T, nb)]
    B = blocks_of_f if nc else 0
    a = {name: [] for name in ARRAY_ORDER}
    a["Interpolation"] = list(clip["interp"])
    a["Tension"] = list(clip["tension"])
    a["Key_Count"] = n
    a["Curve_Of"] = [order.index(c) if c in order else 0xFFFFFFFF for c in range(C)]
    a["Fixed_Value"] = [values[c][0] if n[c] == 1 else 0.0 for c in range(C)]
    a["Fixed_Frame"] = [frames[c][0] if n[c] == 1 else 0 for c in range(C)]
    a["Fixed_Channels"] = [c for c in range(C) if n[c] <= 1]
    for lane in range(L):
        c = order[lane] if lane < nc else None
        if c is not None:
            a["Curves"].append((min(qs[c]), clip["step"][c], (max(qs[c]) - min(qs[c])).bit_length(), 0))
        a["Curve_S"].append(rd.f32(rd.f32(1.0 - clip["tension"][c]) * 0.5) if c is not None else 0.0)
        a["First_Frame"].append(float(frames[c][0]) if c is not None else float("inf"))
        a["Last_Frame"].append(float(frames[c][-1]) if c is not None else float("inf"))
        a["First_Value"].append(values[c][0] if c is not None else 0.0)
        a["Last_Value"].append(values[c][-1] if c is not None else 0.0)
        a["Curve_Linear"].append(0xFFFFFFFF if c is not None and clip["interp"][c] == 1 else 0)
    a["Curve_Channel"] = order
    a["Quat_Node"] = [q["node"] for q in quats]
    a["Quat_Column"] = [q["column"] for q in quats]
    lanes = [rd.reference_lanes(*q["reference"]) for q in quats] + [[0.0, 0.0, 0.0, 1.0]] * (LQ - Q)
    a["Quat_Reference"] = [lanes[j][k] for k in range(4) for j in range(LQ)]  # rx of all, then ry, rz, rw
    first = 0
    for c in lists:
        a["Lists"].append((first, n[c]))
        first += n[c]
        a["List_Frames"] += frames[c]
        a["List_Values"] += values[c]
        a["List_Q"] += qs[c]
    payload = b""
    for b in range(B):
        for t in tracks:
            a["Record_Offset"].append(len(payload))
            chans = [order[i] for i in t]
            mask = sum(1 << (k - 64 * b) for k in frames[chans[0]] if 64 * b <= k < 64 * b + 64)
            fields = [rd.expected_record(frames[c], qs[c], b, min(qs[c])) for c in chans]
            payload += pack_record(fields, mask, [a["Curves"][i][2] for i in t])
    a["Record_Offset"] += [0] * 8
    a["Payload"] = payload + bytes(8)
    header = dict(zip(HEADER, [6, nc, nb, B, len(a["List_Frames"]), len(payload),
                               Q if major >= 5 else 0, T if major >= 5 else 0]))
    return header, a


def image_bytes(header, a):
    """IMAG's content: the header, then every array followed by zero bytes up to a multiple of 8."""
    out = bytearray(struct.pack("<8I", *[header[k] for k in HEADER]))
    for name in ARRAY_ORDER:
        fmt, entries = FORMATS[name], a[name]
        raw = bytes(entries) if fmt is None else b"".join(
            struct.pack("<" + fmt, *(e if isinstance(e, tuple) else (e,))) for e in entries)
        out += raw + bytes(rd.pad8(len(raw)) - len(raw))
    return bytes(out)


def archive_contents(data):
    """{tag: content} of an archive-profile file's sections, decompressed, in table order."""
    major, minor, runtime, count = rd.parse_header(data)
    assert not runtime
    return rd.archive_sections(data, count, major), major, minor


def runtime_file(archive, major=None, change=None, minor=0, extra=(), clip_change=None):
    """The runtime profile of archive-profile file `archive` (9.1): CLIP, IMAG, SKEL, then NOTE
    if it has one, uncompressed, the XXH64 at the end; Major_Version `major` (default: 5 for a
    version 5 file, else 4). clip_change(clip), when given, alters the decoded clip (its keys)
    before the image is built from it (CLIP's counts are the file's: keep them);
    change(header, arrays) alters the image's parts before they are laid out. extra: more
    (tag, flags, content) entries after these."""
    content, archive_major, _ = archive_contents(archive)
    if major is None:
        major = 5 if archive_major >= 5 else 4
    clip = rd.parse(archive)
    if clip_change:
        clip_change(clip)
    header, a = image_parts(clip, major)
    if change:
        change(header, a)
    sections = [("CLIP", 0, content["CLIP"]), ("IMAG", 0, image_bytes(header, a)), ("SKEL", 0, content["SKEL"])]
    if "NOTE" in content:
        sections.append(("NOTE", 2, content["NOTE"]))
    sections += list(extra)
    head = rd.SIGNATURE + struct.pack("<HHIII", major, minor, 1, len(sections), 0)
    table = b"".join(struct.pack("<4sIQQ", tag.encode(), flags, len(body), len(body)) for tag, flags, body in sections)
    body = head + table + b"".join(body for _, _, body in sections)
    return body + struct.pack("<Q", rd.xxh64(body))
