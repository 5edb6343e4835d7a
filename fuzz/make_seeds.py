#!/usr/bin/env python3
"""Regenerates the seed files of fuzz/corpus/ (the committed ones were made by this script).

usage: fuzz/make_seeds.py KEYANIM_BINARY [SHARED_CORPUS_DIR]
       fuzz/make_seeds.py --view KEYANIM_BINARY   (view/ alone, from the committed load/ seeds)
       fuzz/make_seeds.py --bank MAKE_BANK_SEEDS  (bank/ alone: build/fuzz/make_bank_seeds, built by
                                                   cmake --build build --target make_bank_seeds)

 - bvh/:       tests/data/bvh fixtures, data/*.bvh and CMU clips of the shared corpus cut to 3 frames
 - roundtrip/: a settings byte + BVH snippets of at most 2000 values (see fuzz_roundtrip.cpp)
 - load/:      spec/test-vectors/*.kanim and .kanim files encoded (by KEYANIM_BINARY) from snippets,
               each also with its sections stored uncompressed (zstd CLI): every snippet with
               Euler rotations (--rotations euler: version 3.0, as the seeds were first made), the
               two of data/ also with quaternion nodes (_quat: version 5.0, what encode writes by
               default since format 5)
 - sample/:    request records + those .kanim files (see fuzz_sample.cpp; not for a file of 64 KiB
               or more, spec/test-vectors/v4_blocks.kanim); fuzz_c_api reads them too
 - view/:      view_seeds(): spec/test-vectors/v4_*.kanim and v5_*.kanim (the runtime profile, and
               the archive files of those versions, which view decodes too) and the runtime profile
               (keyanim convert --runtime) of load/'s CMU seeds, those encoded at the default error
               and at 1% with uniform:5 keys (the _raw ones are the same clips), and of the _quat
               ones (version 5.0)
 - bank/:      bank_seeds(): banks written by write_bank (make_bank_seeds.cpp says which; the
               quat_ ones of version 5.0) and the spec's bank vectors (spec/test-vectors/*.kbank,
               as vector_*.kbank); not part of a plain run, since the helper is a C++ program of
               the build, not the CLI
 - c_api/:     c_api_seeds(): a few of sample/'s seeds with every fuzz_c_api request kind, loaded
               with the CRC-32 (a runtime file's XXH64) as given (byte 0 >= 231): intact, a byte
               flipped, cut short

Only CMU clips are used from the shared corpus (their terms allow it); never bandai/ or ManipNet.
Crash inputs found later are added by hand as crash-<what>.* files and never regenerated.
The encoder's output changes with its versions, so a run rewrites the encoded seeds with other
(equally valid) bytes; commit only the files a change is about.
"""
import os
import random
import re
import struct
import subprocess
import sys
import tempfile
import zlib

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)


def cut_bvh(data: bytes, frames: int) -> bytes:
    """The header of a BVH file and its first `frames` motion lines, line endings kept."""
    lines = data.splitlines(keepends=True)
    out, i = [], 0
    while i < len(lines) and not lines[i].strip().upper().startswith(b"MOTION"):
        out.append(lines[i])
        i += 1
    out.append(lines[i])  # MOTION
    i += 1
    m = re.match(rb"(\s*Frames:\s*)\d+(.*)", lines[i], re.S)
    out.append(m.group(1) + str(frames).encode() + m.group(2))
    out.append(lines[i + 1])  # Frame Time
    out.extend(lines[i + 2:i + 2 + frames])
    return b"".join(out)


def channels_of(bvh: bytes) -> int:
    return sum(int(m.group(1)) for m in re.finditer(rb"CHANNELS\s+(\d+)", bvh))


def uncompressed(kanim: bytes) -> bytes:
    """The same .kanim with every zstd section stored raw (zstd CLI), so that mutations of the
    seed reach the section parsers' fields directly; the CRC-32 is recomputed."""
    count = struct.unpack_from("<I", kanim, 16)[0]
    table, sections, pos = [], [], 24 + 24 * count
    for i in range(count):
        tag, flags, stored, raw = struct.unpack_from("<4sIQQ", kanim, 24 + 24 * i)
        data = kanim[pos:pos + stored]
        pos += stored
        if flags & 1:
            data = subprocess.run(["zstd", "-d", "-c"], input=data, capture_output=True, check=True).stdout
            assert len(data) == raw
        table.append(struct.pack("<4sIQQ", tag, flags & ~1, len(data), len(data)))
        sections.append(data)
    body = kanim[:24] + b"".join(table) + b"".join(sections)
    return body + struct.pack("<I", zlib.crc32(body))


# Snippets also encoded with quaternion nodes (version 5.0): the two CMU clips of data/.
QUAT_SNIPPETS = ("data_cmu_02_01_walk", "data_cmu_131_03_hop")
# libFuzzer's -max_len in CI (scripts/sanitize.sh) and in README.md: a longer seed is cut there.
MAX_SEED = 65536


def write(path: str, data: bytes) -> None:
    os.makedirs(os.path.dirname(path), exist_ok=True)
    with open(path, "wb") as f:
        f.write(data)


def main() -> None:
    keyanim = sys.argv[1]
    shared = sys.argv[2] if len(sys.argv) > 2 else os.path.join(ROOT, "..", "shared", "corpus")
    corpus = os.path.join(HERE, "corpus")
    rng = random.Random(20261122)

    sources = {}  # seed name -> full BVH bytes
    cmu = os.path.join(shared, "cmu")
    picks = ["BVH-Examples__05_20-daz.bvh", "BVH-Examples__94_01.bvh", "BvhToDeepMimic__02_01.bvh",
             "InverseKinematics__05_06.bvh", "bvh11__131_03.bvh", "makehuman-crlf__10_01.bvh",
             "makehuman-lf__12_03.bvh"]
    for name in picks:
        with open(os.path.join(cmu, name), "rb") as f:
            sources["cmu_" + name.split("__")[1][:-4]] = f.read()
    for name in ["cmu_02_01_walk.bvh", "cmu_131_03_hop.bvh"]:
        with open(os.path.join(ROOT, "data", name), "rb") as f:
            sources["data_" + name[:-4]] = f.read()

    fixtures = os.path.join(ROOT, "tests", "data", "bvh")
    for name in sorted(os.listdir(fixtures)):
        if name.endswith(".bvh"):
            with open(os.path.join(fixtures, name), "rb") as f:
                data = f.read()
            write(os.path.join(corpus, "bvh", "fixture_" + name), data)
            write(os.path.join(corpus, "roundtrip", "fixture_" + name), bytes([rng.randrange(256)]) + data)

    snippets = {}
    for index, (key, data) in enumerate(sorted(sources.items())):
        write(os.path.join(corpus, "bvh", key + ".bvh"), cut_bvh(data, 3))
        frames = max(2, min(20, 2000 // channels_of(data)))
        snippets[key] = cut_bvh(data, frames)
        for settings in ((0x00, 0x92), (0x4D, 0xE7))[index % 2]:
            write(os.path.join(corpus, "roundtrip", "%s_s%02x.bvh" % (key, settings)),
                  bytes([settings]) + snippets[key])

    kanims = {}
    for name in sorted(os.listdir(os.path.join(ROOT, "spec", "test-vectors"))):
        if name.endswith(".kanim"):
            with open(os.path.join(ROOT, "spec", "test-vectors", name), "rb") as f:
                kanims["vector_" + name[:-6]] = f.read()
    with tempfile.TemporaryDirectory() as tmp:
        for key, bvh in sorted(snippets.items()):
            src, dst = os.path.join(tmp, key + ".bvh"), os.path.join(tmp, key + ".kanim")
            write(src, bvh)
            coarse = ["--error", "1%", "--keys", "uniform:5"]
            variants = [("", ["--rotations", "euler"]), ("_coarse", ["--rotations", "euler"] + coarse)]
            if key in QUAT_SNIPPETS:
                variants += [("_quat", ["--rotations", "quaternion"]), ("_quat_coarse", ["--rotations", "quaternion"] + coarse)]
            for label, extra in variants:
                r = subprocess.run([keyanim, "-q", "-f", "encode", src, "-o", dst] + extra, capture_output=True)
                if r.returncode == 0:
                    with open(dst, "rb") as f:
                        kanims[key + label] = f.read()
                    kanims[key + label + "_raw"] = uncompressed(kanims[key + label])
                elif label in ("", "_quat"):
                    sys.exit("encode failed for %s: %s" % (key, r.stderr.decode()))
                if label == "_quat" and kanims[key + label][8] != 5:
                    sys.exit("%s: not a version 5 file (no quaternion node?)" % (key + label))
    for key, data in sorted(kanims.items()):
        write(os.path.join(corpus, "load", key + ".kanim"), data)
        if len(data) >= MAX_SEED:
            continue
        records = b""
        for mode in range(16):  # every request kind once, then a few random ones
            m = rng.randrange(256) if mode >= 8 else mode | (rng.randrange(8) << 3) | (rng.randrange(2) << 6)
            records += bytes([m]) + struct.pack("<d", rng.uniform(-5, 60))
        write(os.path.join(corpus, "sample", key + ".bin"), bytes([16]) + records + data)
    c_api_seeds(corpus)
    view_seeds(keyanim, corpus)


def view_seeds(keyanim, corpus):
    """fuzz_view's seeds: runtime-profile files (see fuzz_view.cpp)."""
    vectors = os.path.join(ROOT, "spec", "test-vectors")
    for name in sorted(os.listdir(vectors)):
        if name.startswith(("v4_", "v5_")) and name.endswith(".kanim"):
            with open(os.path.join(vectors, name), "rb") as f:
                write(os.path.join(corpus, "view", "vector_" + name), f.read())
    load = os.path.join(corpus, "load")
    for name in sorted(os.listdir(load)):
        if re.fullmatch(r"(cmu_[0-9a-z_-]+?|[0-9a-z_-]+_quat)(_coarse)?\.kanim", name) and "_raw" not in name:
            dst = os.path.join(corpus, "view", name[:-6] + "_runtime.kanim")
            subprocess.run([keyanim, "-q", "-f", "convert", os.path.join(load, name), "--runtime", "-o", dst],
                           check=True)


def bank_seeds(helper, corpus):
    """fuzz_bank's seeds: make_bank_seeds writes them (the library's write_bank; the CLI has no
    bank command) and checks that each is under 64 KiB."""
    out = os.path.join(corpus, "bank")
    os.makedirs(out, exist_ok=True)
    subprocess.run([helper, ROOT, out], check=True)
    vectors = os.path.join(ROOT, "spec", "test-vectors")
    for name in sorted(os.listdir(vectors)):
        if name.endswith(".kbank"):
            with open(os.path.join(vectors, name), "rb") as f:
                write(os.path.join(out, "vector_" + name), f.read())


def c_api_seeds(corpus):
    """fuzz_c_api's own seeds, made from sample/'s: 24 requests (byte 0 = 255: 255 % 33 = 24,
    and >= 231, so that the checksum is kept) of every kind (channels, local, model; by frame or
    time; cursor; short buffer; each way of making a position), on the file as it is, with a
    byte flipped and cut short."""
    rng = random.Random(26)
    for key in ("vector_v3_rules", "data_cmu_02_01_walk_coarse", "data_cmu_131_03_hop_coarse_raw", "vector_v5_quat",
                "vector_v5_quat_runtime"):
        with open(os.path.join(corpus, "sample", key + ".bin"), "rb") as f:
            seed = f.read()
        data = seed[1 + 16 * 9:]
        modes = [(p << 5) | ((p * 3 + k * 11) % 32) for p in range(8) for k in range(3)]
        records = b"".join(bytes([m]) + struct.pack("<d", rng.uniform(-5, 60)) for m in modes)
        flipped = bytearray(data)
        flipped[len(data) // 2] ^= 0x10
        for label, body in (("", data), ("_flipped", bytes(flipped)), ("_cut", data[:len(data) * 2 // 3])):
            write(os.path.join(corpus, "c_api", "crc_kept_" + key + label + ".bin"), bytes([255]) + records + body)


if __name__ == "__main__":
    if len(sys.argv) == 3 and sys.argv[1] == "--view":
        view_seeds(sys.argv[2], os.path.join(HERE, "corpus"))
    elif len(sys.argv) == 3 and sys.argv[1] == "--bank":
        bank_seeds(sys.argv[2], os.path.join(HERE, "corpus"))
    else:
        main()
