#!/usr/bin/env python3
"""keyanim's C API from Python through ctypes: no compiled glue, only libkeyanim_c.so.

  ctypes_test.py LIBKEYANIM_C.so CLIP.kanim POSITION...

Prints what examples/c/sample_clip.c prints (compare.py checks it against `keyanim sample`),
reading every value through ctypes. On the way it checks what only a caller sees: each
position sampled through a cursor and without one gives the same bits, the time calls agree
with their frame calls, and the errors a Python caller can make (NaN, a short buffer, a
missing file) come back as status codes with the last error filled in.
"""
import ctypes
import math
import sys


class Transform(ctypes.Structure):
    """keyanim_transform: 32 bytes, rotation (x, y, z, w) then translation."""
    _fields_ = [("rotation", ctypes.c_float * 4), ("translation", ctypes.c_float * 3), ("pad", ctypes.c_float)]


def load_library(path):
    """libkeyanim_c with the signatures this script uses (ctypes assumes int otherwise)."""
    lib = ctypes.CDLL(path)
    clip_p, cursor_p = ctypes.c_void_p, ctypes.c_void_p
    status = ctypes.c_int32
    sig = {
        "keyanim_status_name": (ctypes.c_char_p, [status]),
        "keyanim_last_error_status": (status, []),
        "keyanim_last_error_detail": (ctypes.c_char_p, []),
        "keyanim_last_error_section": (ctypes.c_char_p, []),
        "keyanim_clip_load_file": (status, [ctypes.c_char_p, ctypes.POINTER(clip_p)]),
        "keyanim_clip_load": (status, [ctypes.c_char_p, ctypes.c_size_t, ctypes.POINTER(clip_p)]),
        "keyanim_clip_free": (None, [clip_p]),
        "keyanim_clip_frame_count": (ctypes.c_uint32, [clip_p]),
        "keyanim_clip_frame_time": (ctypes.c_double, [clip_p]),
        "keyanim_clip_channel_count": (ctypes.c_uint32, [clip_p]),
        "keyanim_clip_node_count": (ctypes.c_uint32, [clip_p]),
        "keyanim_clip_node_name": (ctypes.c_char_p, [clip_p, ctypes.c_uint32]),
        "keyanim_clip_node_parent": (ctypes.c_int32, [clip_p, ctypes.c_uint32]),
        "keyanim_clip_skeleton": (ctypes.c_void_p, [clip_p]),
        "keyanim_skeleton_node_is_end_site": (ctypes.c_int32, [ctypes.c_void_p, ctypes.c_uint32]),
        "keyanim_cursor_create": (status, [clip_p, ctypes.POINTER(cursor_p)]),
        "keyanim_cursor_free": (None, [cursor_p]),
    }
    floats, transforms = ctypes.POINTER(ctypes.c_float), ctypes.POINTER(Transform)
    for kind, out in (("", floats), ("_local", transforms), ("_model", transforms)):
        for at in ("", "_time"):
            sig[f"keyanim_clip_sample{kind}{at}"] = (status, [clip_p, ctypes.c_double, out, ctypes.c_size_t])
            sig[f"keyanim_cursor_sample{kind}{at}"] = (status, [cursor_p, ctypes.c_double, out, ctypes.c_size_t])
    for name, (restype, argtypes) in sig.items():
        fn = getattr(lib, name)
        fn.restype, fn.argtypes = restype, argtypes
    return lib


def expect(condition, what):
    if not condition:
        raise SystemExit(f"ctypes_test: {what}")


def same_bits(a, b):
    return bytes(a) == bytes(b)


def check_errors(lib, clip, channels):
    """The mistakes a Python caller makes come back as statuses, never as a crash."""
    short = (ctypes.c_float * max(channels - 1, 1))()
    expect(lib.keyanim_clip_sample(clip, 0.0, short, channels - 1) == 52, "a short buffer is not output_too_small")
    expect(lib.keyanim_status_name(52) == b"output_too_small", "status 52's name")
    out = (ctypes.c_float * channels)()
    expect(lib.keyanim_clip_sample(clip, math.nan, out, channels) == 50, "NaN is not invalid_argument")
    expect(b"NaN" in lib.keyanim_last_error_detail(), "the last error does not say NaN")
    expect(lib.keyanim_clip_sample(None, 0.0, out, channels) == 50, "a NULL clip is not invalid_argument")
    missing = ctypes.c_void_p()
    expect(lib.keyanim_clip_load_file(b"/nonexistent/x.kanim", ctypes.byref(missing)) == 60, "a missing file")
    expect(missing.value is None and lib.keyanim_last_error_section() == b"file", "the missing file's error")
    damaged = ctypes.c_void_p()
    expect(lib.keyanim_clip_load(b"KANIM not really", 16, ctypes.byref(damaged)) != 0 and damaged.value is None,
           "damaged bytes load")


def main():
    if len(sys.argv) < 3:
        raise SystemExit(__doc__.strip().split("\n\n")[1])
    lib = load_library(sys.argv[1])
    clip = ctypes.c_void_p()
    if lib.keyanim_clip_load_file(sys.argv[2].encode(), ctypes.byref(clip)) != 0:
        raise SystemExit(f"ctypes_test: {sys.argv[2]}: {lib.keyanim_last_error_detail().decode()}")
    cursor = ctypes.c_void_p()
    expect(lib.keyanim_cursor_create(clip, ctypes.byref(cursor)) == 0, "keyanim_cursor_create")
    frames, frame_time = lib.keyanim_clip_frame_count(clip), lib.keyanim_clip_frame_time(clip)
    nodes, channels = lib.keyanim_clip_node_count(clip), lib.keyanim_clip_channel_count(clip)
    skeleton = lib.keyanim_clip_skeleton(clip)
    print(f"clip {frames} {frame_time!r} {nodes} {channels}")
    for i in range(nodes):
        name = lib.keyanim_clip_node_name(clip, i).decode("latin-1")
        print(f"node {i} {lib.keyanim_clip_node_parent(clip, i)} {lib.keyanim_skeleton_node_is_end_site(skeleton, i)} {name}")

    values, again = (ctypes.c_float * channels)(), (ctypes.c_float * channels)()
    pose, pose_again = (Transform * nodes)(), (Transform * nodes)()
    for arg in sys.argv[3:]:
        by_time = arg.startswith("t")
        x = float(arg[1:] if by_time else arg)
        at = "_time" if by_time else ""
        print(f"at {'time' if by_time else 'frame'} {x!r}")
        expect(getattr(lib, f"keyanim_clip_sample{at}")(clip, x, values, channels) == 0, f"sample at {arg}")
        expect(getattr(lib, f"keyanim_cursor_sample{at}")(cursor, x, again, channels) == 0, f"cursor at {arg}")
        expect(same_bits(values, again), f"cursor and plain sample differ at {arg}")
        print("channels " + " ".join(repr(v) for v in values))
        for kind in ("local", "model"):
            expect(getattr(lib, f"keyanim_clip_sample_{kind}{at}")(clip, x, pose, nodes) == 0, f"{kind} at {arg}")
            expect(getattr(lib, f"keyanim_cursor_sample_{kind}{at}")(cursor, x, pose_again, nodes) == 0, f"cursor {kind}")
            expect(same_bits(pose, pose_again), f"cursor and plain {kind} differ at {arg}")
            for i, t in enumerate(pose):
                print(f"{kind} {i} " + " ".join(repr(v) for v in list(t.rotation) + list(t.translation)))
    check_errors(lib, clip, channels)
    lib.keyanim_cursor_free(cursor)
    lib.keyanim_clip_free(clip)
    lib.keyanim_clip_free(None)
    return 0


if __name__ == "__main__":
    sys.exit(main())
