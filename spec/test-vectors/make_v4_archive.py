#!/usr/bin/env python3
"""Makes v4_archive.kanim: v3_rules.kanim with Major_Version 4 (Runtime clear), an archive-profile
file of version 4.0 laid out exactly as 3.0 (spec section 9), with its CRC-32 recomputed (3.3).

Usage: make_v4_archive.py   writes v4_archive.kanim beside this script if it is not there, and
                            otherwise checks that it holds these bytes (vectors never change).
"""
import os
import struct
import sys
import zlib

HERE = os.path.dirname(os.path.abspath(__file__))


def v4_archive_bytes(v3_bytes):
    """The file with Major_Version (offset 8) set to 4 and the CRC-32 of every byte before the
    last four rewritten; Header_Flags (Runtime clear) and every other byte kept."""
    out = bytearray(v3_bytes)
    if struct.unpack_from("<HI", out, 8) != (3, 0) or struct.unpack_from("<I", out, 12)[0] != 0:
        raise ValueError("expected a version 3 file with Header_Flags 0")
    struct.pack_into("<H", out, 8, 4)
    struct.pack_into("<I", out, len(out) - 4, zlib.crc32(bytes(out[:-4])))
    return bytes(out)


def main():
    want = v4_archive_bytes(open(os.path.join(HERE, "v3_rules.kanim"), "rb").read())
    path = os.path.join(HERE, "v4_archive.kanim")
    if os.path.exists(path):
        same = open(path, "rb").read() == want
        print(f"{path}: {'the same bytes' if same else 'DIFFERS from what this script makes'}")
        return 0 if same else 1
    tmp = path + ".tmp"
    with open(tmp, "wb") as fh:
        fh.write(want)
    os.rename(tmp, path)
    print(f"{path}: written")
    return 0


if __name__ == "__main__":
    sys.exit(main())
