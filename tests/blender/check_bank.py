"""blender_bank: check_bank.py -- WORKDIR FILE.bvh FILE.bvh  (inside Blender, common.py says how)

The BVH files are packed into a bank by `keyanim pack`; File > Import > keyanim on the bank
imports the clip named in Clip (the second one here: not the default), whose bone heads at its
first, middle and last frames equal `keyanim sample BANK:NAME --world` within the float margin;
the Clip field suggests the bank's names; with no name the first clip comes in; a name the bank
lacks is refused with a report naming the file and the clips it has."""
import os
import sys

import bpy

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import common  # noqa: E402
from common import check  # noqa: E402


def import_bank(bank, clip):
    for obj in list(bpy.data.objects):
        bpy.data.objects.remove(obj)
    try:
        return bpy.ops.import_anim.keyanim(filepath=bank, clip=clip), ""
    except RuntimeError as e:  # how bpy.ops hands a script the operator's ERROR report
        return None, str(e)


def main():
    work, files = common.args()[0], common.args()[1:]
    addon = common.enable_addon()
    inputs = os.path.join(work, "bank-inputs")
    os.makedirs(inputs, exist_ok=True)
    for f in files:
        os.symlink(os.path.abspath(f), os.path.join(inputs, os.path.basename(f)))
    bank = os.path.join(work, "clips.kbank")
    common.tool("-q", "pack", inputs, "-o", bank)
    names = [c["name"] for c in common.tool_json("list", bank)["clips"]]
    check(len(names) == len(files), "the bank holds %d clips: %s" % (len(names), names))
    op = type("Op", (), {"filepath": bank})()
    check(addon.import_kanim._clip_names(op, bpy.context, "") == names, "the Clip field suggests the bank's names")
    name = names[1]
    check(import_bank(bank, name)[0] == {"FINISHED"}, "import %s clip %s" % (bank, name))
    obj = bpy.context.active_object
    info = common.tool_json("info", "%s:%s" % (bank, name))
    n, size = info["frames"], info["size"]
    check(bpy.context.scene.frame_end == n and obj.animation_data.action.name.startswith(name),
          "clip %s: %d frames, its action named after it" % (name, n))
    for f in sorted({0, (n - 1) // 2, n - 1}):
        common.compare_pose(obj, 1 + f, common.reference("%s:%s" % (bank, name), f), common.FLOAT_MARGIN * size,
                            "%s frame %d" % (name, f))
    result, _ = import_bank(bank, "")
    check(result == {"FINISHED"} and bpy.context.active_object.name.startswith(names[0]), "no name: the first clip")
    result, said = import_bank(bank, "no such clip")
    check(result is None and bank in said and names[0] in said, "an unknown clip is refused, naming the bank: %r" % said.strip())
    common.finish()


main()
