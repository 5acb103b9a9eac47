"""A pose dump (docs/pose-dump.md) of what Unreal plays: an animation sequence evaluated by Unreal's own AnimPose
API at every frame, each bone's component-space ("world" of the pose) transform written. UNTESTED: no Unreal runs
in bonescope's CI; it is kept short so that it can be checked by eye.

Unreal Editor 5.1 or later, with the Python Editor Script Plugin enabled; in the Output Log (Python):

    py examples/dump_unreal.py /Game/Path/To/AnimSequence C:/out/NAME.dump.json
    bonescope fit FILE NAME.dump.json

Unreal composes each bone's component-space transform from its parent's as `FTransform` does (scale along the
child's axes: bonescope's `componentwise`), which is what the fit is asked to confirm. Unreal is left-handed, Z up,
in centimetres; its FBX importer negates Y on import, and this script negates it again on both sides of every matrix
(M' = S·M·S, S = diag(1, -1, 1)), so that the dump is in the file's right-handed axes, Z up (as the header says).
"""

import json
import sys

import unreal


def column_major_mirrored(transform):
    """The 16 numbers of S·M·S (S negates Y), M the column-vector matrix of `transform`, column after column.

    Unreal's matrices act on row vectors: the planes of `to_matrix()` are the column-vector matrix's columns."""
    planes = transform.to_matrix()
    columns = [planes.x_plane, planes.y_plane, planes.z_plane, planes.w_plane]
    sign = [1.0, -1.0, 1.0, 1.0]
    return [sign[c] * sign[r] * v for c, p in enumerate(columns) for r, v in enumerate([p.x, p.y, p.z, p.w])]


def main():
    sequence_path, out = sys.argv[1], sys.argv[2]
    sequence = unreal.load_asset(sequence_path)
    options = unreal.AnimPoseEvaluationOptions()
    keys = unreal.AnimationLibrary.get_num_keys(sequence)  # sampled frames, the last one's included
    poses = unreal.AnimPoseExtensions
    first = poses.get_anim_pose_at_frame(sequence, 0, options)
    names = poses.get_bone_names(first)
    bones = []
    for name in names:
        parent = poses.get_parent_bone_name(first, name)
        bones.append({"name": str(name), "parent": str(parent) if parent != "None" else None})
    dumped = []
    for frame in range(keys):
        pose = poses.get_anim_pose_at_frame(sequence, frame, options)
        # WORLD is the pose's component space, composed by Unreal from the bone-space transforms.
        matrices = [column_major_mirrored(poses.get_bone_pose(pose, n, unreal.AnimPoseSpaces.WORLD)) for n in names]
        time = unreal.AnimationLibrary.get_time_at_frame(sequence, frame)
        dumped.append({"time": time, "matrices": matrices})
    header = {"format": "bonescope-pose-dump", "version": 1, "space": "world", "order": "column-major",
              "unit": "cm", "up": "z", "clip": sequence.get_name(),
              "source": f"Unreal {unreal.SystemLibrary.get_engine_version()} AnimPose"}
    with open(out, "w") as f:
        json.dump({**header, "bones": bones, "frames": dumped}, f)  # `format` first: dicts keep their order
    unreal.log(f"pose dump of {len(bones)} bones, {len(dumped)} frames: {out}")


main()
