"""Every mesh's points in the world, at every time code of the stage, as Pixar's USD places them: for Pixar's baked
baselines (`UsdSkel.BakeSkinning`'s output), the skinned points bonescope must reproduce. Printed as one JSON
document: {"time_codes": [...], "meshes": [{"path": "/A/Mesh", "frames": [[[x, y, z], ...] per time code]}, ...]},
the meshes in the stage's traversal order.

Usage: python world_points.py FILE [EVERY]
EVERY: only every EVERY-th time code from the start, and the last (default 1: all of them).
"""
import json
import sys

from pxr import Usd, UsdGeom

from joint_transforms import every_nth


def main(path, every):
    stage = Usd.Stage.Open(path)
    start, end = stage.GetStartTimeCode(), stage.GetEndTimeCode()
    codes = every_nth([start + i for i in range(int(round(end - start)) + 1)], every)
    meshes = []
    for prim in stage.Traverse():
        if not prim.IsA(UsdGeom.Mesh):
            continue
        points = UsdGeom.Mesh(prim).GetPointsAttr()
        frames = []
        for code in codes:
            world = UsdGeom.Xformable(prim).ComputeLocalToWorldTransform(code)
            frames.append([list(world.Transform(p)) for p in points.Get(code)])
        meshes.append({"path": str(prim.GetPath()), "frames": frames})
    print(json.dumps({"time_codes": codes, "meshes": meshes}))


if __name__ == "__main__":
    main(sys.argv[1], int(sys.argv[2]) if len(sys.argv) > 2 else 1)
