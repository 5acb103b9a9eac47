"""Every mesh's points in the world, at every time code of the stage, as Pixar's USD places them: for Pixar's baked
baselines (`UsdSkel.BakeSkinning`'s output), the skinned points bonescope must reproduce.

Usage: python world_points.py FILE POINTS
Prints one JSON document: {"time_codes": [...], "meshes": [{"path": "/A/Mesh", "points": N}, ...]}, the meshes in
the stage's traversal order; the points go to POINTS as 64-bit little-endian floats x, y, z, mesh after mesh, time
code after time code, point after point.
"""
import json
import sys
from array import array

from pxr import Usd, UsdGeom


def main(path, points_file):
    stage = Usd.Stage.Open(path)
    start, end = stage.GetStartTimeCode(), stage.GetEndTimeCode()
    codes = [start + i for i in range(int(round(end - start)) + 1)]
    meshes = []
    with open(points_file, "wb") as out:
        for prim in stage.Traverse():
            if not prim.IsA(UsdGeom.Mesh):
                continue
            points = UsdGeom.Mesh(prim).GetPointsAttr()
            count = 0
            for code in codes:
                world = UsdGeom.Xformable(prim).ComputeLocalToWorldTransform(code)
                placed = [world.Transform(p) for p in points.Get(code)]
                count = len(placed)
                numbers = array("d", (c for p in placed for c in p))
                if sys.byteorder != "little":
                    numbers.byteswap()
                numbers.tofile(out)
            meshes.append({"path": str(prim.GetPath()), "points": count})
    print(json.dumps({"time_codes": codes, "meshes": meshes}))


if __name__ == "__main__":
    main(sys.argv[1], sys.argv[2])
