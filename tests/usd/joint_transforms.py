"""Pixar's own evaluation of a USD file's skeletons, for bonescope's tests: for every Skeleton prim, its joints and,
at every time code of the stage (or the rest pose's time where none is authored), each joint's world transform as
UsdSkel computes it (`SkeletonQuery.ComputeJointWorldTransforms`), printed as one JSON document.

Usage: python joint_transforms.py FILE [EVERY]
EVERY: only every EVERY-th time code from the start, and the last (default 1: all of them).
Matrices are row-vector (translation in the last row), flattened row by row, as USD writes them.
"""
import json
import sys

from pxr import Usd, UsdGeom, UsdSkel


def flat(matrix):
    return [matrix[r][c] for r in range(4) for c in range(4)]


def main(path, every):
    stage = Usd.Stage.Open(path)
    cache = UsdSkel.Cache()
    skeletons = []
    if stage.HasAuthoredTimeCodeRange():
        start, end = stage.GetStartTimeCode(), stage.GetEndTimeCode()
        times = every_nth([start + i for i in range(int(round(end - start)) + 1)], every)
    else:
        times = [Usd.TimeCode.Default()]
    for prim in stage.Traverse():
        if not prim.IsA(UsdSkel.Skeleton):
            continue
        query = cache.GetSkelQuery(UsdSkel.Skeleton(prim))
        samples = []
        for time in times:
            xforms = UsdGeom.XformCache(time)
            world = query.ComputeJointWorldTransforms(xforms)
            code = None if time == Usd.TimeCode.Default() else time
            samples.append({"time_code": code, "world": [flat(m) for m in world]})
        skeletons.append({
            "path": str(prim.GetPath()),
            "joints": [str(j) for j in query.GetJointOrder()],
            "samples": samples,
        })
    print(json.dumps({
        "meters_per_unit": UsdGeom.GetStageMetersPerUnit(stage),
        "up_axis": str(UsdGeom.GetStageUpAxis(stage)),
        "time_codes_per_second": stage.GetTimeCodesPerSecond(),
        "start_time_code": stage.GetStartTimeCode() if stage.HasAuthoredTimeCodeRange() else None,
        "skeletons": skeletons,
    }))


def every_nth(codes, every):
    """Every `every`-th of `codes` from the first, and the last."""
    return codes[::every] + ([codes[-1]] if (len(codes) - 1) % every else [])


if __name__ == "__main__":
    main(sys.argv[1], int(sys.argv[2]) if len(sys.argv) > 2 else 1)
