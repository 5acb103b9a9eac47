"""Blender's own Inherit Scale modes as a judge of bonescope's (tests/blender_modes.rs runs it).

blender's Python module: python fix_shear.py FILE OUT.json

Imports FILE (.glb or .fbx) with Blender's importer, sets every bone's Inherit Scale to each of FULL and FIX_SHEAR
in turn, and writes per mode and per frame of the scene's first clip every bone's world matrix (column-major).
"""

import json
import sys

import bpy


def main():
    path, out = sys.argv[1:3]
    bpy.ops.wm.read_factory_settings(use_empty=True)
    if path.lower().endswith(".fbx"):
        bpy.ops.import_scene.fbx(filepath=path)
    else:
        bpy.ops.import_scene.gltf(filepath=path)
    scene = bpy.context.scene
    armature = next(o for o in scene.objects if o.type == "ARMATURE")
    start, end = (int(f) for f in armature.animation_data.action.frame_range)
    played = {}
    for mode in ("FULL", "FIX_SHEAR"):
        bpy.context.view_layer.objects.active = armature
        bpy.ops.object.mode_set(mode="EDIT")
        for bone in armature.data.edit_bones:
            bone.inherit_scale = mode
        bpy.ops.object.mode_set(mode="OBJECT")
        frames = []
        for frame in range(start, end + 1):
            scene.frame_set(frame)
            evaluated = armature.evaluated_get(bpy.context.evaluated_depsgraph_get())
            world = evaluated.matrix_world
            bones = {}
            for bone in evaluated.pose.bones:
                m = world @ bone.matrix
                bones[bone.name] = [m[row][col] for col in range(4) for row in range(4)]
            frames.append(bones)
        played[mode] = frames
    with open(out, "w") as f:
        json.dump(played, f)


main()
