"""Writes a USD file as Maya USD's `-unit m` export wrote it (maya-usd 0.36; Autodesk/maya-usd issues #4377 and #4652,
fixed by PR #4686): every Skeleton's `bindTransforms` and `restTransforms` multiplied entry by entry by the unit
factor, so that the rotation block is scaled and the homogeneous corner is the factor instead of 1. Every skinned
character it wrote was scrambled; bonescope's tests check the bind check names it.

Usage: python unit_bug.py SOURCE OUT [FACTOR]   (FACTOR 0.01 unless given)
"""
import sys

from pxr import Gf, Sdf, Usd, UsdSkel


def scaled(matrices, factor):
    return [Gf.Matrix4d(*[m[r][c] * factor for r in range(4) for c in range(4)]) for m in matrices]


def main(source, out, factor):
    stage = Usd.Stage.Open(source)
    for prim in stage.Traverse():
        if not prim.IsA(UsdSkel.Skeleton):
            continue
        skeleton = UsdSkel.Skeleton(prim)
        for attribute in (skeleton.GetBindTransformsAttr(), skeleton.GetRestTransformsAttr()):
            matrices = attribute.Get()
            if matrices:
                attribute.Set(scaled(matrices, factor))
    stage.GetRootLayer().Export(out)


if __name__ == "__main__":
    main(sys.argv[1], sys.argv[2], float(sys.argv[3]) if len(sys.argv) > 3 else 0.01)
