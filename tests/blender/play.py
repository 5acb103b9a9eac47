"""Blender's glTF and USD importers as judges of `bonescope bake` (tests/blender.rs runs it).

blender's Python module: python play.py FILE.glb|FILE.usd[acz] TIMES.json OUT.json

Imports FILE into an empty scene as Blender's own importer does, plays it at each time of TIMES.json (for glTF
seconds, frames of the scene's rate with subframes between; for USD time codes, which Blender's USD importer makes
its frames), and writes per time the origin of every bone and of every other node not hung on a bone, and every
skinned mesh's evaluated vertices in world space, turned back into the file's Y-up axes (Blender is Z-up, glTF and
bonescope's USD Y-up: (x, y, z) = Blender (x, z, -y)). Origins and skinned vertices do not depend on the importer's
choice of bone orientation.
"""

import json
import math
import sys

import bpy


def gltf_axes(v):
    return [v.x, v.z, -v.y]


def main():
    path, times_file, out = sys.argv[1:4]
    bpy.ops.wm.read_factory_settings(use_empty=True)
    usd = path.lower().endswith((".usd", ".usda", ".usdc", ".usdz"))
    if usd:
        bpy.ops.wm.usd_import(filepath=path)
    else:
        bpy.ops.import_scene.gltf(filepath=path)
    scene = bpy.context.scene
    fps = scene.render.fps / scene.render.fps_base
    with open(times_file) as f:
        times = json.load(f)
    played = []
    for time in times:
        frame = time if usd else time * fps
        whole = math.floor(frame)
        scene.frame_set(whole, subframe=frame - whole)
        depsgraph = bpy.context.evaluated_depsgraph_get()
        origins = {}
        bones = {}
        vertices = []
        for ob in scene.objects:
            evaluated = ob.evaluated_get(depsgraph)
            world = evaluated.matrix_world
            skinned = any(m.type == "ARMATURE" for m in ob.modifiers)
            # Objects hung on a bone are placed from the bone's tail, which the importer's bone orientation moves,
            # and a skinned mesh's object is not its glTF node: only the others are nodes as glTF places them.
            if ob.type != "ARMATURE" and ob.parent_type != "BONE" and not skinned:
                origins[ob.name] = gltf_axes(world.translation)
            if ob.type == "ARMATURE":
                for bone in evaluated.pose.bones:
                    bones[bone.name] = gltf_axes(world @ bone.head)
            if ob.type == "MESH" and skinned:
                mesh = evaluated.to_mesh()
                vertices.extend(gltf_axes(world @ v.co) for v in mesh.vertices)
                evaluated.to_mesh_clear()
        origins.update(bones)
        played.append({"origins": origins, "vertices": vertices})
    with open(out, "w") as f:
        json.dump({"fps": fps, "played": played}, f)


main()
