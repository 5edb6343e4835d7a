"""Checks a glTF export of a chain BVH (hostile_test.sh's chain_bvh: joints one below the other,
OFFSET 0 1 0, one Zrotation each, and an End Site), sharing no code with keyanim: the GLB's layout
(glTF 2.0, section 4.4), the node chain and its rest translations, and its rotations played as the
specification samples them (appendix C) against the BVH's forward kinematics at every frame, for
every joint and the End Site, within the tolerance the export states (asset.extras.keyanim).
usage: check_chain_glb.py OUT.glb CLIP.bvh   (CLIP: the exported .kanim decoded to BVH)"""
import json
import math
import struct
import sys


def need(ok, what):
    if not ok:
        sys.exit("check_chain_glb: " + what)


def read_glb(path):
    data = open(path, "rb").read()
    magic, version, length = struct.unpack_from("<4sII", data, 0)
    need(magic == b"glTF" and version == 2 and length == len(data), "the GLB header is wrong")
    json_length, json_type = struct.unpack_from("<II", data, 12)
    need(json_type == 0x4E4F534A, "the GLB lacks its JSON chunk")
    gltf = json.loads(data[20:20 + json_length])
    bin_length, bin_type = struct.unpack_from("<II", data, 20 + json_length)
    need(bin_type == 0x004E4942 and bin_length == gltf["buffers"][0]["byteLength"], "the GLB lacks its BIN chunk")
    return gltf, data[28 + json_length:28 + json_length + bin_length]


def read_chain_bvh(path):
    """Joint count, frame time and per frame the Zrotation of every joint (degrees)."""
    lines = [line.strip() for line in open(path)]
    motion = lines.index("MOTION")
    head = lines[:motion]
    joints = sum(1 for line in head if line.split()[:1] in (["ROOT"], ["JOINT"]))
    need(all(line == "OFFSET 0 1 0" for line in head if line.startswith("OFFSET")), "the BVH is not a chain of unit offsets")
    need(sum(1 for line in head if line == "CHANNELS 1 Zrotation") == joints, "the BVH has other channels than Zrotation")
    frame_time = float(lines[motion + 2].split(":")[1])
    frames = [[float(v) for v in line.split()] for line in lines[motion + 3:] if line]
    need(all(len(row) == joints for row in frames), "a BVH frame is not one value a joint")
    return joints, frame_time, frames


def accessor(gltf, buffer, index):
    a = gltf["accessors"][index]
    view = gltf["bufferViews"][a["bufferView"]]
    width = {"SCALAR": 1, "VEC4": 4}[a["type"]]
    start = view.get("byteOffset", 0) + a.get("byteOffset", 0)
    need(a["componentType"] == 5126 and start + 4 * width * a["count"] <= len(buffer), "accessor %d is out of its buffer" % index)
    flat = struct.unpack_from("<%df" % (width * a["count"]), buffer, start)
    return [flat[k:k + width] for k in range(0, len(flat), width)]


def sample(times, values, cubic, t):
    """A rotation sampler at time t (glTF 2.0 appendix C: LINEAR slerp, CUBICSPLINE normalised)."""
    value = (lambda k: values[3 * k + 1]) if cubic else (lambda k: values[k])
    if len(times) == 1 or t <= times[0]:
        q = value(0)
    elif t >= times[-1]:
        q = value(len(times) - 1)
    else:
        k = max(i for i in range(len(times)) if times[i] <= t)
        td = times[k + 1] - times[k]
        u = (t - times[k]) / td
        if cubic:
            v0, b0, a1, v1 = values[3 * k + 1], values[3 * k + 2], values[3 * k + 3], values[3 * k + 4]
            h = (2 * u**3 - 3 * u**2 + 1, td * (u**3 - 2 * u**2 + u), -2 * u**3 + 3 * u**2, td * (u**3 - u**2))
            q = [h[0] * v0[c] + h[1] * b0[c] + h[2] * v1[c] + h[3] * a1[c] for c in range(4)]
        else:
            a, b = value(k), value(k + 1)
            dot = sum(x * y for x, y in zip(a, b))
            if dot < 0:
                b, dot = [-x for x in b], -dot
            theta = math.acos(min(1.0, dot))
            w0, w1 = (math.sin((1 - u) * theta), math.sin(u * theta)) if theta > 1e-9 else (1 - u, u)
            q = [w0 * x + w1 * y for x, y in zip(a, b)]
    norm = math.sqrt(sum(x * x for x in q))
    return tuple(x / norm for x in q)


def qmul(a, b):
    ax, ay, az, aw = a
    bx, by, bz, bw = b
    return (aw * bx + ax * bw + ay * bz - az * by, aw * by - ax * bz + ay * bw + az * bx,
            aw * bz + ax * by - ay * bx + az * bw, aw * bw - ax * bx - ay * by - az * bz)


def up(q):
    """(0, 1, 0) rotated by q."""
    x, y, z, w = q
    return (2 * (x * y - w * z), 1 - 2 * (x * x + z * z), 2 * (y * z + w * x))


def main():
    gltf, buffer = read_glb(sys.argv[1])
    joints, frame_time, frames = read_chain_bvh(sys.argv[2])
    nodes = gltf["nodes"][:joints + 1]
    need(len(gltf["nodes"]) == joints + 2, "%d nodes for %d joints, an End Site and the bone mesh" % (len(gltf["nodes"]), joints))
    need(gltf["nodes"][-1] == {"name": "keyanim bones", "mesh": 0, "skin": 0}, "the last node is not the skinned bone mesh")
    need(gltf["skins"][0]["joints"] == list(range(joints + 1)), "the skin's joints are not the chain")
    for i, node in enumerate(nodes):
        need(node.get("children", []) == ([i + 1] if i < joints else []), "node %d is not a link of the chain" % i)
        need(node.get("translation") == [0, 1, 0], "node %d is not at its OFFSET" % i)
    need(gltf["scenes"][gltf.get("scene", 0)]["nodes"] == [0, joints + 1], "the scene is not the chain's root and the mesh")
    (animation,) = gltf["animations"]
    local = [[(0.0, 0.0, 0.0, 1.0)] * len(frames) for _ in nodes]
    for channel in animation["channels"]:
        sampler = animation["samplers"][channel["sampler"]]
        need(channel["target"]["path"] == "rotation", "a channel animates more than a rotation")
        times = [t[0] for t in accessor(gltf, buffer, sampler["input"])]
        values = accessor(gltf, buffer, sampler["output"])
        cubic = sampler.get("interpolation", "LINEAR") == "CUBICSPLINE"
        need(all(a < b for a, b in zip(times, times[1:])) and len(values) == len(times) * (3 if cubic else 1),
             "a sampler is malformed")
        local[channel["target"]["node"]] = [sample(times, values, cubic, f * frame_time) for f in range(len(frames))]
    tolerance = gltf["asset"]["extras"]["keyanim"]["tolerance"]
    worst = 0.0
    for f, row in enumerate(frames):
        played = clip = (0.0, 1.0, 0.0)  # the root at its OFFSET
        played_q = clip_q = (0.0, 0.0, 0.0, 1.0)
        for i in range(joints):
            played_q = qmul(played_q, local[i][f])
            half = math.radians(row[i]) / 2
            clip_q = qmul(clip_q, (0.0, 0.0, math.sin(half), math.cos(half)))
            played = tuple(p + d for p, d in zip(played, up(played_q)))
            clip = tuple(p + d for p, d in zip(clip, up(clip_q)))
            worst = max(worst, math.dist(played, clip))
    need(worst <= tolerance, "the export plays %g from the clip, beyond its tolerance %g" % (worst, tolerance))
    print("%d nodes, %d rotation tracks, within %g of the clip (tolerance %g)" % (len(nodes), len(animation["channels"]), worst, tolerance))


main()
