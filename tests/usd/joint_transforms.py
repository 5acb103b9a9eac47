"""Pixar's own evaluation of a USD file's skeletons, for bonescope's tests: for every Skeleton prim, its joints and,
at every time code of the stage (or the rest pose's time where none is authored), each joint's world transform as
UsdSkel computes it (`SkeletonQuery.ComputeJointWorldTransforms`).

Usage: python joint_transforms.py FILE MATRICES
Prints one JSON document (the stage's clock, and per skeleton its path, joints and time codes); the matrices go to
MATRICES as 64-bit little-endian floats, skeleton after skeleton, time code after time code, joint after joint, each
row-vector (translation in the last row) and row by row, as USD writes them: a long clip's every pose, which as JSON
would be hundreds of megabytes.
"""
import json
import sys
from array import array

from pxr import Usd, UsdGeom, UsdSkel


def main(path, matrices):
    stage = Usd.Stage.Open(path)
    cache = UsdSkel.Cache()
    skeletons = []
    if stage.HasAuthoredTimeCodeRange():
        start, end = stage.GetStartTimeCode(), stage.GetEndTimeCode()
        times = [start + i for i in range(int(round(end - start)) + 1)]
    else:
        times = [Usd.TimeCode.Default()]
    with open(matrices, "wb") as out:
        for prim in stage.Traverse():
            if not prim.IsA(UsdSkel.Skeleton):
                continue
            query = cache.GetSkelQuery(UsdSkel.Skeleton(prim))
            for time in times:
                world = query.ComputeJointWorldTransforms(UsdGeom.XformCache(time))
                numbers = array("d", (m[r][c] for m in world for r in range(4) for c in range(4)))
                if sys.byteorder != "little":
                    numbers.byteswap()
                numbers.tofile(out)
            skeletons.append({
                "path": str(prim.GetPath()),
                "joints": [str(j) for j in query.GetJointOrder()],
                "time_codes": [None if t == Usd.TimeCode.Default() else t for t in times],
            })
    print(json.dumps({
        "meters_per_unit": UsdGeom.GetStageMetersPerUnit(stage),
        "up_axis": str(UsdGeom.GetStageUpAxis(stage)),
        "time_codes_per_second": stage.GetTimeCodesPerSecond(),
        "start_time_code": stage.GetStartTimeCode() if stage.HasAuthoredTimeCodeRange() else None,
        "skeletons": skeletons,
    }))


if __name__ == "__main__":
    main(sys.argv[1], sys.argv[2])
