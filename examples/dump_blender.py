"""A pose dump (docs/pose-dump.md) of what Blender plays: a glTF or FBX file imported by Blender's own importer, its
action played, every armature's and pose bone's world matrix written at every key of the action. Compare it with the
source:

    pip install "bpy==4.5.*"                          # Blender as a Python 3.11 module, or run Blender itself:
    python examples/dump_blender.py FILE.glb|FILE.fbx OUT.dump.json [CLIP]
    blender --background --python examples/dump_blender.py -- FILE OUT.dump.json [CLIP]
    bonescope fit FILE OUT.dump.json

CLIP is the action's name (default: the one the importer assigned). The dump is written to a file, not to standard
output, where Blender and its importers print their logs.

Matrices are `armature.matrix_world @ pose_bone.matrix` (column-major), in Blender's metres and axes: Z up, which the
header says and bonescope turns back into the file's Y up. Blender's bones point along their own Y axis, so its
importers may turn a bone's axes away from the file's joint; the bone's head is the joint's origin whatever they do.
The axes are the file's too as imported here: glTF with `bone_heuristic='BLENDER'` (each bone's axes are its node's,
Y up turned to Z up) and FBX with the default bone axes (`primary_bone_axis='Y'`, no automatic orientation).
"""

import json
import math
import sys

import bpy
from mathutils import Matrix


def import_file(path):
    """Imports `path` into an empty scene with Blender's own importer for its extension; whether it is glTF."""
    bpy.ops.wm.read_factory_settings(use_empty=True)
    gltf = not path.lower().endswith(".fbx")
    if gltf:
        # The default heuristic turns each bone towards its child; 'BLENDER' keeps the node's axes.
        bpy.ops.import_scene.gltf(filepath=path, bone_heuristic="BLENDER")
    else:
        # Keys at the file's own times: by default the importer starts them at frame 1, not 0.
        bpy.ops.import_scene.fbx(filepath=path, anim_offset=0.0)
    return gltf


def armatures_playing(clip):
    """The armatures with an action, `clip` assigned to each where given; and the action they play."""
    armatures = [ob for ob in bpy.context.scene.objects if ob.type == "ARMATURE"]
    if clip is not None:
        action = bpy.data.actions.get(clip)
        if action is None:
            sys.exit(f"no action {clip}: {[a.name for a in bpy.data.actions]}")
        for ob in armatures:
            ob.animation_data_create().action = action
    playing = [ob for ob in armatures if ob.animation_data and ob.animation_data.action]
    if not playing:
        sys.exit("no armature plays an action")
    return playing, playing[0].animation_data.action


def curves(action):
    """The F-curves of `action`: in its layers' channel bags (Blender 4.4's slotted actions; 5.0 has no other way),
    else in its own list."""
    if getattr(action, "layers", None):
        bags = [bag for layer in action.layers for strip in layer.strips for bag in strip.channelbags]
        return [curve for bag in bags for curve in bag.fcurves]
    return list(action.fcurves)


def key_frames(action):
    """Every frame that holds a key of `action`, in order. Sampled there, the dump depends less on how Blender
    interpolates between keys (quaternions component by component; glTF's cubic splines with handles of its own),
    though a channel keyed at other frames than the rest is still interpolated at theirs."""
    return sorted({key.co.x for curve in curves(action) for key in curve.keyframe_points})


def bones_of(armatures, gltf):
    """Each armature object as a root and its pose bones under it, as (name, parent, world matrix of now)."""
    # The glTF importer turns an object's axes from Y up to Z up as it turns the scene (its bones keep the node's, as
    # FBX's objects and bones do): the node's own axes are the object's turned back.
    node_axes = Matrix.Rotation(math.pi / 2, 4, "X") if gltf else Matrix.Identity(4)
    bones = []
    for ob in armatures:
        names = {bone.name for bone in ob.pose.bones}
        # The armature object is the file's node above the bones (glTF's skeleton node, FBX's null) unless a bone
        # has its name: then it is left out, names being unique in a dump.
        root = None if ob.name in names else ob.name
        if root is not None:
            bones.append((root, None, lambda ob=ob: ob.matrix_world @ node_axes))
        for bone in ob.pose.bones:
            parent = bone.parent.name if bone.parent else root
            bones.append((bone.name, parent, lambda ob=ob, bone=bone: ob.matrix_world @ bone.matrix))
    return bones


def column_major(matrix):
    """The 16 numbers of a mathutils matrix, column after column."""
    return [matrix[row][column] for column in range(4) for row in range(4)]


def main():
    argv = sys.argv[sys.argv.index("--") + 1 :] if "--" in sys.argv else sys.argv[1:]
    if len(argv) < 2:
        sys.exit("usage: python dump_blender.py FILE.glb|FILE.fbx OUT.dump.json [CLIP]")
    path, out, clip = argv[0], argv[1], argv[2] if len(argv) > 2 else None
    gltf = import_file(path)
    armatures, action = armatures_playing(clip)
    scene = bpy.context.scene
    fps = scene.render.fps / scene.render.fps_base
    bones = bones_of(armatures, gltf)
    frames = []
    for frame in key_frames(action):
        whole = int(frame // 1)
        scene.frame_set(whole, subframe=frame - whole)
        frames.append({"time": frame / fps, "matrices": [column_major(world()) for _, _, world in bones]})
    dump = {
        "format": "bonescope-pose-dump",
        "version": 1,
        "space": "world",
        "order": "column-major",
        "unit": "m",
        "up": "z",
        "clip": action.name,
        "source": f"Blender {bpy.app.version_string} {'glTF' if gltf else 'FBX'} importer",
        "bones": [{"name": name, "parent": parent} for name, parent, _ in bones],
        "frames": frames,
    }
    with open(out, "w") as f:
        json.dump(dump, f)


main()
