"""Encoding, reading and bulk sampling release the GIL: another thread runs Python code while
they work, and threads calling them at once get what one thread gets.

How `runs_beside` tells, without timing anything: with the interpreter's switch interval set
very long, a thread holding the GIL keeps it until it blocks or releases it itself. The main
thread waits for the worker to signal that it is about to call; it can only run again when the
worker lets the GIL go. If the call releases the GIL, the main thread runs during the call and
sees it unfinished; if it does not, the main thread runs only after the worker has finished.
"""

import sys
import threading

import numpy as np
import pytest

from conftest import HOP


def runs_beside(call):
    """True if the main thread ran Python code while call() was running in another thread."""
    about_to_call = threading.Event()
    finished = []
    result = []

    def worker():
        about_to_call.set()
        result.append(call())
        finished.append(True)

    interval = sys.getswitchinterval()
    sys.setswitchinterval(1000.0)
    try:
        t = threading.Thread(target=worker)
        t.start()
        about_to_call.wait()
        ran_during_call = not finished
        t.join()
    finally:
        sys.setswitchinterval(interval)
    assert result, "the call failed in its thread"
    return ran_during_call


@pytest.fixture(scope="module")
def long_bvh(tmp_path_factory):
    """The hop with its motion repeated ten times: 11,020 frames, about 8 MB of text."""
    text = HOP.read_text()
    head, motion = text.split("MOTION", 1)
    lines = motion.strip().splitlines()
    frames = lines[2:]
    body = "\n".join(frames * 10)
    path = tmp_path_factory.mktemp("long") / "long.bvh"
    path.write_text(head + "MOTION\nFrames: %d\n%s\n%s\n" % (len(frames) * 10, lines[1], body))
    return path


@pytest.fixture(scope="module")
def long_motion(keyanim, long_bvh):
    return keyanim.read_bvh(long_bvh)


@pytest.fixture(scope="module")
def long_clip(keyanim, long_motion):
    return keyanim.Clip(keyanim.encode(long_motion, error="0.5%")[0])


def test_control_a_call_that_keeps_the_gil():
    # Pure Python keeps the GIL (no switch for 1000 s): the check must say so.
    assert not runs_beside(lambda: sum(i * i for i in range(300000)))


def repeated(call, times=5):
    """A short call several times over: more chances for the main thread to be scheduled."""
    return lambda: [call() for _ in range(times)]


def test_read_bvh(keyanim, long_bvh):
    assert runs_beside(repeated(lambda: keyanim.read_bvh(long_bvh)))


def test_encode(keyanim, long_motion):
    assert runs_beside(lambda: keyanim.encode(long_motion, error="0.5%", threads=1))


def test_motion_forward_kinematics(long_motion):
    assert runs_beside(repeated(long_motion.world_positions))
    assert runs_beside(repeated(long_motion.local_quaternions))


def test_clip_sampling(long_clip):
    times = np.linspace(0, long_clip.duration, 200000)
    assert runs_beside(lambda: long_clip.sample(times))
    assert runs_beside(lambda: long_clip.sample_frames(times / long_clip.frame_time))
    assert runs_beside(lambda: long_clip.sample_stored(times / long_clip.frame_time))
    assert runs_beside(lambda: long_clip.local_transforms(times[:60000]))
    assert runs_beside(lambda: long_clip.world_positions(times[:60000]))
    assert runs_beside(lambda: long_clip.to_motion(fps=1200))


def test_threads_sampling_one_clip_agree(long_clip):
    times = np.linspace(0, long_clip.duration, 50000)
    alone = long_clip.sample(times)
    out = [None] * 4

    def work(k):
        out[k] = long_clip.sample(times)

    threads = [threading.Thread(target=work, args=(k,)) for k in range(4)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    for o in out:
        assert np.array_equal(o, alone)
