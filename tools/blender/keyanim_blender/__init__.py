"""keyanim for Blender: File > Import > keyanim (.kanim, .kbank), File > Import > BVH (keyanim),
File > Export > keyanim, through the keyanim Python module (module.py says where it is found).

Convention: an armature's own space is the file's (BVH is usually Y up); the armature object is
turned +90 degrees about X so that the motion stands up in Blender's Z-up world. A bone per BVH
node (End Sites are leaf bones), named as the joints; the scene takes the clip's rate and range,
its first frame at Start Frame (1 by default, Blender's own). README.md, "In Blender", has more.
"""
bl_info = {
    "name": "keyanim",
    "author": "keyanim",
    "version": (0, 2, 0),
    "blender": (3, 3, 0),  # StringProperty(search=...), the Clip field's suggestions
    "location": "File > Import > keyanim / BVH (keyanim), File > Export > keyanim",
    "description": "Import and export keyanim clips (.kanim, .kbank) and read BVH exactly",
    "category": "Import-Export",
}

import bpy

from . import export_kanim, import_bvh, import_kanim, prefs

CLASSES = (prefs.KeyanimPreferences, import_kanim.ImportKanim, import_bvh.ImportBvhKeyanim, export_kanim.ExportKanim)


def _menu_import(self, context):
    self.layout.operator(import_kanim.ImportKanim.bl_idname, text="keyanim (.kanim, .kbank)")
    self.layout.operator(import_bvh.ImportBvhKeyanim.bl_idname, text="BVH (keyanim) (.bvh)")


def _menu_export(self, context):
    self.layout.operator(export_kanim.ExportKanim.bl_idname, text="keyanim (.kanim)")


def register():
    for cls in CLASSES:
        bpy.utils.register_class(cls)
    bpy.types.TOPBAR_MT_file_import.append(_menu_import)
    bpy.types.TOPBAR_MT_file_export.append(_menu_export)


def unregister():
    bpy.types.TOPBAR_MT_file_export.remove(_menu_export)
    bpy.types.TOPBAR_MT_file_import.remove(_menu_import)
    for cls in reversed(CLASSES):
        bpy.utils.unregister_class(cls)
