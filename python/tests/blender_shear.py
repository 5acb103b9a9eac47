"""Run by Blender's Python (`bpy`) with the bonescope wheel installed: builds an armature whose parent bone scales
non-uniformly under a turned child, exports it with Blender's own glTF exporter to the path given, and checks that
bonescope's shear of each bone, read back from that file, equals the shear of Blender's evaluated pose matrices
(`pose.bones[...].matrix`) at every frame. Prints "sheared bones agree" and exits 0, else raises."""

import contextlib
import io
import math
import sys
from pathlib import Path

import bpy
import numpy as np

import bonescope


def shear_deg(matrix):
    """The largest deviation from 90° between two columns of a 3×3 matrix, in degrees (as bonescope measures it)."""
    columns = [np.array(matrix)[:, i] for i in range(3)]
    worst = 0.0
    for i, j in ((0, 1), (0, 2), (1, 2)):
        cosine = abs(columns[i] @ columns[j]) / (np.linalg.norm(columns[i]) * np.linalg.norm(columns[j]))
        worst = max(worst, math.degrees(math.asin(min(1.0, cosine))))
    return worst


bpy.ops.wm.read_factory_settings(use_empty=True)
scene = bpy.context.scene
scene.render.fps, scene.frame_start, scene.frame_end = 24, 1, 12
armature = bpy.data.armatures.new("Rig")
rig = bpy.data.objects.new("Rig", armature)
scene.collection.objects.link(rig)
bpy.context.view_layer.objects.active = rig
bpy.ops.object.mode_set(mode="EDIT")
for name, head, tail, parent in [("root", (0, 0, 0), (0, 0, 1), None), ("arm", (0, 0, 1), (0, 0, 2), "root"),
                                 ("hand", (0, 0, 2), (0, 0, 2.5), "arm")]:
    bone = armature.edit_bones.new(name)
    bone.head, bone.tail = head, tail
    if parent:
        bone.parent = armature.edit_bones[parent]
        bone.use_connect = True
bpy.ops.object.mode_set(mode="POSE")
arm, root = rig.pose.bones["arm"], rig.pose.bones["root"]
arm.rotation_mode = "XYZ"
for frame, scale, turn in [(1, (1, 1, 1), 0.0), (12, (1.8, 1.0, 0.7), 50.0)]:
    root.scale = scale
    arm.rotation_euler = (0.0, 0.0, math.radians(turn))
    root.keyframe_insert("scale", frame=frame)
    arm.keyframe_insert("rotation_euler", frame=frame)
bpy.ops.object.mode_set(mode="OBJECT")
out = sys.argv[-1]
bpy.ops.export_scene.gltf(filepath=out, export_format="GLB", export_animations=True, export_force_sampling=True)

evaluation = bonescope.load(out).evaluate(0, [frame / scene.render.fps for frame in range(1, 13)])
sheared = 0
for row, frame in enumerate(range(1, 13)):
    scene.frame_set(frame)
    for name in ("root", "arm", "hand"):
        blender = shear_deg(rig.pose.bones[name].matrix.to_3x3())
        ours = evaluation.shear_deg[row, evaluation.bones.index(name)]
        assert abs(blender - ours) < 1e-3, f"{name} at frame {frame}: Blender {blender:.5f}°, bonescope {ours:.5f}°"
        sheared += blender > 1.0
assert sheared >= 10, f"only {sheared} sheared samples: the rig does not shear as built"
print(f"sheared bones agree: {sheared} sheared samples of 36, within 1e-3°")

# The example add-on on the same armature: it reports the sheared bones and a fix for each.
sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "examples"))
import blender_check  # noqa: E402

said = []
explained = blender_check.check(rig, lambda level, text: said.append((level, text)))
assert {bone["name"] for bone in explained} >= {"arm"}, said
assert all(bone["best_fix"] for bone in explained), explained
assert any(level == "WARNING" and "arm shears" in text for level, text in said), said
print("the example add-on reports:", *[text for _, text in said], sep="\n  ")

# The README's Blender snippet, on the same armature selected.
readme = (Path(__file__).resolve().parents[2] / "README.md").read_text()
snippet = readme.split("```python\n")[2].split("```", 1)[0]
rig.select_set(True)
printed = io.StringIO()
with contextlib.redirect_stdout(printed):
    exec(compile(snippet, "README.md", "exec"), {})
lines = printed.getvalue().splitlines()
assert any(line.startswith("arm: root's scale (1.8, 1, 0.7) under a 40° turn; fix: arm → ") for line in lines), lines
print("the README's snippet prints:", *lines, sep="\n  ")
