#!/usr/bin/env python3
"""Reference decoder for .kanim 3.0 (and 2.0, 1.0: Appendix E), written from spec/FORMAT.md alone.

It shares no code with the C++ library: it parses the bytes, checks the rules of the spec,
and evaluates Appendix A in binary32 (every operation computed in binary64 and rounded once to
binary32, which gives the correctly rounded binary32 result for + - * /, since 53 >= 2*24 + 2).

Usage:
  reference_decoder.py FILE.kanim [POSITION ...]   print the values at these frame positions
  reference_decoder.py --write-json DIR            write DIR/NAME.json for every DIR/*.kanim

Needs only the Python standard library, plus either the `zstandard` module or the `zstd`
command-line program for compressed sections.
"""
import glob
import json
import math
import os
import struct
import subprocess
import sys
import zlib

SIGNATURE = bytes([0x89, 0x4B, 0x41, 0x4E, 0x0D, 0x0A, 0x1A, 0x0A])
CHANNEL_NAMES = ["Xposition", "Yposition", "Zposition", "Xrotation", "Yrotation", "Zrotation"]
CRITICAL = ["CLIP", "SKEL", "CHAN", "KTIM", "KVAL"]


class KanimError(Exception):
    def __init__(self, status, message):
        super().__init__(f"{status}: {message}")
        self.status = status


def f32(x):
    """Round a Python float (binary64) to the nearest binary32, as a Python float."""
    return struct.unpack("<f", struct.pack("<f", x))[0]


def zstd_decompress(data):
    try:
        import zstandard  # type: ignore
        return zstandard.ZstdDecompressor().decompress(data)
    except ImportError:
        out = subprocess.run(["zstd", "-d", "-c", "-q"], input=data, stdout=subprocess.PIPE, check=True)
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


def parse(data):
    """Returns a dict describing the clip; raises KanimError for a file that breaks the spec."""
    if data[:min(8, len(data))] != SIGNATURE[:min(8, len(data))]:
        raise KanimError("bad_signature", "signature")
    if len(data) < 24:
        raise KanimError("truncated", "header")
    major, minor, header_flags, count, reserved = struct.unpack_from("<HHIII", data, 8)
    if major not in (1, 2, 3):
        raise KanimError("unsupported_version", f"major {major}")
    if header_flags & 0xFFFF or reserved:
        raise KanimError("reserved_bits_set", "header")
    if len(data) < 24 + 24 * count + 4:
        raise KanimError("truncated", "table")
    sections = []
    pos = 24 + 24 * count
    for i in range(count):
        tag, flags, stored, raw = struct.unpack_from("<4sIQQ", data, 24 + 24 * i)
        tag = tag.decode("latin-1")
        if flags & 0xFFFC:
            raise KanimError("reserved_bits_set", "section flags")
        sections.append((tag, flags, data[pos:pos + stored], raw))
        pos += stored
    if len(data) < pos + 4:
        raise KanimError("truncated", "sections")
    if len(data) > pos + 4:
        raise KanimError("trailing_bytes", "after checksum")
    if zlib.crc32(data[:pos]) != struct.unpack_from("<I", data, pos)[0]:
        raise KanimError("checksum_mismatch", "crc")

    content = {}
    critical_seen = []
    for tag, flags, stored, raw in sections:
        ancillary = bool(flags & 2)
        if tag in CRITICAL:
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
            body = zstd_decompress(stored)
            if len(body) != raw:
                raise KanimError("zstd_error", f"{tag}: decompressed size")
        else:
            if len(stored) != raw:
                raise KanimError("corrupt", f"{tag}: raw size")
            body = stored
        content[tag] = body
    if critical_seen != CRITICAL:
        raise KanimError("corrupt", f"critical sections {critical_seen}")

    # CLIP
    clip = content["CLIP"]
    if len(clip) != 32:
        raise KanimError("corrupt", "CLIP size")
    F, N, C, rule, clip_flags, clip_reserved, frame_time, K = struct.unpack("<IIIBBHdQ", clip)
    if rule > 1 or clip_flags or clip_reserved:
        raise KanimError("reserved_bits_set", "CLIP")
    if not math.isfinite(frame_time) or frame_time < 0 or (F > 1 and not frame_time > 0):
        raise KanimError("corrupt", "Frame_Time")
    if K > C * F:
        raise KanimError("corrupt", "Key_Count")

    # SKEL
    r = Reader(content["SKEL"], "SKEL")
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

    # CHAN
    chan = content["CHAN"]
    if len(chan) != {1: 17, 2: 18, 3: 19}[major] * C:
        raise KanimError("corrupt", "CHAN size")
    # Value_Coding (2.0 on): 0 delta, 1 extrapolate; version 1 has only deltas.
    coding = list(chan[17 * C:18 * C]) if major >= 2 else [0] * C
    # Residual_Bytes (3.0): bytes of each zigzag residual in KVAL.
    residual_bytes = list(chan[18 * C:19 * C]) if major == 3 else None
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
    if sum(key_count) != K:
        raise KanimError("corrupt", "Key_Count sum")

    # KTIM
    r = Reader(content["KTIM"], "KTIM")
    frames = []
    for c in range(C):
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
    if major == 3:
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

    values = []
    for c in range(C):
        qs, vals = [], []
        for i in range(key_count[c]):
            u = next_residual(c)
            r = (u >> 1) if u % 2 == 0 else -((u + 1) >> 1)
            if abs(r) > (2 ** 57 if major >= 2 else 2 ** 54):
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
    if major < 3 and not all(p.at_end() for p in planes):
        raise KanimError("corrupt", "KVAL plane bytes left over")

    return {"version": (major, minor), "frame_count": F, "frame_time": frame_time, "tangent_rule": rule,
            "nodes": nodes, "interp": interp, "tension": tension, "frames": frames, "values": values,
            "notes": content.get("NOTE", b"").decode("utf-8", errors="surrogateescape")}


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


def write_json(path):
    data = open(path, "rb").read()
    clip = parse(data)
    samples = []
    for x in positions_for(clip["frame_count"]):
        samples.append({"position": x,
                        "values": [channel_value(clip, c, x) for c in range(len(clip["frames"]))]})
    out = {
        "vector": os.path.basename(path),
        "format_version": "%d.%d" % clip["version"],
        "generated_by": "spec/test-vectors/reference_decoder.py",
        "frame_count": clip["frame_count"],
        "frame_time": clip["frame_time"],
        "tangent_rule": clip["tangent_rule"],
        "notes": clip["notes"],
        "nodes": clip["nodes"],
        "samples": samples,
    }
    json_path = os.path.splitext(path)[0] + ".json"
    # One sample per line: readable, and diffs show which position changed.
    header = json.dumps({k: v for k, v in out.items() if k != "samples"}, indent=1)
    lines = ",\n".join("  " + json.dumps(sample) for sample in samples)
    with open(json_path, "w") as fh:
        fh.write(header[:-2] + ',\n "samples": [\n' + lines + "\n ]\n}\n")
    json.load(open(json_path))  # the hand-assembled text must still be JSON
    return json_path


def main(argv):
    if len(argv) == 3 and argv[1] == "--write-json":
        for p in sorted(glob.glob(os.path.join(argv[2], "*.kanim"))):
            print(write_json(p))
        return 0
    if len(argv) >= 2:
        try:
            clip = parse(open(argv[1], "rb").read())
        except KanimError as e:
            print(e, file=sys.stderr)
            return 1
        for x in [float(a) for a in argv[2:]] or [0.0]:
            print(x, [channel_value(clip, c, x) for c in range(len(clip["frames"]))])
        return 0
    print(__doc__, file=sys.stderr)
    return 2


if __name__ == "__main__":
    sys.exit(main(sys.argv))
