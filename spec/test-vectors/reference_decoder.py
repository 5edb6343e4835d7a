#!/usr/bin/env python3
"""Reference decoder for .kanim 5.0 (both profiles, quaternion nodes: 4.7, and banks: section 10),
4.1, 4.0, 3.0, 2.0 and 1.0 (Appendix E), written from spec/FORMAT.md alone.

It shares no code with the C++ library: it parses the bytes, checks the rules of the spec,
and evaluates Appendix A in binary32 (every operation computed in binary64 and rounded once to
binary32, which gives the correctly rounded binary32 result for + - * /, since 53 >= 2*24 + 2).
A runtime-profile file (section 9) has its keys recovered from IMAG (9.3) after every structure
rule of 9.4, and then its content checked too: the image is rebuilt from the recovered keys and
compared field by field (9.4 lets a decoder skip this; an independent check should not). Its
keys are then evaluated by the same Appendix A code as an archive file's.

Version 5 adds quaternion nodes (4.7): a node's three rotation channels hold the x, y, z of its
rotation relative to a reference, on key frames the three share. Their stored values are
evaluated by Appendix A like any channel's; a vector's JSON then also lists the quaternion nodes
and, at each position, their rotations computed in binary64 from the stored values (4.7).

A bank (section 10) is opened from its header, tables, names and Bank_Checksum (10.1-10.4);
each member is decoded on request (10.5) with the bank's skeleton as its SKEL, and a failure
names the clip and gives offsets from the bank's first byte.

Usage:
  reference_decoder.py FILE.kanim [POSITION ...]   print the values at these frame positions
  reference_decoder.py --write-json DIR            write DIR/NAME.json for every DIR/*.kanim (one
                                                   that exists is left as it is; if its values
                                                   differ, exit status 1)
  reference_decoder.py BANK                        print the bank's clip index as JSON
  reference_decoder.py BANK NAME                   print clip NAME's expected values as JSON, as
                                                   the .json beside a .kanim vector holds them
  reference_decoder.py BANK:NAME [POSITION ...]    clip NAME of the bank as FILE.kanim above (the
                                                   form keyanim's commands read)
Exit status: 0, 1 for a file refused (the status and place on stderr) or no clip of that name,
2 for a usage error.

Needs only the Python standard library, plus either the `zstandard` module or the `zstd`
command-line program for compressed sections (archive profile; a bank's dictionary is given to
either, the program taking it from a temporary file). The XXH64 of the runtime profile and banks
uses the `xxhash` module (Debian: python3-xxhash) when it is installed, else xxh64_pure below,
written from xxHash's specification (same results, slower).
"""
import glob
import json
import math
import os
import struct
import subprocess
import sys
import tempfile
import zlib

SIGNATURE = bytes([0x89, 0x4B, 0x41, 0x4E, 0x0D, 0x0A, 0x1A, 0x0A])
CHANNEL_NAMES = ["Xposition", "Yposition", "Zposition", "Xrotation", "Yrotation", "Zrotation"]
CRITICAL = ["CLIP", "SKEL", "CHAN", "KTIM", "KVAL"]
CRITICAL_V5 = ["CLIP", "SKEL", "QUAT", "CHAN", "KTIM", "KVAL"]  # 3.2.3: QUAT between SKEL and CHAN
QUAT_VERSION = 5  # the first Major_Version with quaternion nodes (4.7)


class KanimError(Exception):
    """status: the failure's name (section 7); offset: the byte of the offending field, where
    known (from the bank's first byte for a bank and its members); clip: (index, name) of the
    bank's member that failed, else None."""

    def __init__(self, status, message, offset=None, clip=None):
        super().__init__(f"{status}: {message}" + ("" if offset is None else f" (at byte {offset})"))
        self.status, self.message, self.offset, self.clip = status, message, offset, clip


def f32(x):
    """Round a Python float (binary64) to the nearest binary32, as a Python float (an overflow
    gives the infinity of its sign, as the rounding of IEEE 754 does)."""
    try:
        return struct.unpack("<f", struct.pack("<f", x))[0]
    except OverflowError:  # struct refuses what rounds beyond the largest binary32
        return math.copysign(math.inf, x)


def f32_bits(x):
    """The binary32 encoding of x (a binary32 value held in a Python float): tells -0 from +0."""
    return struct.unpack("<I", struct.pack("<f", x))[0]


def zstd_decompress(data, dictionary=None):
    """One zstd frame's content; with `dictionary` (a bank's, 10.4) decompressed with it. A frame
    that zstd refuses is zstd_error."""
    try:
        import zstandard  # type: ignore
    except ImportError:
        return zstd_program_decompress(data, dictionary)
    try:
        if dictionary is None:
            return zstandard.ZstdDecompressor().decompress(data)
        return zstandard.ZstdDecompressor(dict_data=zstandard.ZstdCompressionDict(dictionary)).decompress(data)
    except zstandard.ZstdError as e:
        raise KanimError("zstd_error", f"zstd: {e}")


def zstd_program_decompress(data, dictionary):
    """The `zstd` program's decompression (for want of the zstandard module); the dictionary
    goes through a temporary file, removed after."""
    with tempfile.NamedTemporaryFile(prefix="kanim-dict-") as dict_file:
        command = ["zstd", "-d", "-c", "-q"]
        if dictionary is not None:
            dict_file.write(dictionary)
            dict_file.flush()
            command += ["-D", dict_file.name]
        out = subprocess.run(command, input=data, stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    if out.returncode:
        raise KanimError("zstd_error", "zstd: " + out.stderr.decode("utf-8", "replace").strip())
    return out.stdout


def zstd_declared_size(data):
    """Frame_Content_Size from a zstd frame header (RFC 8878 3.1.1.1), or None if absent."""
    if len(data) < 5 or struct.unpack_from("<I", data, 0)[0] != 0xFD2FB528:
        raise KanimError("zstd_error", "not a zstd frame")
    fhd = data[4]
    fcs_flag = fhd >> 6
    single_segment = (fhd >> 5) & 1
    dict_flag = fhd & 3
    pos = 5 + (0 if single_segment else 1) + [0, 1, 2, 4][dict_flag]
    size = [1 if single_segment else 0, 2, 4, 8][fcs_flag]
    if size == 0:
        return None
    raw = int.from_bytes(data[pos:pos + size], "little")
    return raw + 256 if size == 2 else raw


class Reader:
    def __init__(self, data, name):
        self.data, self.pos, self.name = data, 0, name

    def take(self, n):
        if self.pos + n > len(self.data):
            raise KanimError("corrupt", f"{self.name} ends early")
        b = self.data[self.pos:self.pos + n]
        self.pos += n
        return b

    def unpack(self, fmt):
        return struct.unpack("<" + fmt, self.take(struct.calcsize("<" + fmt)))

    def varint(self, max_bytes, bits):
        value = 0
        for i in range(max_bytes):
            b = self.take(1)[0]
            value |= (b & 0x7F) << (7 * i)
            if not b & 0x80:
                if b == 0 and i > 0:
                    raise KanimError("corrupt", "over-long varint")
                if value >> bits:
                    raise KanimError("corrupt", "varint too large")
                return value
        raise KanimError("corrupt", "varint too long")

    def at_end(self):
        return self.pos == len(self.data)


def parse(data, check_content=True):
    """Returns a dict describing the clip; raises KanimError for a file that breaks the spec.
    check_content=False skips the content rules of a runtime-profile file (9.4), as a player
    that samples in place may: only for tests that tell the two classes of rules apart.
    A bank (section 10) is not a clip: open_bank reads it."""
    major, minor, runtime, count = parse_header(data)
    if runtime:
        return parse_runtime(data, major, minor, count, check_content)
    return decode_archive(archive_sections(data, count, major), major, minor, len(data))


MEMBER, BANK = 2, 4  # Header_Flags bits 1 and 2 (version 4.1 on, section 10)


def parse_header(data, member=False):
    """Signature and header (2.1, 2.2): (major, minor, Runtime flag, Section_Count). member:
    the file is a bank's member (10.5.1), whose Member bit must be set; a file by itself must
    have it clear. Offsets are from the file's (the member's) first byte."""
    if data[:min(8, len(data))] != SIGNATURE[:min(8, len(data))]:
        raise KanimError("bad_signature", "signature", 0)
    if len(data) < 24:
        raise KanimError("truncated", "header", len(data))
    major, minor, header_flags, count, reserved = struct.unpack_from("<HHIII", data, 8)
    if major not in (1, 2, 3, 4, 5):
        raise KanimError("unsupported_version", f"major {major}", 8)
    # Versions 4 and 5: bit 0 Runtime (section 9), bits 1 Member and 2 Bank (4.1, section 10);
    # before version 4 all three are reserved, and bits 3-15 always are.
    if header_flags & (0xFFF8 if major >= 4 else 0xFFFF):
        raise KanimError("reserved_bits_set", "header: Header_Flags", 12)
    if header_flags & BANK:
        raise KanimError("corrupt", "header: Header_Flags has Bank set: a bank (section 10), not a clip", 12)
    if member and not header_flags & MEMBER:
        raise KanimError("corrupt", "header: a bank's member without the Member bit (10.5.1)", 12)
    if not member and header_flags & MEMBER:
        raise KanimError("corrupt", "header: Member set in a file read by itself (10.5.1)", 12)
    if reserved:
        raise KanimError("reserved_bits_set", "header: Header_Reserved", 20)
    return major, minor, bool(header_flags & 1), count


# Section 8: a key takes at least a third of a byte of a version 5 KTIM (a quaternion node's three
# keys at a frame share one varint), and a zstd frame makes at most 32768 bytes of each byte.
KEYS_PER_FILE_BYTE_V5 = 3 * 32768


def parse_clip(clip, file_size=None):
    """CLIP (4.1): (F, N, C, Tangent_Rule, Frame_Time, K). file_size: the bytes of a version 5
    archive file (or member), whose K section 8 bounds by them as soon as it is read, before
    anything it sizes (versions 1 to 4 are read as before, without that bound)."""
    if len(clip) != 32:
        raise KanimError("corrupt", "CLIP size")
    F, N, C, rule, clip_flags, clip_reserved, frame_time, K = struct.unpack("<IIIBBHdQ", clip)
    if rule > 1 or clip_flags or clip_reserved:
        raise KanimError("reserved_bits_set", "CLIP")
    if not math.isfinite(frame_time) or frame_time < 0 or (F > 1 and not frame_time > 0):
        raise KanimError("corrupt", "Frame_Time")
    if file_size is not None and K > KEYS_PER_FILE_BYTE_V5 * file_size:  # fields in order (section 7)
        raise KanimError("corrupt", f"CLIP: Key_Count {K} > 98304 x the file's {file_size} bytes (section 8): "
                         "more keys than KTIM can hold")
    if K > C * F:
        raise KanimError("corrupt", "Key_Count")
    return F, N, C, rule, frame_time, K


def parse_skel(skel, N, C):
    """SKEL (4.2): the nodes, checked against N and C."""
    r = Reader(skel, "SKEL")
    nodes = []
    channel_total = 0
    for i in range(N):
        (name_len,) = r.unpack("I")
        name = r.take(name_len).decode("utf-8", errors="surrogateescape")
        (parent,) = r.unpack("i")
        offset = list(r.unpack("3d"))
        node_flags, n_ch = r.unpack("BB")
        types = list(r.take(n_ch))
        end_site = bool(node_flags & 1)
        if node_flags & 0xFE or any(t > 5 for t in types):
            raise KanimError("reserved_bits_set", f"node {i}")
        if not (parent == -1 or 0 <= parent < i) or (parent >= 0 and nodes[parent]["end_site"]):
            raise KanimError("corrupt", f"node {i} parent")
        if not all(math.isfinite(o) for o in offset) or n_ch > 6:
            raise KanimError("corrupt", f"node {i}")
        if end_site and (n_ch != 0 or parent < 0):
            raise KanimError("corrupt", f"node {i} End Site")
        nodes.append({"name": name, "parent": parent, "end_site": end_site, "offset": offset,
                      "channels": [CHANNEL_NAMES[t] for t in types]})
        channel_total += n_ch
    if not r.at_end() or channel_total != C:
        raise KanimError("corrupt", "SKEL")
    return nodes


# ---- Quaternion nodes (version 5, 4.7): the archive profile's QUAT, the runtime profile's
# Quat_Node, and the rotation a node's stored x, y, z make.

def quat_node_columns(nodes, quat_nodes, where, increasing=True):
    """4.7's rules on the listed nodes against SKEL: each < N with exactly three rotation
    channels, consecutive in its channel list, one about each of X, Y and Z, and (increasing)
    strictly increasing, as QUAT lists them (IMAG orders them otherwise: check_quat_node_order).
    Returns each node's stored x: the frame column of its first rotation channel (stored y and
    z are the next two, whatever axes the three are about)."""
    first, total = [], 0
    for node in nodes:
        first.append(total)
        total += len(node["channels"])
    columns = []
    for j, n in enumerate(quat_nodes):
        if n >= len(nodes):
            raise KanimError("corrupt", f"{where}: entry {j}: Node {n} not < Node_Count {len(nodes)} (4.7)")
        if increasing and j and n <= quat_nodes[j - 1]:
            raise KanimError("corrupt", f"{where}: entry {j}: Node {n} not above the entry before (4.7)")
        types = nodes[n]["channels"]
        rotations = [k for k, t in enumerate(types) if t.endswith("rotation")]
        if (len(rotations) != 3 or rotations[2] - rotations[0] != 2 or
                sorted(types[k][0] for k in rotations) != ["X", "Y", "Z"]):
            raise KanimError("corrupt", f"{where}: entry {j}: node {n}'s channels {types} are not three consecutive "
                             "rotation channels about X, Y and Z (4.7)")
        columns.append(first[n] + rotations[0])
    return columns


def check_reference(X, Y, Z, where):
    """4.7: a reference of three int16 lies in the unit ball of 2^15."""
    if X * X + Y * Y + Z * Z > 2 ** 30:
        raise KanimError("corrupt", f"{where}: Reference ({X}, {Y}, {Z}) has X^2 + Y^2 + Z^2 > 2^30 (4.7)")


def parse_quat(quat, nodes):
    """QUAT (4.7): [{node, reference: [X, Y, Z], column: its stored x's channel}], after its
    size, its nodes against SKEL and its references."""
    N = len(nodes)
    if len(quat) < 4:
        raise KanimError("corrupt", "QUAT: shorter than Quat_Count")
    (Q,) = struct.unpack_from("<I", quat, 0)
    if Q > N:
        raise KanimError("corrupt", f"QUAT: Quat_Count {Q} > Node_Count {N}")
    if len(quat) != 4 + 10 * Q:
        raise KanimError("corrupt", f"QUAT: Raw_Size {len(quat)} != 4 + 10 x Quat_Count {Q}")
    entries = [struct.unpack_from("<I3h", quat, 4 + 10 * j) for j in range(Q)]
    columns = quat_node_columns(nodes, [e[0] for e in entries], "QUAT")
    for j, (node, X, Y, Z) in enumerate(entries):
        check_reference(X, Y, Z, f"QUAT: entry {j}")
    return [{"node": e[0], "reference": list(e[1:]), "column": c} for e, c in zip(entries, columns)]


def reference_lanes(X, Y, Z):
    """9.2's Quat_Reference lanes of reference (X, Y, Z): rx, ry, rz exact in binary32, and rw
    the binary64 square root rounded to binary32."""
    return [f32(X * 2.0 ** -15), f32(Y * 2.0 ** -15), f32(Z * 2.0 ** -15),
            f32(math.sqrt(1.0 - (X * X + Y * Y + Z * Z) * 2.0 ** -30))]


def hamilton(a, b):
    """The Hamilton product a b of quaternions written (x, y, z, w), as 4.7 spells it out."""
    ax, ay, az, aw = a
    bx, by, bz, bw = b
    return (aw * bx + ax * bw + ay * bz - az * by,
            aw * by - ax * bz + ay * bw + az * bx,
            aw * bz + ax * by - ay * bx + az * bw,
            aw * bw - ax * bx - ay * by - az * bz)


def check_stored_bound(values, quats):
    """4.7: every key of a quaternion node's stored x, y, z within +-16 (values: per channel)."""
    for quat in quats:
        for c in range(quat["column"], quat["column"] + 3):
            if any(abs(v) > 16 for v in values[c]):
                raise KanimError("corrupt", f"channel {c}: a quaternion node's stored value beyond +-16")


def quat_rotation(reference, sx, sy, sz):
    """4.7: the rotation (x, y, z, w) of a quaternion node with this reference (X, Y, Z) and
    stored values sx, sy, sz (binary32), in binary64: r (s, w) normalized. The stored values
    are exact; the spec leaves the precision of the rest to the decoder."""
    X, Y, Z = reference
    r = (X * 2.0 ** -15, Y * 2.0 ** -15, Z * 2.0 ** -15, math.sqrt(1.0 - (X * X + Y * Y + Z * Z) * 2.0 ** -30))
    w = math.sqrt(max(0.0, 1.0 - (sx * sx + sy * sy + sz * sz)))
    q = hamilton(r, (sx, sy, sz, w))
    norm = math.sqrt(sum(x * x for x in q))  # >= 1 - rounding: |r| = 1, |(s, w)| >= 1
    return [x / norm for x in q]


def archive_sections(data, count, major, member=False, dictionary=None):
    """Rules 3.1-3.3 on an archive-profile file's table, sizes and CRC-32: {tag: content} of
    the known sections, decompressed (with a bank's dictionary, 10.4). major: the file's
    Major_Version (version 5 has QUAT, an unknown critical tag before). member: a bank's
    member, whose table holds no SKEL (10.5.2)."""
    critical = CRITICAL_V5 if major >= QUAT_VERSION else CRITICAL
    if len(data) < 24 + 24 * count + 4:
        raise KanimError("truncated", "table")
    sections = []
    pos = 24 + 24 * count
    for i in range(count):
        tag, flags, stored, raw = struct.unpack_from("<4sIQQ", data, 24 + 24 * i)
        tag = tag.decode("latin-1")
        if flags & 0xFFFC:
            raise KanimError("reserved_bits_set", f"table entry {i}: section flags", 28 + 24 * i)
        sections.append((tag, flags, data[pos:pos + stored], raw))
        pos += stored
    if len(data) < pos + 4:
        raise KanimError("truncated", "sections", len(data))
    if len(data) > pos + 4:
        raise KanimError("trailing_bytes", "after checksum", pos + 4)
    if zlib.crc32(data[:pos]) != struct.unpack_from("<I", data, pos)[0]:
        raise KanimError("checksum_mismatch", "crc", pos)

    content = {}
    critical_seen = []
    for tag, flags, stored, raw in sections:
        ancillary = bool(flags & 2)
        if member and tag == "SKEL":
            raise KanimError("corrupt", "a SKEL section in a bank's member (10.5.2)")
        if tag in critical:
            if ancillary:
                raise KanimError("corrupt", f"{tag} marked ancillary")
            critical_seen.append(tag)
        elif tag == "NOTE":
            if not ancillary or "NOTE" in content:
                raise KanimError("corrupt", "NOTE")
        elif not ancillary:
            raise KanimError("reserved_bits_set", f"unknown critical section {tag}")
        else:
            continue  # unknown ancillary: skipped
        if flags & 1:
            declared = zstd_declared_size(stored)
            if declared is None or declared != raw:
                raise KanimError("zstd_error", f"{tag}: content size")
            body = zstd_decompress(stored, dictionary)
            if len(body) != raw:
                raise KanimError("zstd_error", f"{tag}: decompressed size")
        else:
            if len(stored) != raw:
                raise KanimError("corrupt", f"{tag}: raw size")
            body = stored
        content[tag] = body
    if critical_seen != [t for t in critical if not (member and t == "SKEL")]:
        raise KanimError("corrupt", f"critical sections {critical_seen}")
    return content


def decode_archive(content, major, minor, file_size):
    """The archive profile's sections (4.1-4.7, 5): versions 1 to 3, 4 with Runtime clear
    (laid out as 3.0), and 5 (3.0's layout, with QUAT and the key frames a quaternion node's
    x, y, z share). content: {tag: content}, SKEL's being a bank's skeleton for a member;
    file_size: the file's (the member's) bytes."""
    layout = min(major, 3)  # 4.0's and 5.0's archive profile have 3.0's bytes (sections 4.3-4.5, 9)
    v5 = major >= QUAT_VERSION
    F, N, C, rule, frame_time, K = parse_clip(content["CLIP"], file_size if v5 else None)
    nodes = parse_skel(content["SKEL"], N, C)
    quats = parse_quat(content["QUAT"], nodes) if v5 else []
    # Each quaternion node's stored y and z take the key frames of its stored x (4.4).
    shares_frames_of = {}
    for quat in quats:
        shares_frames_of[quat["column"] + 1] = shares_frames_of[quat["column"] + 2] = quat["column"]

    # CHAN
    chan = content["CHAN"]
    if len(chan) != {1: 17, 2: 18, 3: 19}[layout] * C:
        raise KanimError("corrupt", "CHAN size")
    # Value_Coding (2.0 on): 0 delta, 1 extrapolate; version 1 has only deltas.
    coding = list(chan[17 * C:18 * C]) if layout >= 2 else [0] * C
    # Residual_Bytes (3.0): bytes of each zigzag residual in KVAL.
    residual_bytes = list(chan[18 * C:19 * C]) if layout == 3 else None
    interp = list(chan[:C])
    tension = list(struct.unpack_from(f"<{C}f", chan, C))
    step = list(struct.unpack_from(f"<{C}d", chan, 5 * C))
    key_count = list(struct.unpack_from(f"<{C}I", chan, 13 * C))
    for c in range(C):
        if interp[c] > 1:
            raise KanimError("reserved_bits_set", f"channel {c} interpolation")
        if not (math.isfinite(tension[c]) and -1 <= tension[c] <= 1):
            raise KanimError("corrupt", f"channel {c} tension")
        if not (math.isfinite(step[c]) and step[c] > 0):
            raise KanimError("corrupt", f"channel {c} step")
        if key_count[c] > F:
            raise KanimError("corrupt", f"channel {c} key count")
        if coding[c] > 1:
            raise KanimError("reserved_bits_set", f"channel {c} value coding")
        if residual_bytes is not None and (residual_bytes[c] > 8 or (key_count[c] == 0 and residual_bytes[c])):
            raise KanimError("corrupt", f"channel {c} residual bytes")
    for j, quat in enumerate(quats):  # 4.3: one Interpolation, Tension (bits) and Key_Count for x, y, z
        x = quat["column"]
        for c in (x + 1, x + 2):
            if (interp[c], f32_bits(tension[c]), key_count[c]) != (interp[x], f32_bits(tension[x]), key_count[x]):
                raise KanimError("corrupt", f"CHAN: quaternion node {quat['node']} (QUAT entry {j}): channel {c}'s "
                                 f"Interpolation, Tension or Key_Count is not its stored x's (channel {x}'s) (4.3)")
    if sum(key_count) != K:
        raise KanimError("corrupt", "Key_Count sum")

    # KTIM
    r = Reader(content["KTIM"], "KTIM")
    frames = []
    for c in range(C):
        if c in shares_frames_of:  # no varints: a quaternion node's y and z (4.4)
            frames.append(list(frames[shares_frames_of[c]]))
            continue
        fr = []
        for i in range(key_count[c]):
            v = r.varint(5, 32)
            fr.append(v if i == 0 else fr[-1] + v + 1)
            if fr[-1] >= F:
                raise KanimError("corrupt", f"channel {c} key frame")
        frames.append(fr)
    if not r.at_end():
        raise KanimError("corrupt", "KTIM size")

    kval = content["KVAL"]
    if layout == 3:
        # KVAL (3.0): plane k holds byte k (little-endian) of every zigzag residual of the
        # channels whose Residual_Bytes exceed k, channel after channel, key after key.
        sizes = [sum(key_count[c] for c in range(C) if residual_bytes[c] > k) for k in range(8)]
        if sum(sizes) != len(kval):
            raise KanimError("corrupt", "KVAL size")
        starts = [sum(sizes[:k]) for k in range(8)]
        cursor = list(starts)

        def next_residual(c):
            value = 0
            for k in range(residual_bytes[c]):
                value |= kval[cursor[k]] << (8 * k)
                cursor[k] += 1
            return value
    else:
        # KVAL (1.0, 2.0): Plane_Count, Plane_Size[], planes; byte k of each varint from plane k.
        if len(kval) < 1 or kval[0] > 10:
            raise KanimError("corrupt", "Plane_Count")
        P = kval[0]
        if (P == 0) != (K == 0) or len(kval) < 1 + 4 * P:
            raise KanimError("corrupt", "KVAL planes")
        sizes = list(struct.unpack_from(f"<{P}I", kval, 1))
        if 1 + 4 * P + sum(sizes) != len(kval) or 0 in sizes or (P and sizes[0] != K):
            raise KanimError("corrupt", "KVAL plane sizes")
        planes, at = [], 1 + 4 * P
        for size in sizes:
            planes.append(Reader(kval[at:at + size], "KVAL plane"))
            at += size

        def next_residual(c):
            value = 0
            for k in range(10):
                if k >= P:
                    raise KanimError("corrupt", "varint past the last plane")
                b = planes[k].take(1)[0]
                value |= (b & 0x7F) << (7 * k)
                if not b & 0x80:
                    if b == 0 and k > 0:
                        raise KanimError("corrupt", "over-long varint")
                    if value >> 64:
                        raise KanimError("corrupt", "varint too large")
                    return value
            raise KanimError("corrupt", "varint too long")

    def prediction(c, qs, i):
        """pred_i of section 4.5, in Python's exact integers (// is the floor)."""
        if i == 0:
            return 0
        if i == 1 or coding[c] == 0:
            return qs[i - 1]
        k = frames[c]
        d, g0, g1 = qs[i - 1] - qs[i - 2], k[i - 1] - k[i - 2], k[i] - k[i - 1]
        if abs(d) < 2 ** 40 and g0 < 2 ** 16 and g1 < 2 ** 16:
            return qs[i - 1] + (2 * d * g1 + g0) // (2 * g0)
        return qs[i - 1] + d

    values, quantized = [], []
    for c in range(C):
        qs, vals = [], []
        for i in range(key_count[c]):
            u = next_residual(c)
            r = (u >> 1) if u % 2 == 0 else -((u + 1) >> 1)
            if abs(r) > (2 ** 57 if layout >= 2 else 2 ** 54):
                raise KanimError("corrupt", f"channel {c} residual")
            q = prediction(c, qs, i) + r
            qs.append(q)
            if abs(q) > 2 ** 53:
                raise KanimError("corrupt", f"channel {c} |q|")
            v = f32(float(q) * step[c])  # binary64 product, one rounding to binary32
            if not math.isfinite(v):
                raise KanimError("corrupt", f"channel {c} value")
            vals.append(v)
        values.append(vals)
        quantized.append(qs)
    if layout < 3 and not all(p.at_end() for p in planes):
        raise KanimError("corrupt", "KVAL plane bytes left over")
    check_stored_bound(values, quats)

    return {"version": (major, minor), "frame_count": F, "frame_time": frame_time, "tangent_rule": rule,
            "nodes": nodes, "interp": interp, "tension": tension, "frames": frames, "values": values,
            "q": quantized, "step": step, "quat_nodes": quats,
            "notes": content.get("NOTE", b"").decode("utf-8", errors="surrogateescape")}


# ---------------------------------------------------------------------------------------------
# The runtime profile (section 9): CLIP, IMAG, SKEL, NOTE uncompressed, XXH64 at the end.

XXH_P1, XXH_P2, XXH_P3 = 0x9E3779B185EBCA87, 0xC2B2AE3D27D4EB4F, 0x165667B19E3779F9
XXH_P4, XXH_P5 = 0x85EBCA77C2B2AE63, 0x27D4EB2F165667C5
U64 = (1 << 64) - 1


def _rotl64(x, r):
    return ((x << r) | (x >> (64 - r))) & U64


def _xxh64_round(acc, lane):
    return (_rotl64((acc + lane * XXH_P2) & U64, 31) * XXH_P1) & U64


def xxh64_pure(data, seed=0):
    """XXH64 written from xxHash's doc/xxhash_spec.md (stripes of 4 lanes, merge, tail,
    avalanche), in Python's integers masked to 64 bits."""
    n, p = len(data), 0
    if n >= 32:
        v = [(seed + XXH_P1 + XXH_P2) & U64, (seed + XXH_P2) & U64, seed & U64, (seed - XXH_P1) & U64]
        while p + 32 <= n:
            lanes = struct.unpack_from("<4Q", data, p)
            v = [_xxh64_round(v[i], lanes[i]) for i in range(4)]
            p += 32
        acc = (_rotl64(v[0], 1) + _rotl64(v[1], 7) + _rotl64(v[2], 12) + _rotl64(v[3], 18)) & U64
        for lane in v:
            acc = ((acc ^ _xxh64_round(0, lane)) * XXH_P1 + XXH_P4) & U64
    else:
        acc = (seed + XXH_P5) & U64
    acc = (acc + n) & U64
    while p + 8 <= n:
        acc ^= _xxh64_round(0, struct.unpack_from("<Q", data, p)[0])
        acc = (_rotl64(acc, 27) * XXH_P1 + XXH_P4) & U64
        p += 8
    if p + 4 <= n:
        acc ^= (struct.unpack_from("<I", data, p)[0] * XXH_P1) & U64
        acc = (_rotl64(acc, 23) * XXH_P2 + XXH_P3) & U64
        p += 4
    while p < n:
        acc ^= (data[p] * XXH_P5) & U64
        acc = (_rotl64(acc, 11) * XXH_P1) & U64
        p += 1
    acc = ((acc ^ (acc >> 33)) * XXH_P2) & U64
    acc = ((acc ^ (acc >> 29)) * XXH_P3) & U64
    return acc ^ (acc >> 32)


def xxh64(data):
    """XXH64, seed 0: the `xxhash` module when it is installed (faster), else xxh64_pure."""
    try:
        import xxhash  # type: ignore
    except ImportError:
        return xxh64_pure(data)
    return xxhash.xxh64(data).intdigest()


RUNTIME_SECTIONS = ["CLIP", "IMAG", "SKEL"]


def runtime_sections(data, count, major, member=False):
    """Rules 3.1 and 9.1 on the table: CLIP, IMAG, SKEL at entries 0-2, then at most one NOTE
    (ancillary) and unknown ancillary sections, in any order; nothing compressed; the XXH64 at
    the end. Returns {tag: content} of the known sections. major: the file's Major_Version (in
    version 5 a QUAT section is refused as CHAN is, 9.1.2; before, it is an unknown tag).
    member: a bank's member, whose table has CLIP and IMAG only at entries 0-1 and no SKEL
    anywhere (10.5.2)."""
    if len(data) < 24 + 24 * count + 8:
        raise KanimError("truncated", "table")
    fixed = RUNTIME_SECTIONS[:2] if member else RUNTIME_SECTIONS
    refused = RUNTIME_SECTIONS + (CRITICAL_V5 if major >= QUAT_VERSION else CRITICAL)
    entries = [struct.unpack_from("<4sIQQ", data, 24 + 24 * i) for i in range(count)]
    tags = [e[0].decode("latin-1") for e in entries]
    for i, (_, flags, stored, raw) in enumerate(entries):
        tag, ancillary, at = tags[i], bool(flags & 2), 24 + 24 * i
        if flags & 0xFFFC:
            raise KanimError("reserved_bits_set", f"table entry {i}: section flags", at + 4)
        if member and tag == "SKEL":
            raise KanimError("corrupt", f"table entry {i}: a SKEL section in a bank's member (10.5.2)", at)
        if i < len(fixed) and (tag != fixed[i] or ancillary):
            raise KanimError("corrupt", f"table entry {i}: must be {fixed[i]}, critical (9.1)", at)
        if i >= len(fixed) and tag == "NOTE" and (not ancillary or tag in tags[len(fixed):i]):
            raise KanimError("corrupt", f"table entry {i}: NOTE must be ancillary, and appear once (9.1)", at)
        if i >= len(fixed) and tag in refused:
            raise KanimError("corrupt", f"table entry {i}: {tag} in a runtime-profile file (9.1)", at)
        if i >= len(fixed) and tag != "NOTE" and not ancillary:
            raise KanimError("reserved_bits_set", f"table entry {i}: unknown critical section {tag}", at)
        if flags & 1:
            raise KanimError("corrupt", f"table entry {i}: {tag} compressed (9.1)", at + 4)
        if raw != stored:
            raise KanimError("corrupt", f"table entry {i}: {tag} Raw_Size != Stored_Size", at + 16)
    if count < len(fixed):
        raise KanimError("corrupt", f"table: fewer than {', '.join(fixed)} (9.1)", 16)
    end = 24 + 24 * count + sum(e[2] for e in entries)
    if len(data) < end + 8:
        raise KanimError("truncated", "sections", len(data))
    if len(data) > end + 8:
        raise KanimError("trailing_bytes", "after checksum", end + 8)
    if xxh64(data[:end]) != struct.unpack_from("<Q", data, end)[0]:
        raise KanimError("checksum_mismatch", "XXH64", end)
    content, pos = {}, 24 + 24 * count
    for tag, (_, _, stored, _) in zip(tags, entries):
        if tag in RUNTIME_SECTIONS + ["NOTE"]:  # the unknown ancillary sections are skipped
            content[tag] = data[pos:pos + stored]
        pos += stored
    return content


def parse_runtime(data, major, minor, count, check_content=True):
    """A runtime-profile file (section 9): its keys recovered from IMAG, structure and content
    checked (9.4), in the same dict as decode_archive's."""
    return decode_runtime(runtime_sections(data, count, major), major, minor, check_content)


def decode_runtime(content, major, minor, check_content=True):
    """The runtime profile's sections (9.2-9.4). content: {tag: content}, SKEL's being a bank's
    skeleton for a member."""
    F, N, C, rule, frame_time, K = parse_clip(content["CLIP"])
    # Version 5 checks IMAG's quaternion nodes against SKEL, so reads SKEL first (9.4); version
    # 4 keeps the table's order (CLIP, IMAG, SKEL), as before.
    nodes = parse_skel(content["SKEL"], N, C) if major >= QUAT_VERSION else None
    image = parse_image(content["IMAG"], F, C, K, major, nodes)
    if check_content:
        check_image_content(image)
        check_stored_bound(image["values"], image["quat_nodes"])
    if nodes is None:
        nodes = parse_skel(content["SKEL"], N, C)
    return {"version": (major, minor), "frame_count": F, "frame_time": frame_time, "tangent_rule": rule,
            "nodes": nodes, "interp": image["interp"], "tension": image["tension"],
            "frames": image["frames"], "values": image["values"],
            # In node order, as QUAT lists them (IMAG lists the quaternion tracks' nodes first):
            # the clip's facts do not depend on its profile.
            "quat_nodes": sorted(image["quat_nodes"], key=lambda quat: quat["node"]),
            "notes": content.get("NOTE", b"").decode("utf-8", errors="surrogateescape")}


# ---- IMAG (9.2): header and arrays.

def pad8(n):
    return (n + 7) // 8 * 8


def image_header(body, F, C, N, major):
    """IMAG's 32-byte header: the counts that size its arrays (9.2). Quat_Track_Count (T) sizes
    Record_Offset as declared (R = B x (nb - 2T)); that it counts the quaternion nodes whose
    curves are block curves is checked with the quaternion nodes (check_quat_node_order)."""
    if len(body) < 32:
        raise KanimError("corrupt", "IMAG: header")
    shift, nc, nb, B, M, P, Q, T = struct.unpack_from("<8I", body, 0)
    if shift != 6:
        raise KanimError("corrupt", "IMAG: Block_Shift")
    if nc > C:
        raise KanimError("corrupt", "IMAG: Curve_Count")
    if nb > nc:
        raise KanimError("corrupt", "IMAG: Block_Curve_Count")
    if B != ((F + 63) // 64 if nc else 0):
        raise KanimError("corrupt", "IMAG: Block_Count")
    if major < QUAT_VERSION and (Q or T):  # version 4's Image_Reserved
        raise KanimError("reserved_bits_set", "IMAG: Image_Reserved")
    if major >= QUAT_VERSION and Q > N:
        raise KanimError("corrupt", f"IMAG: Quat_Count {Q} > Node_Count {N}")
    # T of the Q nodes have three block curves each: checked here only as far as the sizes
    # need (nt = nb - 2T is a count), against the nodes themselves later.
    if T > Q or 3 * T > nb:
        raise KanimError("corrupt", f"IMAG: Quat_Track_Count {T} > Quat_Count {Q} or 3 x {T} > Block_Curve_Count {nb}")
    nt = nb - 2 * T  # every quaternion track's three block curves one track, every other one its own
    return {"nc": nc, "nb": nb, "nl": nc - nb, "B": B, "M": M, "P": P, "L": 4 * ((nc + 3) // 4),
            "X": C - nc, "Q": Q, "LQ": 4 * ((Q + 3) // 4), "T": T, "nt": nt, "R": B * nt, "F": F, "C": C}


def image_array_specs(h):
    """(name, struct format of one entry, entries) of IMAG's arrays, in file order (9.2); the
    quaternion nodes' arrays are empty in version 4 (Q = 0)."""
    C, L, nc, M, Q = h["C"], h["L"], h["nc"], h["M"], h["Q"]
    return [("Interpolation", "B", C), ("Tension", "f", C), ("Key_Count", "I", C),
            ("Curve_Of", "I", C), ("Fixed_Value", "f", C), ("Fixed_Frame", "I", C),
            ("Fixed_Channels", "I", h["X"]), ("Curves", "qdII", nc), ("Curve_S", "f", L),
            ("First_Frame", "f", L), ("Last_Frame", "f", L), ("First_Value", "f", L),
            ("Last_Value", "f", L), ("Curve_Linear", "I", L), ("Curve_Channel", "I", nc),
            ("Quat_Node", "I", Q), ("Quat_Column", "I", Q), ("Quat_Reference", "f", 4 * h["LQ"]),
            ("Lists", "II", h["nl"]), ("List_Frames", "I", M), ("List_Values", "f", M),
            ("List_Q", "q", M), ("Record_Offset", "I", h["R"] + 8), ("Payload", None, h["P"] + 8)]


def image_arrays(body, h):
    """Every array of IMAG, after checking Raw_Size and every Pad byte. Float arrays are read
    twice: as values, and as their bits under NAME_bits (to compare -0 and +0 exactly)."""
    specs = image_array_specs(h)
    sizes = [struct.calcsize("<" + fmt) * n if fmt else n for _, fmt, n in specs]
    if len(body) != 32 + sum(pad8(s) for s in sizes):
        raise KanimError("corrupt", "IMAG: Raw_Size against the arrays' sizes")
    a, pos = {}, 32
    for (name, fmt, n), size in zip(specs, sizes):
        if any(body[pos + size:pos + pad8(size)]):
            raise KanimError("corrupt", f"IMAG: {name}'s Pad")
        raw = body[pos:pos + size]
        if fmt is None:
            a[name] = raw
        else:
            flat = struct.unpack("<" + fmt * n, raw) if n else ()
            a[name] = [flat[i:i + len(fmt)] for i in range(0, len(flat), len(fmt))] if len(fmt) > 1 else list(flat)
            if fmt == "f":
                a[name + "_bits"] = list(struct.unpack(f"<{n}I", raw))
        pos += pad8(size)
    return a


# ---- IMAG (9.2): the rules of its tables.

def check_channel_values(a, h, K):
    """The per-channel facts of 9.2: Interpolation, Tension, Key_Count and its sum."""
    F, C, n = h["F"], h["C"], a["Key_Count"]
    for c in range(C):
        if a["Interpolation"][c] > 1:
            raise KanimError("reserved_bits_set", f"IMAG: Interpolation[{c}]")
    for c in range(C):
        t = a["Tension"][c]
        if not (math.isfinite(t) and -1 <= t <= 1):
            raise KanimError("corrupt", f"IMAG: Tension[{c}]")
    for c in range(C):
        if n[c] > F:
            raise KanimError("corrupt", f"IMAG: Key_Count[{c}] > Frame_Count")
    if sum(n) != K:
        raise KanimError("corrupt", "IMAG: Key_Count sum != CLIP's Key_Count")


def is_block_curve(a, h, c):
    """9.2: a curve (n_c >= 2) with at least a quarter as many keys as blocks."""
    n = a["Key_Count"][c]
    return n >= 2 and not 4 * n < (h["F"] + 63) // 64


def check_channel_arrays(a, h, quats):
    """Which channels are block curves, list curves, fixed (9.2), and the curves' order: the
    quaternion tracks' x's, y's, z's (quats: the checked quaternion nodes, tracks first), then
    the other block curves, then the list curves, each in increasing channel order. Returns
    the block tracks' curves (9.2: nt of them)."""
    C, n = h["C"], a["Key_Count"]
    curves = [c for c in range(C) if n[c] >= 2]
    lists = [c for c in curves if not is_block_curve(a, h, c)]
    track_x = [quat["column"] for quat in quats if is_block_curve(a, h, quat["column"])]
    in_tracks = {x + k for x in track_x for k in range(3)}
    order = ([x for x in track_x] + [x + 1 for x in track_x] + [x + 2 for x in track_x] +
             [c for c in curves if c not in lists and c not in in_tracks] + lists)
    if len(curves) != h["nc"] or len(order) - len(lists) != h["nb"]:
        raise KanimError("corrupt", "IMAG: Curve_Count or Block_Curve_Count against Key_Count")
    curve_of = [0xFFFFFFFF] * C
    for i, c in enumerate(order):
        curve_of[c] = i
    for c in range(C):
        if a["Curve_Of"][c] != curve_of[c]:
            raise KanimError("corrupt", f"IMAG: Curve_Of[{c}]")
    for c in range(C):
        one = n[c] == 1
        if one and not math.isfinite(a["Fixed_Value"][c]) or not one and a["Fixed_Value_bits"][c] != 0:
            raise KanimError("corrupt", f"IMAG: Fixed_Value[{c}]")
        if one and a["Fixed_Frame"][c] >= h["F"] or not one and a["Fixed_Frame"][c] != 0:
            raise KanimError("corrupt", f"IMAG: Fixed_Frame[{c}]")
    if a["Fixed_Channels"] != [c for c in range(C) if n[c] <= 1]:
        raise KanimError("corrupt", "IMAG: Fixed_Channels")
    if a["Curve_Channel"] != order:
        raise KanimError("corrupt", "IMAG: Curve_Channel")
    T = len(track_x)  # track t: curves t, T + t, 2T + t; then each other block curve alone
    return [[t, T + t, 2 * T + t] for t in range(T)] + [[i] for i in range(3 * T, h["nb"])]


INF32_BITS = 0x7F800000


def check_curve_arrays(a, h):
    """Curves and the per-curve lanes (9.2), apart from what the keys fix (First_*, Last_*)."""
    nc = h["nc"]
    for i in range(nc):
        q_base, step, base_bits, reserved = a["Curves"][i]
        if abs(q_base) > 2 ** 53:
            raise KanimError("corrupt", f"IMAG: Curves[{i}].Q_Base")
        if not (math.isfinite(step) and step > 0):
            raise KanimError("corrupt", f"IMAG: Curves[{i}].Step")
        if base_bits > 55:
            raise KanimError("corrupt", f"IMAG: Curves[{i}].Base_Bits")
        if reserved:
            raise KanimError("reserved_bits_set", f"IMAG: Curves[{i}].Curve_Reserved")
    for i in range(h["L"]):
        c = a["Curve_Channel"][i] if i < nc else None
        s = f32(f32(1.0 - a["Tension"][c]) * 0.5) if i < nc else 0.0
        if a["Curve_S_bits"][i] != f32_bits(s):
            raise KanimError("corrupt", f"IMAG: Curve_S[{i}]")
        if i >= nc and (a["First_Frame_bits"][i] != INF32_BITS or a["Last_Frame_bits"][i] != INF32_BITS or
                        a["First_Value_bits"][i] or a["Last_Value_bits"][i]):
            raise KanimError("corrupt", f"IMAG: padding lane {i} of First/Last_Frame/Value")
        linear = 0xFFFFFFFF if i < nc and a["Interpolation"][c] == 1 else 0
        if a["Curve_Linear"][i] != linear:
            raise KanimError("corrupt", f"IMAG: Curve_Linear[{i}]")


ONE32_BITS = 0x3F800000


def check_quat_arrays(a, h, nodes):
    """Version 5: Quat_Node against SKEL (4.7), Quat_Column, Quat_Reference's lanes (and its
    padding lanes (0, 0, 0, 1)), each quaternion node's stored x, y, z with one Interpolation,
    Tension (bits) and Key_Count (9.2, 9.4), then the nodes' order and Quat_Track_Count.
    Returns [{node, reference, column}] in Quat_Node's order, as parse_quat does, the
    reference's X, Y, Z read back from rx, ry, rz."""
    Q, LQ, lanes = h["Q"], h["LQ"], a["Quat_Reference_bits"]
    if not LQ:
        return []  # version 4, or a version 5 clip without quaternion nodes
    columns = quat_node_columns(nodes, a["Quat_Node"], "IMAG: Quat_Node", increasing=False)
    for j in range(Q):
        if a["Quat_Column"][j] != columns[j]:
            raise KanimError("corrupt", f"IMAG: Quat_Column[{j}] {a['Quat_Column'][j]} is not node "
                             f"{a['Quat_Node'][j]}'s first rotation channel {columns[j]}")
    quats = []
    for j in range(LQ):
        got = [lanes[k * LQ + j] for k in range(4)]  # rx, ry, rz, rw: four arrays of LQ
        if j >= Q:
            if got != [0, 0, 0, ONE32_BITS]:
                raise KanimError("corrupt", f"IMAG: Quat_Reference padding lane {j} is not (0, 0, 0, 1)")
            continue
        scaled = [a["Quat_Reference"][k * LQ + j] * 32768.0 for k in range(3)]
        if not all(v.is_integer() and -32768 <= v <= 32767 for v in scaled):
            raise KanimError("corrupt", f"IMAG: Quat_Reference lane {j}: rx, ry, rz are not int16 x 2^-15")
        X, Y, Z = (int(v) for v in scaled)
        check_reference(X, Y, Z, f"IMAG: Quat_Reference lane {j}")
        if got != [f32_bits(v) for v in reference_lanes(X, Y, Z)]:  # bits: -0.0 is not the X of 0
            raise KanimError("corrupt", f"IMAG: Quat_Reference lane {j} is not the reference ({X}, {Y}, {Z}) as 9.2 "
                             "rounds it")
        quats.append({"node": a["Quat_Node"][j], "reference": [X, Y, Z], "column": columns[j]})
    for j, quat in enumerate(quats):
        x = quat["column"]
        for c in (x + 1, x + 2):
            if ((a["Interpolation"][c], a["Tension_bits"][c], a["Key_Count"][c]) !=
                    (a["Interpolation"][x], a["Tension_bits"][x], a["Key_Count"][x])):
                raise KanimError("corrupt", f"IMAG: quaternion node {quat['node']} (entry {j}): channel {c}'s "
                                 f"Interpolation, Tension or Key_Count is not its stored x's (channel {x}'s)")
    check_quat_node_order(a, h, quats)
    return quats


def check_quat_node_order(a, h, quats):
    """Quat_Node's order (9.2): first the T quaternion tracks' nodes (whose x, y, z are block
    curves), then the others, each part strictly increasing; and Quat_Track_Count = T."""
    tracks = [is_block_curve(a, h, quat["column"]) for quat in quats]
    T = sum(tracks)
    for j, quat in enumerate(quats):
        if tracks[j] != (j < T):
            raise KanimError("corrupt", f"IMAG: Quat_Node[{j}]: node {quat['node']} " +
                             ("has block curves after a node without" if tracks[j] else "has no block curves before a "
                              "node with") + " (9.2: the quaternion tracks' nodes first)")
        if j not in (0, T) and quat["node"] <= quats[j - 1]["node"]:
            raise KanimError("corrupt", f"IMAG: Quat_Node[{j}]: node {quat['node']} not above the entry before (9.2)")
    if h["T"] != T:
        raise KanimError("corrupt", f"IMAG: Quat_Track_Count {h['T']} is not the {T} quaternion nodes whose curves "
                         "are block curves")


def check_quat_key_frames(a, h, quats, keys):
    """A quaternion node's stored x, y, z share their key frames (4.3, 4.4). A track of three
    holds them once (one Mask); list curves and fixed channels hold each channel's own, so
    theirs must be equal."""
    for j, quat in enumerate(quats):
        x = quat["column"]
        n, curve = a["Key_Count"][x], a["Curve_Of"][x]
        for c in (x + 1, x + 2):
            if n == 1 and a["Fixed_Frame"][c] != a["Fixed_Frame"][x]:
                raise KanimError("corrupt", f"IMAG: Fixed_Frame[{c}] is not its quaternion node's stored x's "
                                 f"(channel {x}): they share key frames (4.4)")
            if n >= 2 and curve >= h["nb"] and keys[a["Curve_Of"][c]][0] != keys[curve][0]:
                raise KanimError("corrupt", f"IMAG: list curve {a['Curve_Of'][c]}'s List_Frames are not its quaternion "
                                 f"node's stored x's (curve {curve}): they share key frames (4.4)")


def check_curve_ends(a, i, frames, values, with_values):
    """First_Frame, Last_Frame (and First_Value, Last_Value) of curve i against its keys."""
    if a["First_Frame_bits"][i] != f32_bits(f32(float(frames[0]))):
        raise KanimError("corrupt", f"IMAG: First_Frame[{i}]")
    if a["Last_Frame_bits"][i] != f32_bits(f32(float(frames[-1]))):
        raise KanimError("corrupt", f"IMAG: Last_Frame[{i}]")
    if with_values and a["First_Value_bits"][i] != f32_bits(values[0]):
        raise KanimError("corrupt", f"IMAG: First_Value[{i}]")
    if with_values and a["Last_Value_bits"][i] != f32_bits(values[-1]):
        raise KanimError("corrupt", f"IMAG: Last_Value[{i}]")


def list_curve_keys(a, h):
    """The list curves' keys (9.2 Lists, List_*), checked key by key: {curve: (frames, q, v)}."""
    keys, first = {}, 0
    for j in range(h["nl"]):
        i = h["nb"] + j
        start, count = a["Lists"][j]
        if start != first or count != a["Key_Count"][a["Curve_Channel"][i]]:
            raise KanimError("corrupt", f"IMAG: Lists[{j}]")
        first += count
    if first != h["M"]:
        raise KanimError("corrupt", "IMAG: List_Key_Count against the lists' Count")
    for j in range(h["nl"]):
        i = h["nb"] + j
        start, count = a["Lists"][j]
        step = a["Curves"][i][1]
        frames, qs = a["List_Frames"][start:start + count], a["List_Q"][start:start + count]
        for x in range(count):
            if frames[x] >= h["F"] or (x and frames[x] <= frames[x - 1]):
                raise KanimError("corrupt", f"IMAG: List_Frames[{start + x}]")
            if abs(qs[x]) > 2 ** 53:
                raise KanimError("corrupt", f"IMAG: List_Q[{start + x}]")
            v = f32(float(qs[x]) * step)
            if not math.isfinite(v) or a["List_Values_bits"][start + x] != f32_bits(v):
                raise KanimError("corrupt", f"IMAG: List_Values[{start + x}]")
        values = a["List_Values"][start:start + count]
        check_curve_ends(a, i, frames, values, with_values=True)
        keys[i] = (frames, qs, values)
    return keys


# ---- IMAG (9.3): the records.

def unzigzag(u):
    return (u >> 1) if u % 2 == 0 else -((u + 1) >> 1)


def zigzag(d):
    return 2 * d if d >= 0 else -2 * d - 1


def read_record(payload, pos, P, wcs, b, F, where):
    """Block b's record at byte pos of Payload of a track of one curve or three (wcs: their
    Base_Bits), after the structure rules of 9.3 and 9.4 (widths, size within Payload_Size,
    zero bits after it, Mask, window order). Returns its size and, for each curve, its fields
    as a record of that curve alone would hold them (the Mask, Context_Bits and Context are
    the three's)."""
    n = len(wcs)
    head = 64 + 8 * n + 8  # Mask, one Value_Bits a curve, Context_Bits: 80 bits, or 96 for three
    if pos + head // 8 > P:
        raise KanimError("corrupt", f"IMAG: {where} runs past Payload_Size")
    mask = struct.unpack_from("<Q", payload, pos)[0]
    if F - 64 * b < 64 and mask >> (F - 64 * b):
        raise KanimError("corrupt", f"IMAG: {where}: Mask bit of a frame >= Frame_Count")
    ws, wk = list(payload[pos + 8:pos + 8 + n]), payload[pos + 8 + n]
    for w in ws:
        if w > 55:
            raise KanimError("corrupt", f"IMAG: {where}: Value_Bits {w} > 55")
    if wk > 31:
        raise KanimError("corrupt", f"IMAG: {where}: Context_Bits {wk} > 31")
    m = bin(mask).count("1")
    nbits = head + 4 * wk + sum(wcs) + (m + 4) * sum(ws)
    size = (nbits + 7) // 8
    if pos + size > P:
        raise KanimError("corrupt", f"IMAG: {where} runs past Payload_Size")
    bits = int.from_bytes(payload[pos:pos + size], "little")
    if bits >> nbits:
        raise KanimError("corrupt", f"IMAG: {where}: bits after its last field")
    fields, p = [], head
    for width in [wk] * 4 + wcs + [w for w in ws for _ in range(m + 4)]:  # Context, Bases, Values of each
        fields.append((bits >> p) & ((1 << width) - 1))
        p += width
    ctx, bases, values = fields[:4], fields[4:4 + n], fields[4 + n:]
    lo, hi = 64 * b, 64 * b + 64
    e = [lo + unzigzag(ctx[0]), lo + unzigzag(ctx[1]), hi + unzigzag(ctx[2]), hi + unzigzag(ctx[3])]
    frames = [lo + t for t in range(64) if mask >> t & 1]
    order = e[:2] + frames + e[2:]  # e_0 < e_1 < the block's keys < e_2 < e_3
    if not all(x < y for x, y in zip(order, order[1:])):
        raise KanimError("corrupt", f"IMAG: {where}: window frames out of order")
    return {"size": size, "curves": [{"Value_Bits": ws[k], "Context_Bits": wk, "Context": ctx, "Base": bases[k],
                                      "Values": values[k * (m + 4):(k + 1) * (m + 4)], "frames": frames}
                                     for k in range(n)]}


def block_curve_keys(a, h, tracks):
    """Every record, block-major and track after track, checked against Record_Offset; the
    block curves' keys (9.3 "The keys of a curve"): {curve: (frames, q, v)}, and the records
    {curve: [record]} (a record of three curves given as each curve's own)."""
    payload, offsets, nb, nt, P = a["Payload"], a["Record_Offset"], h["nb"], h["nt"], h["P"]
    records = {i: [] for i in range(nb)}
    pos = 0
    for b in range(h["B"]):
        for t, curves in enumerate(tracks):
            if offsets[b * nt + t] != pos:
                raise KanimError("corrupt", f"IMAG: Record_Offset[{b * nt + t}]")
            where = (f"record of block {b}, curve {curves[0]}" if len(curves) == 1 else
                     f"record of block {b}, quaternion track {t} (curves {', '.join(map(str, curves))})")
            record = read_record(payload, pos, P, [a["Curves"][i][2] for i in curves], b, h["F"], where)
            for i, fields in zip(curves, record["curves"]):
                records[i].append(fields)
            pos += record["size"]
    if pos != P:
        raise KanimError("corrupt", "IMAG: the records end before Payload_Size")
    if any(offsets[h["R"]:]) or any(payload[P:]):
        raise KanimError("corrupt", "IMAG: the 8 entries after the records' offsets, or bytes after the records, not 0")
    keys = {}
    for i in range(nb):
        q_base, step = a["Curves"][i][0], a["Curves"][i][1]
        frames, qs = [], []
        for rec in records[i]:
            frames += rec["frames"]
            qs += [q_base + rec["Base"] + x for x in rec["Values"][2:2 + len(rec["frames"])]]
        if len(frames) != a["Key_Count"][a["Curve_Channel"][i]]:
            raise KanimError("corrupt", f"IMAG: curve {i}: the records' popcounts against its Key_Count")
        check_curve_ends(a, i, frames, None, with_values=False)
        keys[i] = (frames, qs, [f32(float(q) * step) for q in qs])
    return keys, records


def parse_image(body, F, C, K, major, nodes):
    """IMAG: every structure rule of 9.4, then each channel's keys (9.3). nodes: SKEL's (version
    5, whose quaternion nodes are checked against them), else None."""
    h = image_header(body, F, C, len(nodes) if nodes is not None else None, major)
    a = image_arrays(body, h)
    check_channel_values(a, h, K)
    # Version 5: the quaternion nodes before the curves' order, which they make (9.2).
    quats = check_quat_arrays(a, h, nodes)
    tracks = check_channel_arrays(a, h, quats)
    check_curve_arrays(a, h)
    keys = list_curve_keys(a, h)
    check_quat_key_frames(a, h, quats, keys)
    block_keys, records = block_curve_keys(a, h, tracks)
    keys.update(block_keys)
    frames, values = [], []
    for c in range(C):
        if a["Key_Count"][c] >= 2:
            k = keys[a["Curve_Of"][c]]
            frames.append(list(k[0]))
            values.append(list(k[2]))
        else:  # a fixed channel: no key (0 everywhere) or one
            frames.append([a["Fixed_Frame"][c]] if a["Key_Count"][c] else [])
            values.append([a["Fixed_Value"][c]] if a["Key_Count"][c] else [])
    return {"header": h, "arrays": a, "keys": keys, "records": records, "tracks": tracks, "quat_nodes": quats,
            "interp": a["Interpolation"], "tension": a["Tension"], "frames": frames, "values": values}


# ---- IMAG (9.4): the content rules, by rebuilding from the recovered keys.

def window_key(k, q, i):
    """Key i of a curve extended by virtual keys (9.3 "The window"): (frame, q)."""
    n = len(k)
    if i < 0:
        return k[0] + (k[1] - k[0]) * i, q[0]
    if i >= n:
        return k[n - 1] + (k[n - 1] - k[n - 2]) * (i - n + 1), q[n - 1]
    return k[i], q[i]


def expected_record(k, q, b, q_base):
    """What 9.3 defines for block b's record of a curve with keys (k, q)."""
    lo, hi = 64 * b, 64 * b + 64
    f = sum(1 for x in k if x < lo)  # the first key at or after the block
    l = sum(1 for x in k if x < hi)  # one past the block's last key
    window = [window_key(k, q, i) for i in [f - 2, f - 1] + list(range(f, l)) + [l, l + 1]]
    e = [window[0][0], window[1][0], window[-2][0], window[-1][0]]
    ctx = [zigzag(e[0] - lo), zigzag(e[1] - lo), zigzag(e[2] - hi), zigzag(e[3] - hi)]
    wq = [x[1] for x in window]
    base = min(wq) - q_base
    return {"Value_Bits": (max(wq) - min(wq)).bit_length(), "Context_Bits": (ctx[0] | ctx[1] | ctx[2] | ctx[3]).bit_length(),
            "Context": ctx, "Base": base, "Values": [x - q_base - base for x in wq]}


def check_image_content(image):
    """9.4's content rules: IMAG is the image 9.2 and 9.3 build from the keys it holds."""
    a, keys = image["arrays"], image["keys"]
    for i in sorted(keys):
        frames, qs, values = keys[i]
        if any(abs(q) > 2 ** 53 for q in qs):
            raise KanimError("corrupt", f"IMAG: curve {i}: a key's |q| > 2^53")
        if not all(math.isfinite(v) for v in values):
            raise KanimError("corrupt", f"IMAG: curve {i}: a key's value is not finite")
        q_base, _, base_bits, _ = a["Curves"][i]
        if q_base != min(qs):
            raise KanimError("corrupt", f"IMAG: Curves[{i}].Q_Base is not the curve's smallest q")
        if base_bits != (max(qs) - min(qs)).bit_length():
            raise KanimError("corrupt", f"IMAG: Curves[{i}].Base_Bits")
        check_curve_ends(a, i, frames, values, with_values=True)
        for b, rec in enumerate(image["records"].get(i, [])):
            want = expected_record(frames, qs, b, q_base)
            for name in ["Value_Bits", "Context_Bits", "Context", "Base", "Values"]:
                if rec[name] != want[name]:
                    raise KanimError("corrupt", f"IMAG: record of block {b}, curve {i}: {name} is not what 9.3 makes of the keys")


# ---------------------------------------------------------------------------------------------
# Banks (section 10): many clips in one file, each distinct skeleton once, an index by position
# and by name, a zstd dictionary for archive-profile members, a checksum per clip.

BANK_HEADER_SIZE, SKELETON_ENTRY_SIZE, CLIP_ENTRY_SIZE, NAME_ORDER_ENTRY_SIZE = 40, 32, 40, 4
DICTIONARY_MAGIC = bytes([0x37, 0xA4, 0x30, 0xEC])  # RFC 8878 section 5
MAX_NAME_SIZE = 1024
# The one limit of section 8 this decoder applies: 10.3 makes comparing the skeletons' Raw_Size
# sum with it a MUST before any is inflated. keyanim's default for decompressed bytes, 1 GiB.
DECOMPRESSED_LIMIT = 1 << 30
ZSTD_MAX_RATIO = 32768  # section 8: no zstd frame makes more than 32768 bytes of each of its bytes


BANK_VERSIONS = (4, 5)  # 10.2: 4.1, and 5.0 for a bank that may hold members of version 5


def is_bank(data):
    """The header says a bank (10.2): the signature, Major_Version 4 or 5 and Header_Flags' Bank
    bit (a version 1-3 file with that bit is a clip file breaking 2.2, refused by parse)."""
    return (len(data) >= 16 and data[:8] == SIGNATURE and struct.unpack_from("<H", data, 8)[0] in BANK_VERSIONS
            and bool(struct.unpack_from("<I", data, 12)[0] & BANK))


def bank_header(data):
    """The bank header (10.2): {runtime, major, minor, clips, skeletons, names_size, dictionary_size}."""
    if data[:min(8, len(data))] != SIGNATURE[:min(8, len(data))]:
        raise KanimError("bad_signature", "signature", 0)
    if len(data) < BANK_HEADER_SIZE:
        raise KanimError("truncated", "bank header: the file ends inside its 40 bytes", len(data))
    major, minor, flags, clips, skeletons, names_size, dictionary_size = struct.unpack_from("<HHIIIQQ", data, 8)
    if major not in BANK_VERSIONS:
        raise KanimError("unsupported_version", f"bank header: major {major}", 8)
    if flags & 0xFFF8:
        raise KanimError("reserved_bits_set", "bank header: Header_Flags bits 3-15", 12)
    if not flags & BANK:
        raise KanimError("corrupt", "bank header: Header_Flags' Bank bit is clear (not a bank)", 12)
    if flags & MEMBER:
        raise KanimError("corrupt", "bank header: Header_Flags' Member bit is set", 12)
    if flags & 1 and dictionary_size:
        raise KanimError("corrupt", "bank header: a Dictionary_Size with Runtime set", 32)
    return {"runtime": bool(flags & 1), "major": major, "minor": minor, "clips": clips, "skeletons": skeletons,
            "names_size": names_size, "dictionary_size": dictionary_size}


def bank_tables(data, h):
    """The skeleton table, the clip table and the name order (10.3), once their sizes and the
    names' are known to fit in the file (10.1: nothing is allocated before)."""
    skel_at = BANK_HEADER_SIZE
    clip_at = skel_at + SKELETON_ENTRY_SIZE * h["skeletons"]
    order_at = clip_at + CLIP_ENTRY_SIZE * h["clips"]
    names_at = order_at + NAME_ORDER_ENTRY_SIZE * h["clips"]
    if names_at + h["names_size"] > len(data):  # Python's integers: no overflow to guard
        raise KanimError("truncated", f"bank: the tables and names ({h['skeletons']} skeletons, {h['clips']} clips, "
                         f"Names_Size {h['names_size']}) end at byte {names_at + h['names_size']}, "
                         f"past the file's {len(data)} bytes", len(data))
    skeletons = []
    for j in range(h["skeletons"]):
        at = skel_at + SKELETON_ENTRY_SIZE * j
        offset, stored, raw, flags, reserved = struct.unpack_from("<QQQII", data, at)
        skeletons.append({"index": j, "offset": offset, "stored": stored, "raw": raw, "flags": flags,
                          "reserved": reserved, "entry": at})
    clips = []
    for i in range(h["clips"]):
        at = clip_at + CLIP_ENTRY_SIZE * i
        offset, size, frame_time, frame_count, skeleton, name_offset, name_size = struct.unpack_from("<QQdIIII", data, at)
        clips.append({"index": i, "offset": offset, "size": size, "frame_time": frame_time,
                      "frame_count": frame_count, "skeleton": skeleton, "name_offset": name_offset,
                      "name_size": name_size, "entry": at})
    order = list(struct.unpack_from(f"<{h['clips']}I", data, order_at))
    return skeletons, clips, order, order_at, names_at


def bank_layout(data, h, skeletons, clips, names_at):
    """10.1: every part's offset computed from the sizes before it, the tables' Offset fields
    against it, the file's size against the end of the last part. Returns (the checksum's
    offset, [(start, end) of each padding before the checksum]): that padding is checked when the
    bank opens, the padding before a member (c["padding"]) with the member (10.1)."""
    padding = []

    def align(pos):
        padding.append((pos, pad8(pos)))
        return pad8(pos)

    pos = align(names_at + h["names_size"]) + h["dictionary_size"]
    for j, s in enumerate(skeletons):
        at = align(pos)
        if s["offset"] != at:
            raise KanimError("corrupt", f"skeleton table entry {j}: Offset {s['offset']}, the layout puts skeleton {j} at {at} (10.1)", s["entry"])
        if s["stored"] < 1:
            raise KanimError("corrupt", f"skeleton table entry {j}: Stored_Size 0 (10.3)", s["entry"] + 8)
        pos = at + s["stored"]
    checksum_at = align(pos)
    pos = checksum_at + 8
    for c in clips:
        at = align(pos)
        c["padding"] = padding.pop()
        if c["offset"] != at:
            raise KanimError("corrupt", f"clip table entry {c['index']}: Offset {c['offset']}, the layout puts member "
                             f"{c['index']} at {at} (10.1)", c["entry"])
        pos = at + c["size"]
    if len(data) < pos:
        raise KanimError("truncated", f"bank: the last part ends at byte {pos}, past the file's {len(data)} bytes", len(data))
    if len(data) > pos:
        raise KanimError("trailing_bytes", f"bank: {len(data) - pos} bytes after the last part", pos)
    return checksum_at, padding


def check_skeleton_entries(skeletons):
    """The skeleton table's fields (10.3) that need no more than the table: flags, Raw_Size,
    and a compressed one's Raw_Size within 32768 times its Stored_Size (section 8); then the
    sum of Raw_Size against the limit, before anything is inflated."""
    for s in skeletons:
        j, at = s["index"], s["entry"]
        if s["flags"] & 0xFFFE:
            raise KanimError("reserved_bits_set", f"skeleton table entry {j}: Skeleton_Flags bits 1-15", at + 24)
        if s["reserved"]:
            raise KanimError("reserved_bits_set", f"skeleton table entry {j}: Skeleton_Reserved", at + 28)
        if s["raw"] < 1:
            raise KanimError("corrupt", f"skeleton table entry {j}: Raw_Size 0 (10.3)", at + 16)
        if not s["flags"] & 1 and s["raw"] != s["stored"]:
            raise KanimError("corrupt", f"skeleton table entry {j}: not Compressed, Raw_Size {s['raw']} != "
                             f"Stored_Size {s['stored']} (3.2.4)", at + 16)
        if s["flags"] & 1 and s["raw"] > ZSTD_MAX_RATIO * s["stored"]:
            raise KanimError("zstd_error", f"skeleton table entry {j}: Raw_Size {s['raw']} > 32768 x Stored_Size "
                             f"{s['stored']} (section 8)", at + 16)
    total = sum(s["raw"] for s in skeletons)
    if total > DECOMPRESSED_LIMIT:
        raise KanimError("limit_exceeded", f"skeleton table: the skeletons' Raw_Size sum {total} > the limit "
                         f"{DECOMPRESSED_LIMIT} (10.3, section 8)", BANK_HEADER_SIZE)


def skeleton_content(data, s):
    """A skeleton's content (10.3): its stored bytes, or the one zstd frame they hold (made
    without the bank's dictionary) declaring and inflating to Raw_Size bytes."""
    stored = data[s["offset"]:s["offset"] + s["stored"]]
    if not s["flags"] & 1:
        return stored
    where = f"skeleton {s['index']} (bytes {s['offset']} to {s['offset'] + s['stored'] - 1})"
    try:
        declared = zstd_declared_size(stored)
        if declared != s["raw"]:
            raise KanimError("zstd_error", f"its frame declares {declared} bytes, not Raw_Size {s['raw']}")
        content = zstd_decompress(stored)
        if len(content) != s["raw"]:
            raise KanimError("zstd_error", f"it inflates to {len(content)} bytes, not Raw_Size {s['raw']}")
    except KanimError as e:
        raise KanimError("zstd_error", f"{where}: {e.message}", s["offset"]) from e
    return content


def check_clip_entries(clips, h):
    """The clip table's fields that need no more than the tables (10.3): Skeleton, Name_Size,
    the name within the pool."""
    for c in clips:
        i, at = c["index"], c["entry"]
        if c["skeleton"] >= h["skeletons"]:
            raise KanimError("corrupt", f"clip table entry {i}: Skeleton {c['skeleton']} >= Skeleton_Count {h['skeletons']}", at + 28)
        if not 1 <= c["name_size"] <= MAX_NAME_SIZE:
            raise KanimError("corrupt", f"clip table entry {i}: Name_Size {c['name_size']} not within 1 to {MAX_NAME_SIZE}", at + 36)
        if c["name_offset"] + c["name_size"] > h["names_size"]:
            raise KanimError("corrupt", f"clip table entry {i}: the name (Name_Offset {c['name_offset']}, Name_Size "
                             f"{c['name_size']}) ends past Names_Size {h['names_size']}", at + 32)


def check_name(name, i, at):
    """A name (10.3): no byte 0; split at '/', no part empty, '.' or '..'."""
    if 0 in name:
        raise KanimError("corrupt", f"clip {i}: its name holds a byte 0", at + name.index(0))
    for part in name.split(b"/"):
        if part in (b"", b".", b".."):
            raise KanimError("corrupt", f"clip {i}: its name {name!r} has a part {part.decode()!r} (10.3)", at)


def check_name_order(order, clips, order_at):
    """The name order (10.3): every clip once, in strictly increasing order of name (bytes
    compared as unsigned values, a name before every longer one it begins: Python's bytes <)."""
    seen = [False] * len(clips)
    for k, i in enumerate(order):
        if i >= len(clips) or seen[i]:
            raise KanimError("corrupt", f"name order entry {k}: clip {i} " + ("out of range" if i >= len(clips) else "listed twice"),
                             order_at + 4 * k)
        seen[i] = True
    for k in range(1, len(order)):
        a, b = clips[order[k - 1]], clips[order[k]]
        if not a["name"] < b["name"]:
            why = "share the name" if a["name"] == b["name"] else "are out of order"
            raise KanimError("corrupt", f"name order entries {k - 1} and {k}: clips {a['index']} and {b['index']} "
                             f"{why} {a['name']!r}" + ("" if a["name"] == b["name"] else f", {b['name']!r}"), order_at + 4 * k)


def open_bank(data):
    """Opens a bank (10.1-10.4) from its index, reading no member: header, tables, layout and
    file size, the tables' fields, the skeletons' size limit, then Bank_Checksum, then the
    padding before it, dictionary magic, names and their order, and the skeletons inflated.
    Returns {data, runtime, version, dictionary, skeletons, clips, order}; clips[i] holds
    index, name (bytes), frame_count, frame_time, skeleton, offset and size."""
    h = bank_header(data)
    skeletons, clips, order, order_at, names_at = bank_tables(data, h)
    checksum_at, padding = bank_layout(data, h, skeletons, clips, names_at)
    check_skeleton_entries(skeletons)
    check_clip_entries(clips, h)
    if xxh64(data[:checksum_at]) != struct.unpack_from("<Q", data, checksum_at)[0]:
        raise KanimError("checksum_mismatch", "Bank_Checksum (XXH64 of the bank's bytes before it)", checksum_at)
    for start, end in padding:
        if any(data[start:end]):
            raise KanimError("corrupt", f"bank: padding bytes {start} to {end - 1} not zero (10.1)", start)
    dictionary = None
    if h["dictionary_size"]:
        dict_at = pad8(names_at + h["names_size"])
        dictionary = data[dict_at:dict_at + h["dictionary_size"]]
        if dictionary[:4] != DICTIONARY_MAGIC:
            raise KanimError("corrupt", "dictionary: not a zstd dictionary (its first bytes are not 37 A4 30 EC, 10.4)", dict_at)
    for c in clips:
        at = names_at + c["name_offset"]
        c["name"] = data[at:at + c["name_size"]]
        check_name(c["name"], c["index"], at)
    check_name_order(order, clips, order_at)
    for s in skeletons:
        s["content"] = skeleton_content(data, s)  # inflated once for all the clips of the skeleton
    return {"data": data, "runtime": h["runtime"], "version": (h["major"], h["minor"]), "dictionary": dictionary,
            "skeletons": skeletons, "clips": clips, "order": order}


def find_clip(bank, name):
    """The index of the clip named `name` (bytes), by binary search over the name order; None
    when there is none."""
    clips, order = bank["clips"], bank["order"]
    lo, hi = 0, len(order)
    while lo < hi:
        mid = (lo + hi) // 2
        other = clips[order[mid]]["name"]
        if other == name:
            return order[mid]
        if other < name:
            lo = mid + 1
        else:
            hi = mid
    return None


def clip_label(c):
    return f"clip {c['index']} {c['name'].decode('utf-8', errors='surrogateescape')!r}"


def decode_member(bank, i, check_content=True):
    """Member i (10.5), in the dict parse returns: the padding before it (10.1), the checks of
    section 7 (and 9.4) on the member's bytes with the bank's skeleton as SKEL and its dictionary, then the clip table's
    Frame_Count and Frame_Time against CLIP. A failure names the clip (KanimError.clip) and
    gives its offset from the bank's first byte."""
    c = bank["clips"][i]
    member = bank["data"][c["offset"]:c["offset"] + c["size"]]
    skeleton = bank["skeletons"][c["skeleton"]]
    start, end = c["padding"]
    if any(bank["data"][start:end]):
        raise KanimError("corrupt", f"{clip_label(c)}: the padding before its member (bytes {start} to {end - 1}) "
                         "is not zero (10.1)", start, (i, c["name"]))
    try:
        major, minor, runtime, count = parse_header(member, member=True)
        if major > bank["version"][0]:
            raise KanimError("corrupt", f"header: a member of version {major} in a bank of version "
                             f"{bank['version'][0]} (10.5)", 8)
        if runtime != bank["runtime"]:
            raise KanimError("corrupt", "header: Runtime differs from the bank's (10.5.1)", 12)
        if runtime:
            content = runtime_sections(member, count, major, member=True)
        else:
            content = archive_sections(member, count, major, member=True, dictionary=bank["dictionary"])
        content["SKEL"] = skeleton["content"]
        if runtime:
            clip = decode_runtime(content, major, minor, check_content)
        else:
            clip = decode_archive(content, major, minor, len(member))
    except KanimError as e:
        # The place: the field's offset in the bank where the member's parse knows it, else
        # the member's first byte (the message names the section).
        raise KanimError(e.status, f"{clip_label(c)} (member at bytes {c['offset']} to {c['offset'] + c['size'] - 1} "
                         f"of the bank, skeleton {c['skeleton']}): {e.message}",
                         c["offset"] + (e.offset or 0), (i, c["name"])) from e
    if clip["frame_count"] != c["frame_count"]:
        raise KanimError("corrupt", f"{clip_label(c)}: the clip table's Frame_Count {c['frame_count']} is not CLIP's "
                         f"{clip['frame_count']} (10.5)", c["entry"] + 24, (i, c["name"]))
    if struct.pack("<d", clip["frame_time"]) != struct.pack("<d", c["frame_time"]):
        raise KanimError("corrupt", f"{clip_label(c)}: the clip table's Frame_Time {c['frame_time']!r} is not CLIP's "
                         f"{clip['frame_time']!r}, bit for bit (10.5)", c["entry"] + 16, (i, c["name"]))
    return clip


def bank_index(bank, label):
    """The bank's clip index, as `reference_decoder.py BANK` prints it."""
    return {"bank": label, "format_version": "%d.%d" % bank["version"],
            "profile": "runtime" if bank["runtime"] else "archive",
            "dictionary_size": len(bank["dictionary"] or b""),
            "skeletons": [{"offset": s["offset"], "stored_size": s["stored"], "raw_size": s["raw"],
                           "compressed": bool(s["flags"] & 1)} for s in bank["skeletons"]],
            "clips": [{"index": c["index"], "name": c["name"].decode("utf-8", errors="surrogateescape"),
                       "frame_count": c["frame_count"], "frame_time": c["frame_time"], "skeleton": c["skeleton"],
                       "offset": c["offset"], "size": c["size"]} for c in bank["clips"]]}


def segment_value(k, v, n, j, u, interp, tension, rule):
    """Appendix A, segment j at local parameter u; every operation rounded to binary32."""
    p0, p1 = v[j], v[j + 1]
    if interp == 1:
        return f32(p0 + f32(u * f32(p1 - p0)))
    pm = v[max(j - 1, 0)]
    p2 = v[min(j + 2, n - 1)]
    s = f32(f32(1.0 - tension) * 0.5)
    a0 = a1 = 1.0
    if rule == 1:
        length = f32(float(k[j + 1] - k[j]))
        if j > 0:
            len_in = f32(float(k[j] - k[j - 1]))
            a0 = f32(f32(2.0 * length) / f32(len_in + length))
        if j + 2 < n:
            len_out = f32(float(k[j + 2] - k[j + 1]))
            a1 = f32(f32(2.0 * length) / f32(length + len_out))
    m0 = f32(f32(s * a0) * f32(p1 - pm))
    m1 = f32(f32(s * a1) * f32(p2 - p0))
    u2 = f32(u * u)
    u3 = f32(u2 * u)
    h01 = f32(f32(-2.0 * u3) + f32(3.0 * u2))
    h10 = f32(f32(u3 - f32(2.0 * u2)) + u)
    h11 = f32(u3 - u2)
    return f32(f32(f32(p0 + f32(h01 * f32(p1 - p0))) + f32(h10 * m0)) + f32(h11 * m1))


def channel_value(clip, c, x):
    """Appendix A: channel c at frame position x (binary64)."""
    f = f32(x)
    k, v = clip["frames"][c], clip["values"][c]
    n = len(k)
    if n == 0:
        return 0.0
    K = [f32(float(frame)) for frame in k]
    if n == 1 or not f > K[0]:
        return v[0]
    if f >= K[n - 1]:
        return v[n - 1]
    j = max(i for i in range(n - 1) if K[i] <= f)  # a plain scan: no shared search code
    if f == K[j]:
        return v[j]
    u = f32(f32(f - K[j]) / f32(K[j + 1] - K[j]))
    return segment_value(k, v, n, j, u, clip["interp"][c], clip["tension"][c], clip["tangent_rule"])


def positions_for(frame_count):
    """Frame positions a vector's JSON lists: outside the clip, every key and every quarter
    frame, and some positions that are not exact in binary32."""
    last = max(frame_count - 1, 0)
    ps = [-3.0, -0.5]
    i = 0
    while i <= 4 * min(last, 24):  # every quarter frame of the first 24 frames
        ps.append(i / 4.0)
        i += 1
    i = 1
    while 24 + 0.75 * i <= min(last, 1024):  # then every 0.75 frame up to frame 1024
        ps.append(24 + 0.75 * i)
        i += 1
    i = 1
    while 1024 + 250.5 * i <= last:  # then every 250.5 frames
        ps.append(1024 + 250.5 * i)
        i += 1
    ps += [0.1, 1.0 / 3.0, last * 0.7 + 0.01, last - 1e-7 if last > 0 else 0.3, last + 0.5, last + 1e6]
    return ps


def rotations_at(clip, values):
    """Each quaternion node's rotation (4.7) from the stored values at one position."""
    return [quat_rotation(q["reference"], *values[q["column"]:q["column"] + 3]) for q in clip["quat_nodes"]]


def expected_values(clip, vector, clip_name=None):
    """What a vector's .json holds: the clip's facts and its values at positions_for's
    positions. vector: the file's name; clip_name: the clip's name in a bank (a "clip" field).
    Version 5 adds the quaternion nodes and, at each position, their rotations (4.7); the
    values stay the stored ones (a quaternion node's x, y, z, not angles). Earlier versions'
    JSON has neither field, as before."""
    v5 = clip["version"][0] >= QUAT_VERSION
    samples = []
    for x in positions_for(clip["frame_count"]):
        values = [channel_value(clip, c, x) for c in range(len(clip["frames"]))]
        samples.append({"position": x, "values": values})
        if v5:
            samples[-1]["rotations"] = rotations_at(clip, values)
    out = {"vector": vector}
    if clip_name is not None:
        out["clip"] = clip_name
    out.update({
        "format_version": "%d.%d" % clip["version"],
        "generated_by": "spec/test-vectors/reference_decoder.py",
        "frame_count": clip["frame_count"],
        "frame_time": clip["frame_time"],
        "tangent_rule": clip["tangent_rule"],
        "notes": clip["notes"],
        "nodes": clip["nodes"],
    })
    if v5:
        out["quat_nodes"] = [{"node": q["node"], "reference": q["reference"]} for q in clip["quat_nodes"]]
    out["samples"] = samples
    return out


def json_text(out):
    """expected_values' dict as the vectors' .json text: one sample per line (readable, and
    diffs show which position changed)."""
    header = json.dumps({k: v for k, v in out.items() if k != "samples"}, indent=1)
    lines = ",\n".join("  " + json.dumps(sample) for sample in out["samples"])
    text = header[:-2] + ',\n "samples": [\n' + lines + "\n ]\n}\n"
    json.loads(text)  # the hand-assembled text must still be JSON
    return text


def write_json(path):
    """Writes the expected values of vector `path` beside it, as NAME.json; returns (its path,
    "wrote" or "unchanged"). A vector's JSON never changes once published (Appendix C): one
    that exists with these bytes is left as it is, one with other bytes is an error (KanimError
    "json_differs"), not overwritten."""
    clip = parse(open(path, "rb").read())
    json_path = os.path.splitext(path)[0] + ".json"
    text = json_text(expected_values(clip, os.path.basename(path)))
    if os.path.exists(json_path):
        with open(json_path, "rb") as fh:
            if fh.read() == text.encode():
                return json_path, "unchanged"
        raise KanimError("json_differs", f"{json_path} exists with other values than this decoder's; a published "
                         "vector's values never change (remove the file to write it anew)")
    with open(json_path, "w") as fh:
        fh.write(text)
    return json_path, "wrote"


def bank_main(path, data, names):
    """`reference_decoder.py BANK [NAME]`: the index, or clip NAME's expected values."""
    bank = open_bank(data)
    if not names:
        print(json.dumps(bank_index(bank, os.path.basename(path)), indent=1))
        return 0
    name = os.fsencode(names[0])  # the argument's bytes, as the OS gave them
    i = find_clip(bank, name)
    if i is None:
        print(f"{path}: no clip named {names[0]!r}", file=sys.stderr)
        return 1
    clip = decode_member(bank, i)
    sys.stdout.write(json_text(expected_values(clip, os.path.basename(path), names[0])))
    return 0


def split_bank_clip(arg):
    """BANK:NAME -> (BANK, NAME) when arg is no file but its part before a ':' is (a name may
    hold ':' too: the first such part that is a file); else (arg, None)."""
    if os.path.exists(arg):
        return arg, None
    at = arg.find(":")
    while at >= 0:
        if os.path.isfile(arg[:at]):
            return arg[:at], arg[at + 1:]
        at = arg.find(":", at + 1)
    return arg, None


def read_clip(path, name):
    """The clip of FILE.kanim (name None), or clip `name` of bank `path`."""
    data = open(path, "rb").read()
    if name is None:
        return parse(data)
    bank = open_bank(data)
    i = find_clip(bank, os.fsencode(name))
    if i is None:
        raise KanimError("not_found", f"no clip named {name!r}")
    return decode_member(bank, i)


def main(argv):
    if len(argv) == 3 and argv[1] == "--write-json":
        failed = 0
        for p in sorted(glob.glob(os.path.join(argv[2], "*.kanim"))):
            try:
                json_path, what = write_json(p)
                print(f"{what}: {json_path}")
            except KanimError as e:
                print(f"{p}: {e}", file=sys.stderr)
                failed = 1
        return failed
    if len(argv) >= 2 and not argv[1].startswith("--"):
        path, name = split_bank_clip(argv[1])
        try:
            data = open(path, "rb").read() if name is None else None
            if data is not None and is_bank(data):
                if len(argv) > 3:
                    print(__doc__, file=sys.stderr)
                    return 2
                return bank_main(path, data, argv[2:])
            clip = read_clip(path, name)
        except KanimError as e:
            print(f"{path}: {e}", file=sys.stderr)
            return 1
        for x in [float(a) for a in argv[2:]] or [0.0]:
            print(x, [channel_value(clip, c, x) for c in range(len(clip["frames"]))])
        return 0
    print(__doc__, file=sys.stderr)
    return 2


if __name__ == "__main__":
    sys.exit(main(sys.argv))
