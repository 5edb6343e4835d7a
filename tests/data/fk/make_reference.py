#!/usr/bin/env python3
"""Reference world positions for keyanim's forward-kinematics test (tests/unit/fk_test.cpp).

Two independent implementations, neither sharing code with keyanim:

  blender  Blender's own BVH importer (bpy.ops.import_anim.bvh) builds an armature; the world
           positions are read back from the posed bones. This writes the committed JSON files.
             blender -b --factory-startup --python make_reference.py -- \
                 blender CORPUS_DIR OUT_DIR cmu/assimp__01_01.bvh ...
  scipy    A small BVH parser below plus scipy.spatial.transform.Rotation (uppercase axes =
           intrinsic Euler angles), in float64. For every JSON written by the blender step it
           prints the largest Blender-scipy distance relative to the skeleton size and adds its
           own positions as "positions_f64" (Blender computes in float32).
             python3 make_reference.py scipy CORPUS_DIR OUT_DIR

See README.md beside this file for the exact commands and versions used.
"""
import json
import math
import os
import sys

FRAMES_PER_FILE = 5


def parse_bvh(path):
    """Nodes in file order: dicts with name, parent, end_site, offset, channels; and the frames."""
    with open(path, "r", newline=None) as f:  # universal newlines: CRLF, LF and mixed files
        tokens_by_line = [line.split() for line in f]
    nodes, stack, frames = [], [], []
    i = 0
    while i < len(tokens_by_line):
        t = tokens_by_line[i]
        i += 1
        if not t:
            continue
        key = t[0].upper()
        if key in ("ROOT", "JOINT"):
            nodes.append({"name": " ".join(t[1:]), "parent": stack[-1] if stack else -1,
                          "end_site": False, "offset": None, "channels": []})
        elif key == "END":
            nodes.append({"name": " ".join(t[2:]), "parent": stack[-1], "end_site": True,
                          "offset": None, "channels": []})
        elif key == "{":
            stack.append(len(nodes) - 1)
        elif key == "}":
            stack.pop()
        elif key == "OFFSET":
            nodes[stack[-1]]["offset"] = [float(v) for v in t[1:4]]
        elif key == "CHANNELS":
            nodes[stack[-1]]["channels"] = t[2:2 + int(t[1])]
        elif key == "MOTION":
            break
    count = sum(len(n["channels"]) for n in nodes)
    values = []
    for t in tokens_by_line[i:]:
        if t and t[0].upper() not in ("FRAMES:", "FRAME"):
            values.extend(float(v) for v in t)
    frames = [values[k:k + count] for k in range(0, len(values) - count + 1, count)]
    return nodes, frames


def skeleton_size(nodes):
    rest = []
    for n in nodes:
        base = rest[n["parent"]] if n["parent"] >= 0 else [0.0, 0.0, 0.0]
        rest.append([base[a] + n["offset"][a] for a in range(3)])
    return max(max(p[a] for p in rest) - min(p[a] for p in rest) for a in range(3))


def pick_frames(count):
    return sorted({0, count // 4, count // 2, (3 * count) // 4, count - 1})


def scipy_positions(nodes, row):
    from scipy.spatial.transform import Rotation
    world_rot, world_pos, col = [], [], 0
    for n in nodes:
        t = list(n["offset"])
        axes, angles = "", []
        for ch in n["channels"]:
            v = row[col]
            col += 1
            axis = ch[0].upper()
            if ch.lower().endswith("position"):
                t["XYZ".index(axis)] = v
            else:
                axes += axis
                angles.append(v)
        local = (Rotation.from_euler(axes, angles, degrees=True) if axes
                 else Rotation.identity())
        if n["parent"] < 0:
            world_pos.append(t)
            world_rot.append(local)
        else:
            pr = world_rot[n["parent"]]
            pp = world_pos[n["parent"]]
            d = pr.apply(t)
            world_pos.append([pp[a] + d[a] for a in range(3)])
            world_rot.append(pr * local)
    return world_pos


def blender_positions(path, nodes, frames):
    import builtins

    import bpy
    import io_anim_bvh.import_bvh as importer
    # Debian's Blender 3.4.1 importer opens files with mode 'rU', which Python 3.11 rejects;
    # shadow open() inside that module only, with the same universal-newline reading.
    importer.open = lambda p, mode="r", *a, **k: builtins.open(p, mode.replace("U", ""), *a, **k)

    bpy.ops.wm.read_factory_settings(use_empty=True)
    # axis_forward='Y', axis_up='Z' is Blender's own frame: the importer's axis conversion is
    # the identity, so the positions are in the file's coordinates (checked below).
    bpy.ops.import_anim.bvh(filepath=path, rotate_mode="NATIVE", global_scale=1.0,
                            axis_forward="Y", axis_up="Z", frame_start=1,
                            use_fps_scale=False, update_scene_fps=False)
    arm = next(o for o in bpy.data.objects if o.type == "ARMATURE")
    mw = arm.matrix_world
    assert all(abs(mw[r][c] - (1.0 if r == c else 0.0)) < 1e-12
               for r in range(4) for c in range(4)), mw
    scene = bpy.context.scene
    out = []
    for f in frames:
        scene.frame_set(f + 1)  # Blender frame 1 holds BVH frame 0
        row = []
        for j, n in enumerate(nodes):
            if not n["end_site"]:
                p = mw @ arm.pose.bones[n["name"]].head
            else:
                # The importer makes an End Site the tail of its parent's bone, except that a
                # tail within 0.001 of the head is moved (bones cannot have zero length).
                length = math.sqrt(sum(v * v for v in n["offset"]))
                parent = arm.pose.bones[nodes[n["parent"]]["name"]]
                if length == 0.0:
                    p = mw @ parent.head  # a zero-length End Site sits on its parent
                else:
                    assert length > 0.001, (path, j)
                    p = mw @ parent.tail
            row.append([p[0], p[1], p[2]])
        out.append(row)
    return out


def main_blender(corpus, out_dir, files):
    import bpy
    version = "Blender " + bpy.app.version_string
    for rel in files:
        path = os.path.join(corpus, rel)
        nodes, all_frames = parse_bvh(path)
        names = [n["name"] for n in nodes if not n["end_site"]]
        assert len(set(names)) == len(names) and max(map(len, names)) < 64, "bone names"
        frames = pick_frames(len(all_frames))
        positions = blender_positions(path, nodes, frames)
        doc = {
            "source": rel,
            "generator": version + " bpy.ops.import_anim.bvh(rotate_mode='NATIVE', "
                         "global_scale=1, axis_forward='Y', axis_up='Z'); pose bone heads, "
                         "End Sites as leaf bone tails",
            "frames": frames,
            "nodes": [{"name": n["name"], "parent": n["parent"], "end_site": n["end_site"]}
                      for n in nodes],
            # positions_blender[k] is frame frames[k]: x, y, z of every node in order. Blender
            # computes in float32, so 9 significant digits keep all it knows.
            "positions_blender": [[float("%.9g" % v) for p in row for v in p] for row in positions],
        }
        name = os.path.splitext(os.path.basename(rel))[0] + ".json"
        with open(os.path.join(out_dir, name), "w") as f:
            json.dump(doc, f, separators=(",", ":"))
            f.write("\n")
        print("wrote", name, len(nodes), "nodes, frames", frames)


def main_scipy(corpus, out_dir):
    import scipy
    print("scipy", scipy.__version__)
    for name in sorted(os.listdir(out_dir)):
        if not name.endswith(".json"):
            continue
        path = os.path.join(out_dir, name)
        with open(path) as f:
            doc = json.load(f)
        nodes, all_frames = parse_bvh(os.path.join(corpus, doc["source"]))
        size = skeleton_size(nodes)
        worst = 0.0
        f64 = []
        for k, f in enumerate(doc["frames"]):
            ref = scipy_positions(nodes, all_frames[f])
            got = doc["positions_blender"][k]
            for j, p in enumerate(ref):
                d = math.sqrt(sum((p[a] - got[3 * j + a]) ** 2 for a in range(3)))
                worst = max(worst, d)
            f64.append([float("%.12g" % v) for p in ref for v in p])  # far below the tolerance
        print("%s: skeleton size %.6g, largest Blender-scipy distance %.3g (%.3g of size)"
              % (name, size, worst, worst / size))
        doc["generator_f64"] = ("scipy %s Rotation.from_euler (intrinsic, degrees), float64"
                                % scipy.__version__)
        doc["skeleton_size"] = float("%.12g" % size)  # rest pose from OFFSETs, End Sites in
        doc["positions_f64"] = f64
        with open(path, "w") as f:
            json.dump(doc, f, separators=(",", ":"))
            f.write("\n")


if __name__ == "__main__":
    argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else sys.argv[1:]
    if argv[0] == "blender":
        main_blender(argv[1], argv[2], argv[3:])
    elif argv[0] == "scipy":
        main_scipy(argv[1], argv[2])
    else:
        sys.exit(__doc__)
