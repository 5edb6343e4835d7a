# Plays a glTF export in Blender (its bundled glTF importer) and writes the world matrix of every
# node at every source frame, in glTF's axes (Y up), as JSON for blender_compare.mjs.
#   blender -b --factory-startup --python tests/gltf/blender_play.py -- IN.glb FRAMES FRAME_TIME OUT.json
# Nodes are matched by name (keyanim names End Sites PARENT_End; names are unique in the corpus).
import json
import sys

import bpy

glb, frames, frame_time, out = sys.argv[sys.argv.index("--") + 1:]
frames, frame_time = int(frames), float(frame_time)

bpy.ops.wm.read_factory_settings(use_empty=True)
bpy.ops.import_scene.gltf(filepath=glb)
scene = bpy.context.scene
fps = scene.render.fps / scene.render.fps_base  # the importer put time t at frame t * fps

with open(glb, "rb") as f:
    data = f.read()
json_len = int.from_bytes(data[12:16], "little")
names = [n.get("name", "") for n in json.loads(data[20:20 + json_len])["nodes"]]
objects = [bpy.data.objects[n] for n in names]

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
    result.append([to_gltf(o.matrix_world) for o in objects])
with open(out, "w") as f:
    json.dump({"blender": bpy.app.version_string, "matrices": result}, f)
