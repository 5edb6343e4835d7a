"""Shared fixtures of the Python tests, and an independent reading of BVH and forward kinematics
in plain Python/numpy (written from the BVH description and spec/FORMAT.md appendix B, not from
keyanim's code), which the tests check the module against.

Environment (set by CTest, python/CMakeLists.txt): PYTHONPATH holds the built module;
KEYANIM_REPO_DIR the checkout (data/, tests/data/bvh); KEYANIM_CORPUS_DIR the shared corpus
(tests marked `corpus` skip without it, and a run of corpus tests alone then exits 77, which
CTest reports as skipped); KEYANIM_CLI the keyanim tool, for comparing reports with it.
"""

import json
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

HERE = Path(__file__).resolve().parent
REPO = Path(os.environ.get("KEYANIM_REPO_DIR", HERE.parent.parent))
DATA = REPO / "data"
FIXTURES = REPO / "tests" / "data" / "bvh"
WALK = DATA / "cmu_02_01_walk.bvh"
HOP = DATA / "cmu_131_03_hop.bvh"
CORPUS = Path(os.environ.get("KEYANIM_CORPUS_DIR", REPO.parent / "shared" / "corpus"))
CORPUS_SKIP = "keyanim-corpus-skip: %s not found" % CORPUS


def frames_at_rate(n, frame_time, fps):
    """decode.h's rule, written again from its comment: a rate within 0.01% of N times the
    clip's own gives its frames and N-1 in-betweens, within 0.01% of it divided by M every M-th
    frame, any other frames every 1/fps s up to the end."""
    if n <= 1:
        return n
    r = fps * frame_time
    if round(r) >= 1 and abs(r - round(r)) <= 1e-4 * r:
        return (n - 1) * round(r) + 1
    if round(1 / r) >= 2 and abs(1 / r - round(1 / r)) <= 1e-4 / r:
        return (n - 1) // round(1 / r) + 1
    return int(np.floor((n - 1) * frame_time * fps + 1e-6)) + 1


def corpus_files():
    """Every .bvh of the shared corpus, sorted; empty without it."""
    return sorted(CORPUS.rglob("*.bvh")) if CORPUS.is_dir() else []


def pytest_configure(config):
    config.addinivalue_line("markers", "corpus: needs the shared BVH corpus (KEYANIM_CORPUS_DIR)")


def pytest_collection_modifyitems(config, items):
    if CORPUS.is_dir():
        return
    for item in items:
        if "corpus" in item.keywords:
            item.add_marker(pytest.mark.skip(reason=CORPUS_SKIP))


def pytest_sessionfinish(session, exitstatus):
    # Every selected test skipped for want of the corpus: tell CTest "skipped" (77), not "passed".
    reporter = session.config.pluginmanager.get_plugin("terminalreporter")
    if reporter is None or exitstatus != 0:
        return
    skipped = reporter.stats.get("skipped", [])
    ran = sum(len(reporter.stats.get(k, [])) for k in ("passed", "failed", "error"))
    if skipped and not ran and not CORPUS.is_dir():
        print("\n" + CORPUS_SKIP)
        session.exitstatus = 77


def cli(*args, check=True):
    """Runs the keyanim tool (KEYANIM_CLI); skips the test when it was not built."""
    tool = os.environ.get("KEYANIM_CLI")
    if not tool or not os.path.exists(tool):
        pytest.skip("the keyanim tool is not built (KEYANIM_CLI)")
    r = subprocess.run([tool, *map(str, args)], capture_output=True, text=True, errors="surrogateescape")
    if check and r.returncode != 0:
        raise AssertionError("keyanim %s exited %d: %s" % (" ".join(map(str, args)), r.returncode, r.stderr))
    return r


def cli_json(*args):
    return json.loads(cli(*args).stdout)


# ---- An independent BVH reader: the hierarchy, then the MOTION numbers.

class Bvh:
    """names, parents, offsets (n, 3), end_site flags, channels [(node, 'Xrotation')...],
    frame_count, frame_time, values (frames, channels) float64."""


def parse_bvh(path):
    text = Path(path).read_bytes().decode("latin-1")
    lines = text.replace("\r\n", "\n").replace("\r", "\n").split("\n")
    b = Bvh()
    b.names, b.parents, b.offsets, b.end_site, b.channels = [], [], [], [], []
    stack, i = [], 0
    while not lines[i].strip().upper().startswith("MOTION"):
        words = lines[i].split()
        i += 1
        if not words:
            continue
        key = words[0].upper()
        if key in ("ROOT", "JOINT") or (key == "END" and len(words) > 1 and words[1].upper() == "SITE"):
            end = key == "END"
            rest = lines[i - 1].strip()[len(words[0]):].strip()
            if end:
                rest = rest[len(words[1]):].strip()
            b.names.append(rest.rstrip("{").strip())
            b.parents.append(stack[-1] if stack and key != "ROOT" else -1)
            b.offsets.append([0.0, 0.0, 0.0])
            b.end_site.append(end)
        elif key == "{":
            stack.append(len(b.names) - 1)
        elif key == "}":
            stack.pop()
        elif key == "OFFSET":
            b.offsets[-1] = [float(v) for v in words[1:4]]
        elif key == "CHANNELS":
            b.channels += [(len(b.names) - 1, w) for w in words[2:2 + int(words[1])]]
        if words[-1] == "{" and key != "{":
            stack.append(len(b.names) - 1)
    b.offsets = np.array(b.offsets, dtype=np.float64)
    rest = [r for r in lines[i + 1:] if r.strip()]
    b.frame_count = int(rest[0].split(":")[1])
    b.frame_time = float(rest[1].split(":")[1])
    rows = [r.split() for r in rest[2:]]
    b.values = np.array([[float(v) for v in r] for r in rows], dtype=np.float64).reshape(len(rows), len(b.channels))
    return b


# ---- Independent forward kinematics (spec/FORMAT.md appendix B): R = R_1 R_2 R_3 over the
# rotation channels in order, position channels replace OFFSET components, p = p_parent +
# R_parent t.

def _axis_matrices(axis, degrees):
    a = np.radians(degrees)
    c, s = np.cos(a), np.sin(a)
    m = np.zeros(degrees.shape + (3, 3))
    i, j = [(1, 2), (2, 0), (0, 1)][axis]
    m[..., axis, axis] = 1
    m[..., i, i], m[..., i, j], m[..., j, i], m[..., j, j] = c, -s, s, c
    return m


def local_rotations(bvh, values):
    """(frames, nodes, 3, 3) local rotation matrices."""
    n = len(bvh.names)
    rot = np.tile(np.eye(3), (values.shape[0], n, 1, 1))
    for col, (node, name) in enumerate(bvh.channels):
        if name.lower().endswith("rotation"):
            axis = "xyz".index(name[0].lower())
            rot[:, node] = rot[:, node] @ _axis_matrices(axis, values[:, col])
    return rot


def local_translations(bvh, values, reading="replace"):
    """Position channels replace the OFFSET component ("replace", Blender) or add to it ("add",
    three.js)."""
    t = np.tile(bvh.offsets, (values.shape[0], 1, 1))
    for col, (node, name) in enumerate(bvh.channels):
        if name.lower().endswith("position"):
            axis = "xyz".index(name[0].lower())
            t[:, node, axis] = values[:, col] + (t[:, node, axis] if reading == "add" else 0.0)
    return t


def world_pose(bvh, values, reading="replace"):
    """World rotations (frames, nodes, 3, 3) and positions (frames, nodes, 3)."""
    rot, t = local_rotations(bvh, values), local_translations(bvh, values, reading)
    world_r, world_p = np.empty_like(rot), np.empty_like(t)
    for j, p in enumerate(bvh.parents):
        if p < 0:
            world_r[:, j], world_p[:, j] = rot[:, j], t[:, j]
        else:
            world_r[:, j] = world_r[:, p] @ rot[:, j]
            world_p[:, j] = world_p[:, p] + np.einsum("fij,fj->fi", world_r[:, p], t[:, j])
    return world_r, world_p


def world_positions(bvh, values, reading="replace"):
    """(frames, nodes, 3)."""
    return world_pose(bvh, values, reading)[1]


def measured_points(bvh, values, shell, reading="replace"):
    """The points keyanim's error is measured on: every node (joints and End Sites), then for
    each joint three shell points at distance `shell` along its local x, y and z axes (the
    columns of its world rotation): (frames, points, 3)."""
    world_r, world_p = world_pose(bvh, values, reading)
    if shell == 0:
        return world_p
    joints = [j for j, end in enumerate(bvh.end_site) if not end]
    shells = world_p[:, joints, None, :] + shell * np.swapaxes(world_r[:, joints], -1, -2)
    return np.concatenate([world_p, shells.reshape(values.shape[0], -1, 3)], axis=1)


def has_positions_below_root(bvh):
    return any(bvh.parents[node] >= 0 and name.lower().endswith("position") for node, name in bvh.channels)


def independent_error(bvh, decoded, shell):
    """Largest distance of any measured point over every frame between the BVH text's values and
    `decoded` (frames, channels), under both readings of position channels below the root when
    there are some (as keyanim measures)."""
    readings = ("replace", "add") if has_positions_below_root(bvh) else ("replace",)
    return max(np.linalg.norm(measured_points(bvh, bvh.values, shell, r) - measured_points(bvh, decoded, shell, r),
                              axis=-1).max() for r in readings)


def quaternion_matrices(q):
    """(..., 4) quaternions (x, y, z, w) -> (..., 3, 3) rotation matrices."""
    x, y, z, w = q[..., 0], q[..., 1], q[..., 2], q[..., 3]
    return np.stack([
        np.stack([1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)], -1),
        np.stack([2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)], -1),
        np.stack([2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)], -1),
    ], -2)


# ---- Quaternions, independently of keyanim (x, y, z, w; spec/FORMAT.md 4.7 and Appendix B):
# the rotation of a quaternion node from its stored x, y, z, and of Euler angles.

def hamilton(a, b):
    """The Hamilton product a b of (..., 4) quaternions (x, y, z, w)."""
    ax, ay, az, aw = np.moveaxis(np.asarray(a, dtype=np.float64), -1, 0)
    bx, by, bz, bw = np.moveaxis(np.asarray(b, dtype=np.float64), -1, 0)
    return np.stack([aw * bx + ax * bw + ay * bz - az * by,
                     aw * by - ax * bz + ay * bw + az * bx,
                     aw * bz + ax * by - ay * bx + az * bw,
                     aw * bw - ax * bx - ay * by - az * bz], -1)


def euler_quaternions(degrees, axes):
    """(..., 3) angles in degrees about `axes` ('ZYX': the channels' axes in their order) ->
    (..., 4) unit quaternions of R = R_axes[0] R_axes[1] R_axes[2], as local_rotations composes
    them."""
    degrees = np.asarray(degrees, dtype=np.float64)
    q = np.zeros(degrees.shape[:-1] + (4,))
    q[..., 3] = 1.0
    for k, axis in enumerate(axes):
        half = np.radians(degrees[..., k]) / 2
        turn = np.zeros(degrees.shape[:-1] + (4,))
        turn[..., "XYZ".index(axis.upper())] = np.sin(half)
        turn[..., 3] = np.cos(half)
        q = hamilton(q, turn)
    return q


def stored_quaternions(reference, xyz):
    """4.7: a quaternion node's rotation from its stored (..., 3) x, y, z and its reference (x, y,
    z, w): reference (x, y, z, sqrt(max(0, 1 - x^2 - y^2 - z^2))), normalized."""
    xyz = np.asarray(xyz, dtype=np.float64)
    w = np.sqrt(np.maximum(0.0, 1.0 - np.sum(xyz * xyz, axis=-1)))
    q = hamilton(np.broadcast_to(np.asarray(reference, dtype=np.float64), xyz.shape[:-1] + (4,)),
                 np.concatenate([xyz, w[..., None]], axis=-1))
    return q / np.linalg.norm(q, axis=-1, keepdims=True)


def rotation_angles(a, b):
    """The angle in radians of the rotation between unit quaternions a and b (..., 4), whatever
    their signs (q and -q are one rotation): 2 atan2(|v|, |w|) of conj(a) b."""
    conj = np.asarray(a, dtype=np.float64) * np.array([-1.0, -1.0, -1.0, 1.0])
    d = hamilton(conj, b)
    return 2.0 * np.arctan2(np.linalg.norm(d[..., :3], axis=-1), np.abs(d[..., 3]))


def quat_axes(clip, node):
    """The axes of a quaternion node's rotation channels in their order: 'ZYX' for the CMU
    joints."""
    return "".join(clip.channel_names[c].rsplit(":", 1)[1][0] for c in node["channels"])


def euler_channels(clip):
    """The channels whose values are their keys' (channel(c)['stored'] == 'value'): positions,
    and the Euler angles of nodes that are not quaternion nodes."""
    return [c for c in range(clip.channel_count) if clip.channel(c)["stored"] == "value"]


def assert_same_rotations(clip, a, b, bound=1e-5):
    """(frames, channels) values a and b of `clip`: every quaternion node's three rotation
    channels compose, as Euler angles, to the same rotation within `bound` radians."""
    for node in clip.quat_nodes:
        c, axes = list(node["channels"]), quat_axes(clip, node)
        angle = rotation_angles(euler_quaternions(a[..., c], axes), euler_quaternions(b[..., c], axes))
        assert angle.max() <= bound, (node["joint"], angle.max())


def assert_decoded_is_sampled(clip, decoded, sampled):
    """A Motion's channels decoded from `clip` (Clip.to_motion, float64) against sample_frames at
    the same positions (float32): channels stored as values bit for bit (the decoder's values are
    the sampler's); a quaternion node's, Euler angles of the same rotation (the decoder computes
    them in float64 and keeps them continuous from frame to frame, the sampler position by
    position), each angle within 180 degrees of the frame before."""
    assert decoded.dtype == np.float64 and sampled.dtype == np.float32 and decoded.shape == sampled.shape
    values = euler_channels(clip)
    assert np.array_equal(decoded[..., values], sampled[..., values].astype(np.float64))
    assert_same_rotations(clip, decoded, sampled)
    for node in clip.quat_nodes:
        steps = np.abs(np.diff(decoded[:, list(node["channels"])], axis=0))
        assert steps.size == 0 or steps.max() <= 180.0, node["joint"]


def skeleton_size(bvh):
    """Largest side of the rest pose's bounding box (OFFSETs alone)."""
    rest = np.zeros_like(bvh.offsets)
    for j, p in enumerate(bvh.parents):
        rest[j] = bvh.offsets[j] + (rest[p] if p >= 0 else 0)
    return float((rest.max(axis=0) - rest.min(axis=0)).max())


@pytest.fixture(scope="session")
def keyanim():
    import keyanim as module
    return module


@pytest.fixture(scope="session")
def walk(keyanim):
    return keyanim.read_bvh(WALK)


@pytest.fixture(scope="session")
def walk_bvh():
    return parse_bvh(WALK)


@pytest.fixture(scope="session")
def walk_encoded(keyanim, walk):
    return keyanim.encode(walk)


@pytest.fixture(scope="session")
def walk_clip(keyanim, walk_encoded):
    return keyanim.Clip(walk_encoded[0])


@pytest.fixture(scope="session")
def walk_euler_encoded(keyanim, walk):
    """The walk encoded with every rotation as its Euler channels (a 3.0 file)."""
    return keyanim.encode(walk, rotations="euler")


@pytest.fixture(scope="session")
def walk_euler_clip(keyanim, walk_euler_encoded):
    return keyanim.Clip(walk_euler_encoded[0])


@pytest.fixture
def python():
    return sys.executable
