# Imports a keyanim glTF export with Blender's own glTF importer, as an animator would, and checks
# what issue 27 asks of it (blender_skin_check.sh prepares the reference and says the procedure):
#   blender -b --factory-startup --python-exit-code 1 -P blender_skin.py -- IN.glb FPS SHADING REFERENCE.json
# FPS: the scene's frame rate set before the import (Blender 3.4's importer places a key at time
# t on frame t * scene fps and reads no rate from the file). SHADING: the importer's Shading
# option (Debian's Blender 3.4 fails on any mesh with the default NORMALS, see README).
# REFERENCE.json (keyanim sample --world --json of the .kanim): {"frames", "tolerance",
# "margin", "names": [...], "poses": {"FRAME": {name: [x, y, z]}}}, positions in glTF's axes.
# Checks: one armature object, one action (the armature's), bones named as the reference's
# joints and End Sites, the action's frame range 0 .. frames-1, the file's timing extras kept as
# the scene's "keyanim" property, and every bone's head at each reference frame within
# tolerance + margin; where the bone mesh is imported, its bone ends follow the bones.
import json
import sys

import bpy
from mathutils import Vector

glb, fps, shading, reference = sys.argv[sys.argv.index("--") + 1:]
ref = json.load(open(reference))
problems = []


def need(ok, what):
    if not ok:
        problems.append(what)


bpy.ops.wm.read_factory_settings(use_empty=True)
scene = bpy.context.scene
scene.render.fps, scene.render.fps_base = int(fps), 1.0
bpy.ops.import_scene.gltf(filepath=glb, import_shading=shading)

armatures = [o for o in bpy.data.objects if o.type == "ARMATURE"]
need(len(armatures) == 1, "%d armature objects" % len(armatures))
need(len(bpy.data.actions) == 1, "%d actions: %s" % (len(bpy.data.actions), [a.name for a in bpy.data.actions]))
arm = armatures[0]
action = arm.animation_data.action if arm.animation_data else None
need(action is not None and action == bpy.data.actions[0], "the armature does not play the action")
need([b.name for b in arm.data.bones] == ref["names"], "bones %s, expected %s" % ([b.name for b in arm.data.bones], ref["names"]))
frames = ref["frames"]
start, end = action.frame_range
need(start == 0 and round(end) == frames - 1 and abs(end - (frames - 1)) < 0.01,
     "the action spans frames %g to %g, the clip 0 to %d" % (start, end, frames - 1))
timing = scene.get("keyanim")
need(timing is not None and timing["frame_count"] == frames and round(timing["fps"]) == int(fps),
     "the scene's keyanim property is %s" % (dict(timing) if timing else None))
# What a user does next (Blender 3.4 leaves the scene at 1 .. 250): the clip's range.
scene.frame_start, scene.frame_end = 0, frames - 1


def gltf_axes(p):  # Blender is Z up: the importer maps glTF (x, y, z) to (x, -z, y)
    return [p[0], p[2], -p[1]]


meshes = [o for o in bpy.data.objects if o.type == "MESH"]
bound = ref["tolerance"] + ref["margin"]
worst = 0.0
for frame, pose in ref["poses"].items():
    scene.frame_set(int(frame))
    heads = {pb.name: arm.matrix_world @ pb.head for pb in arm.pose.bones}
    for name, want in pose.items():
        e = (Vector(gltf_axes(heads[name])) - Vector(want)).length
        worst = max(worst, e)
        need(e <= bound, "frame %s, %s: %g from keyanim sample, beyond %g" % (frame, name, e, bound))
    for mesh in meshes:  # each bone end of the mesh (a vertex at its bone's rest head) on that bone's head
        evaluated = mesh.evaluated_get(bpy.context.evaluated_depsgraph_get()).data
        ends = 0
        for v, moved in zip(mesh.data.vertices, evaluated.vertices):
            bone = arm.data.bones[mesh.vertex_groups[v.groups[0].group].name]
            if (mesh.matrix_world @ v.co - arm.matrix_world @ bone.head_local).length < 1e-5 * max(1.0, bone.head_local.length):
                ends += 1
                e = (mesh.matrix_world @ moved.co - heads[bone.name]).length
                need(e <= bound, "frame %s: the mesh's end of %s is %g from the bone's head" % (frame, bone.name, e))
        need(ends > 0, "no bone end found in the mesh")
print("%s: Blender %s, %d bones, 1 armature, 1 action over frames 0-%d at %s fps; heads within %.3f of the tolerance%s" %
      (glb, bpy.app.version_string, len(arm.data.bones), frames - 1, fps, worst / ref["tolerance"],
       ", the bone mesh follows" if meshes else ""))
if problems:
    raise SystemExit("FAIL " + glb + ":\n  " + "\n  ".join(problems[:20]))
