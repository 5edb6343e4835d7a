# Plays a glTF export in Blender (its bundled glTF importer) and writes the world matrix of every
# node at every source frame, in glTF's axes (Y up), as JSON for blender_compare.mjs.
#   blender -b --factory-startup --python tests/gltf/blender_play.py -- IN.glb FRAMES FRAME_TIME OUT.json
# Nodes are matched by name (keyanim names End Sites "End Site of PARENT"; names are unique in
# the corpus). The export's nodes are the joints of a skin, so Blender makes them bones of one
# armature: imported with the "Blender" bone heuristic, every bone is its node turned by a fixed
# 90 degrees about x (the importer's pick_bone_rotation), undone here; the bone mesh is imported
# with Shading "Flat" (Debian's Blender 3.4 fails on any mesh with the default, see README).
import json
import math
import sys

import bpy
from mathutils import Matrix

glb, frames, frame_time, out = sys.argv[sys.argv.index("--") + 1:]
frames, frame_time = int(frames), float(frame_time)

bpy.ops.wm.read_factory_settings(use_empty=True)
bpy.ops.import_scene.gltf(filepath=glb, import_shading="FLAT", bone_heuristic="BLENDER")
scene = bpy.context.scene
fps = scene.render.fps / scene.render.fps_base  # the importer put time t at frame t * fps

with open(glb, "rb") as f:
    data = f.read()
json_len = int.from_bytes(data[12:16], "little")
names = [n.get("name", "") for n in json.loads(data[20:20 + json_len])["nodes"]]
(arm,) = [o for o in bpy.data.objects if o.type == "ARMATURE"]
unturn = Matrix.Rotation(-math.pi / 2, 4, "X")
names = names[:len(arm.pose.bones)]  # the joints come first, the bone mesh's node after them


def world(name):
    return arm.matrix_world @ arm.pose.bones[name].matrix @ unturn

# Blender is Z up: the importer maps a glTF point p to C p with C (x, y, z) = (x, -z, y), so a
# Blender world matrix M is C M_gltf C^-1 and M_gltf = C^-1 M C: rows (x, y, z) -> (x, z, -y),
# then columns: column y is C^-1 M C e_y = C^-1 M e_z, column z is -C^-1 M e_y. Returns the
# 3 x 4 [R | t] rows.
def to_gltf(m):
    x, y, z = ([m[r][c] for c in range(4)] for r in range(3))
    rows = [x, z, [-v for v in y]]
    return [[r[0], r[2], -r[1], r[3]] for r in rows]

result = []
for f in range(frames):
    t = f * frame_time * fps
    scene.frame_set(int(t), subframe=t - int(t))
    result.append([to_gltf(world(n)) for n in names])
with open(out, "w") as f:
    json.dump({"blender": bpy.app.version_string, "matrices": result}, f)
