"""bonescope inside Blender: which bones of the active armature shear, and the cheapest fix of each.

Install the bonescope wheel into Blender's Python once (`<blender>/<version>/python/bin/python3.11 -m pip install
--no-deps bonescope-*.whl`: Blender's own numpy stays), then either run this file in Blender's Text Editor (Run Script) with an armature active, or install
it as an add-on (Edit → Preferences → Add-ons → Install) and use Object → bonescope: check shear. The armature is
exported with Blender's own glTF exporter to a temporary file, analysed by bonescope in the same Python, and each
stretched bone is reported with its worst shear, its main cause and its best fix.
"""

import os
import tempfile

import bpy

import bonescope

bl_info = {
    "name": "bonescope: check shear",
    "description": "Find the bones whose scale turns into shear, and the cheapest fix of each",
    "blender": (4, 2, 0),
    "category": "Animation",
}


def check(armature, say):
    """Exports `armature` (with its animation) to glTF, scans it with bonescope, and says one line per stretched
    bone (`say(level, text)`); returns the scan's explained bones."""
    selected = list(bpy.context.selected_objects)
    for obj in selected:
        obj.select_set(False)
    armature.select_set(True)
    for child in armature.children:
        child.select_set(True)
    with tempfile.TemporaryDirectory() as folder:
        path = os.path.join(folder, "armature.glb")
        bpy.ops.export_scene.gltf(filepath=path, export_format="GLB", use_selection=True, export_animations=True)
        report = bonescope.load(path).scan(explain=True)
    for obj in bpy.context.selected_objects:
        obj.select_set(obj in selected)
    explained = [bone for animation in report["animations"] for bone in animation.get("explained", [])]
    for animation in report["animations"]:
        name = (animation["animation"] or {}).get("name") or "rest pose"
        for bone in animation["stretched"]:
            say("WARNING", f"{name}: {bone['name']} shears {bone['worst_shear_deg']:.2f}° at {bone['worst_shear_time']:.3f} s")
        for bone in animation.get("explained", []):
            say("INFO", f"{name}: {bone['line']}")
    if not explained:
        say("INFO", f"{armature.name}: no bone shears")
    return explained


class BONESCOPE_OT_check_shear(bpy.types.Operator):
    """Find the bones of the active armature whose scale turns into shear, and the cheapest fix of each"""

    bl_idname = "object.bonescope_check_shear"
    bl_label = "bonescope: check shear"

    @classmethod
    def poll(cls, context):
        return context.active_object is not None and context.active_object.type == "ARMATURE"

    def execute(self, context):
        check(context.active_object, lambda level, text: self.report({level}, text))
        return {"FINISHED"}


def menu(self, context):
    self.layout.operator(BONESCOPE_OT_check_shear.bl_idname)


def register():
    bpy.utils.register_class(BONESCOPE_OT_check_shear)
    bpy.types.VIEW3D_MT_object.append(menu)


def unregister():
    bpy.types.VIEW3D_MT_object.remove(menu)
    bpy.utils.unregister_class(BONESCOPE_OT_check_shear)


if __name__ == "__main__":
    active = bpy.context.active_object
    if active is None or active.type != "ARMATURE":
        print("bonescope: make an armature the active object first")
    else:
        check(active, lambda level, text: print(f"{level}: {text}"))
