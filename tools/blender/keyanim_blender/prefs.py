"""The add-on's preference: where the keyanim module is, for a build tree or a custom prefix
(module.py says where it is looked for without it)."""
import bpy
from bpy.props import StringProperty

ADDON = __package__


class KeyanimPreferences(bpy.types.AddonPreferences):
    bl_idname = ADDON
    module_dir: StringProperty(
        name="keyanim module directory", subtype="DIR_PATH",
        description="Directory holding the keyanim package (e.g. a build tree's build/python); empty: "
                    "where it is installed. Read when the module is first imported: restart Blender after a change")

    def draw(self, context):
        self.layout.prop(self, "module_dir")


def module_dir(context):
    addon = context.preferences.addons.get(ADDON)
    return addon.preferences.module_dir if addon else ""
