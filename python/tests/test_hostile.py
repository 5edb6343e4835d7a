"""What a careless or hostile caller does to the module (issue 23, round 2), one test per class
of failure: outputs that destroy something, reads that never end, buffers that crash."""

import os
import shutil
import stat
import subprocess
import sys
import threading

import pytest

from conftest import WALK


# Class 1: devices, FIFOs and links to them, and links to a standard stream, are written in
# place, never renamed over.
def test_write_bvh_to_a_fifo_or_a_link_to_a_device_writes_in_place(keyanim, walk, tmp_path):
    fifo = tmp_path / "pipe.bvh"
    os.mkfifo(fifo)
    got = {}
    reader = threading.Thread(target=lambda: got.update(data=open(fifo, "rb").read()), daemon=True)
    reader.start()
    walk.write_bvh(fifo, overwrite=True)
    reader.join(20)
    if reader.is_alive():  # nothing was written to the FIFO: let the reader go, if it is there
        try:
            os.close(os.open(fifo, os.O_WRONLY | os.O_NONBLOCK))
        except OSError:
            pass
    assert stat.S_ISFIFO(os.lstat(fifo).st_mode), "the FIFO was replaced by a regular file"
    walk.write_bvh(tmp_path / "file.bvh")
    assert got["data"] == (tmp_path / "file.bvh").read_bytes()
    os.unlink(tmp_path / "file.bvh")
    link = tmp_path / "null.bvh"
    link.symlink_to("/dev/null")
    walk.write_bvh(link, overwrite=True)
    assert link.is_symlink() and os.readlink(link) == "/dev/null"
    assert stat.S_ISCHR(os.stat("/dev/null").st_mode)
    assert sorted(os.listdir(tmp_path)) == ["null.bvh", "pipe.bvh"]  # no temporary file left


def test_write_bvh_onto_a_device_node_keeps_it(keyanim, walk, tmp_path):
    node = tmp_path / "null"
    try:
        os.mknod(node, stat.S_IFCHR | 0o666, os.makedev(1, 3))
    except PermissionError:
        pytest.skip("creating a device node needs root")
    walk.write_bvh(node, overwrite=True)
    assert stat.S_ISCHR(os.lstat(node).st_mode), "the device node was replaced by a regular file"
    with pytest.raises(FileExistsError):
        walk.write_bvh(node)


def test_write_bvh_to_a_link_to_standard_output(tmp_path):
    # /dev/stdout is such a link (to /proc/self/fd/1); a private one, so that a failure cannot
    # replace the system's.
    link = tmp_path / "out.bvh"
    link.symlink_to("/proc/self/fd/1")
    code = "import keyanim; keyanim.read_bvh(%r).write_bvh(%r, overwrite=True)" % (str(WALK), str(link))
    with open(tmp_path / "captured", "wb") as out:
        subprocess.run([sys.executable, "-c", code], stdout=out, check=True, env=module_env())
    assert link.is_symlink(), "the link to standard output was replaced"
    assert (tmp_path / "captured").read_bytes().startswith(b"HIERARCHY")


# Class 4: reads that never end go through the CLI's guards (refused by their first bytes).
def module_env():
    """The environment, with the module this test imported first on the path."""
    import keyanim
    env = dict(os.environ)
    env["PYTHONPATH"] = os.path.dirname(os.path.dirname(os.path.abspath(keyanim.__file__)))
    return env


def run_bounded(code, tmp_path, seconds=30):
    """Runs `code` in a fresh interpreter with a time limit and 4 GB of address space, so that a
    regression fails the test instead of hanging it or exhausting the machine."""
    script = "import resource; resource.setrlimit(resource.RLIMIT_AS, (4 << 30, 4 << 30))\n" + code
    return subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, errors="replace", timeout=seconds,
                          env=module_env(), cwd=tmp_path)


@pytest.mark.parametrize("call", ["keyanim.read_bvh('/dev/zero')", "keyanim.Clip('/dev/zero')",
                                  "keyanim.read_bvh('/dev/urandom')", "keyanim.Clip('/dev/urandom')"])
def test_endless_inputs_are_refused_by_their_first_bytes(call, tmp_path):
    code = ("import keyanim\ntry:\n    %s\nexcept keyanim.Error as e:\n    print('refused:', e)\n" % call)
    r = run_bounded(code, tmp_path)
    assert r.returncode == 0 and r.stdout.startswith("refused: /dev/"), r.stdout + r.stderr
    assert "signature" in r.stdout or "expected HIERARCHY" in r.stdout


def test_dataset_leaves_out_a_fifo_named_like_a_clip(tmp_path):
    os.mkfifo(tmp_path / "stuck.bvh")
    os.symlink(WALK, tmp_path / "walk.bvh")
    r = run_bounded("import keyanim\nprint(len(keyanim.Dataset('.', window=16).paths))", tmp_path)
    assert r.returncode == 0, r.stderr
    assert r.stdout.strip() == "1"
    code = "import keyanim\ntry:\n    keyanim.Dataset(['stuck.bvh'])\nexcept keyanim.Error as e:\n    print(e)\n"
    r = run_bounded(code, tmp_path)
    assert r.stdout.strip() == "stuck.bvh: not a regular file", r.stdout + r.stderr


def test_dataset_takes_a_bytes_path(keyanim, tmp_path):
    os.symlink(WALK, tmp_path / "walk.bvh")
    assert len(keyanim.Dataset(os.fsencode(tmp_path), window=16)) > 0


# Class 2: a buffer that is not C-contiguous is copied in order, never read past its memory.
def test_clip_from_a_strided_or_reversed_memoryview(keyanim, walk_encoded):
    data = walk_encoded[0]
    with pytest.raises(keyanim.Error, match="signature"):
        keyanim.Clip(memoryview(data)[::-1])
    spaced = bytes(b for byte in data for b in (byte, 0xAA))
    clip = keyanim.Clip(memoryview(spaced)[::2])
    assert clip.info["bytes"] == len(data)
    assert clip.info == keyanim.Clip(data).info


# Class 6: what cannot be read back is not written, and numpy integers are integers.
def test_write_bvh_refuses_values_bvh_cannot_hold(keyanim, tmp_path):
    m = keyanim.read_bvh(WALK)
    view = m.channels
    view[3, 7] = float("nan")
    with pytest.raises(keyanim.Error, match="channel 7 of frame 3 is nan"):
        m.write_bvh(tmp_path / "nan.bvh")
    assert os.listdir(tmp_path) == []


def test_to_motion_refuses_a_rate_whose_frame_time_is_infinite(keyanim, walk_clip):
    for fps in (1e-320, 1e-309, float("inf"), 0.0, -1.0):
        with pytest.raises(ValueError, match="fps"):
            walk_clip.to_motion(fps=fps)
    assert walk_clip.to_motion(fps=30.0).frame_count > 0


def test_dataset_takes_numpy_integers(keyanim):
    np = pytest.importorskip("numpy")
    d = keyanim.Dataset([WALK], window=np.int64(16), stride=np.int32(8))
    assert d.window == 16 and d.stride == 8 and len(d) > 0
    for bad in (True, np.bool_(True), 2.0, 0):
        with pytest.raises(ValueError, match="window must be an integer"):
            keyanim.Dataset([WALK], window=bad)


# Class 7: errors that say what happened.
def test_encode_names_a_value_keys_cannot_hold_and_what_it_is(keyanim):
    m = keyanim.read_bvh(WALK)
    for value, said in ((float("nan"), r"is NaN \(not a number\)"), (float("-inf"), "is -inf"),
                        (3e38, r"is 3e\+38, beyond what binary32 keys can hold")):
        m.channels[3, 7] = value
        with pytest.raises(keyanim.Error, match=r"^channel 7 \(\S+ [XYZ](position|rotation)\) of frame 3 " + said):
            keyanim.encode(m)


def test_encode_settings_out_of_range_say_so(keyanim, walk):
    with pytest.raises(keyanim.Error, match="level is out of range"):
        keyanim.encode(walk, level=2 ** 40)
    with pytest.raises(TypeError, match="level must be an integer"):
        keyanim.encode(walk, level=True)
    with pytest.raises(keyanim.Error, match="threads is out of range"):
        keyanim.encode(walk, threads=-2 ** 63 - 1)


# Class 6: the bytes of a .kanim do not depend on the process's locale.
def comma_locale(tmp_path):
    """(name, extra environment) of a locale whose decimal point is a comma: an installed one
    (`locale -a`), else de_DE.UTF-8 compiled by localedef into tmp_path (glibc finds it through
    LOCPATH), so that no system locale needs to be installed. None when neither can be had."""
    probe = "import locale, sys; locale.setlocale(locale.LC_ALL, sys.argv[1]); print(locale.localeconv()['decimal_point'])"
    def decimal_point(name, env):
        r = subprocess.run([sys.executable, "-c", probe, name], capture_output=True, text=True, env=env)
        return r.stdout.strip() if r.returncode == 0 else None
    listed = subprocess.run(["locale", "-a"], capture_output=True, text=True).stdout.split() if shutil.which("locale") else []
    for name in sorted(listed, key=lambda n: not n.startswith("de_DE")):
        if is_utf8(name) and decimal_point(name, dict(os.environ)) == ",":
            return name, {}
    if shutil.which("localedef"):
        subprocess.run(["localedef", "-i", "de_DE", "-f", "UTF-8", str(tmp_path / "de_DE.UTF-8")], capture_output=True)
        env = dict(os.environ, LOCPATH=str(tmp_path))
        if decimal_point("de_DE.UTF-8", env) == ",":
            return "de_DE.UTF-8", {"LOCPATH": str(tmp_path)}
    return None


def is_utf8(name):
    return name.lower().replace("-", "").endswith(".utf8")


def test_encode_writes_the_same_bytes_under_a_comma_decimal_locale(keyanim, tmp_path):
    found = comma_locale(tmp_path)
    if found is None:
        pytest.skip("no comma-decimal locale: none installed (locale -a) and localedef could not compile "
                    "de_DE.UTF-8 (Debian: apt-get install locales)")
    name, extra = found
    code = ("import locale, sys, keyanim\n"
            "if sys.argv[1] != 'C': locale.setlocale(locale.LC_ALL, sys.argv[1])\n"
            "assert locale.localeconv()['decimal_point'] == ('.' if sys.argv[1] == 'C' else ',')\n"
            "data, report = keyanim.encode(keyanim.read_bvh(sys.argv[2]), error=0.25, tension=0.5, shell=1.5, threads=1)\n"
            "open(sys.argv[3], 'wb').write(data)\n")
    env = module_env()
    env.update(extra)
    outputs = {}
    for loc in ("C", name):
        out = tmp_path / ("%s.kanim" % loc)
        subprocess.run([sys.executable, "-c", code, loc, str(WALK), str(out)], check=True, env=env)
        outputs[loc] = out.read_bytes()
    notes = keyanim.Clip(outputs[name]).encoder_notes
    assert "tension=0.500000\n" in notes and "tolerance=0.25\n" in notes and "shell=1.5\n" in notes, notes
    assert outputs[name] == outputs["C"], "the notes under %s: %r" % (name, notes)


# Class 3: counts beyond what the file's size can hold are refused as they are read (spec
# section 8: a zstd frame makes at most 32768 bytes of each of its bytes, a key takes a byte of
# KTIM at least), and so is a NOTE above the note limit, through the C++ loader: small files,
# in a bounded interpreter.
def crafted_kanim(frames, channels, key_count, note=None):
    """A 3.0 file made here from spec/FORMAT.md (not by keyanim's writer): one node with
    `channels` channels and no keys, CLIP declaring `key_count`, and optionally a compressed
    NOTE given as (stored frame, Raw_Size)."""
    import struct
    import zlib
    skel = struct.pack("<I", 1) + b"r" + struct.pack("<i3dBB", -1, 0, 0, 0, 0, channels) + bytes(range(channels))
    clip = struct.pack("<IIIBBHdQ", frames, 1, channels, 0, 0, 0, 1 / 30, key_count)
    chan = bytes(channels) + struct.pack("<%df" % channels, *[0.0] * channels) + \
        struct.pack("<%dd" % channels, *[0.01] * channels) + bytes(4 * channels) + bytes(2 * channels)
    sections = [(b"CLIP", 0, clip, 32), (b"SKEL", 0, skel, len(skel)), (b"CHAN", 0, chan, len(chan)),
                (b"KTIM", 0, b"", 0), (b"KVAL", 0, b"", 0)]
    if note:
        sections.append((b"NOTE", 3, note[0], note[1]))
    f = b"\x89KAN\r\n\x1a\n" + struct.pack("<HHIII", 3, 0, 0, len(sections), 0)
    f += b"".join(tag + struct.pack("<IQQ", flags, len(stored), raw) for tag, flags, stored, raw in sections)
    f += b"".join(s[2] for s in sections)
    return f + struct.pack("<I", zlib.crc32(f))


def rle_frame(size, byte):
    """A zstd frame of `size` bytes of `byte` in RLE blocks of 128 KiB (4 bytes each)."""
    import struct
    out, left = bytearray(b"\x28\xb5\x2f\xfd\xe0" + struct.pack("<Q", size)), size
    while True:
        n = min(left, 1 << 17)
        left -= n
        out += struct.pack("<I", (n << 3) | 2 | (left == 0))[:3] + bytes([byte])
        if left == 0:
            return bytes(out)


def test_counts_beyond_the_file_size_and_large_notes_are_refused_as_read(keyanim, tmp_path):
    ok = crafted_kanim(1 << 24, 6, 0)
    assert keyanim.Clip(ok).total_keys == 0  # the crafting is right
    path = tmp_path / "keys.kanim"
    path.write_bytes(crafted_kanim(1 << 24, 6, 1 << 28))
    note = tmp_path / "note.kanim"  # a valid 600 MiB NOTE from 19 KB of RLE blocks: above the note limit
    note.write_bytes(crafted_kanim(2, 6, 0, note=(rle_frame(600 << 20, ord("a")), 600 << 20)))
    assert path.stat().st_size < 1000 and note.stat().st_size < 20000
    code = ("import keyanim, sys\n"
            "for name in sys.argv[1:]:\n"
            "    try:\n"
            "        keyanim.Clip(name)\n"
            "    except keyanim.Error as e:\n"
            "        print(e)\n")
    script = "import resource; resource.setrlimit(resource.RLIMIT_AS, (1 << 30, 1 << 30))\n" + code
    r = subprocess.run([sys.executable, "-c", script, str(path), str(note)], capture_output=True, text=True,
                       timeout=20, env=module_env())
    assert r.returncode == 0, r.stderr
    keys, notes = r.stdout.splitlines()
    assert "Key_Count 268435456 is more than a file of %d bytes can hold" % path.stat().st_size in keys
    assert "NOTE declares 629145600 bytes, above the limit of 16777216" in notes
    # The NOTE declared as what its frame makes loads.
    note.write_bytes(crafted_kanim(2, 6, 0, note=(rle_frame(64 << 10, ord("a")), 64 << 10)))
    assert keyanim.Clip(str(note)).encoder_notes == "a" * (64 << 10)
