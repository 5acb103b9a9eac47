"""Writes the generated rig of `generated_gltf.rs` as a binary USD layer with Pixar's usd-core, for the loading
benchmark: the same skeleton (joints named by their paths) and the same local transform of every joint at every
frame, one time code per frame. The plates mesh is left out: the measure is the skeleton and its animation.

Usage: python generated_usd.py OUT.usdc DATA
DATA: a line of JSON {"joints": [paths], "frames": F, "rate": R}, then little-endian float32 values, ten per joint
(translation xyz, rotation xyzw, scale xyz): the rest pose, then each frame.

Usage: python generated_usd.py --time FILE
prints the seconds usd-core takes (the fastest of three) to open FILE and compute every joint's world transform at
every time code of its stage, the work bonescope's load does.
"""
import array
import json
import sys
import time

from pxr import Gf, Usd, UsdGeom, UsdSkel, Vt


def write(out, data):
    with open(data, "rb") as f:
        header = json.loads(f.readline())
        values = array.array("f")
        values.frombytes(f.read())
    joints, frames = header["joints"], header["frames"]
    count = len(joints)

    def pose(k):
        at = values[10 * count * k: 10 * count * (k + 1)]
        t = [Gf.Vec3f(*at[10 * j: 10 * j + 3]) for j in range(count)]
        r = [Gf.Quatf(at[10 * j + 6], *at[10 * j + 3: 10 * j + 6]) for j in range(count)]
        s = [Gf.Vec3h(*at[10 * j + 7: 10 * j + 10]) for j in range(count)]
        return t, r, s

    stage = Usd.Stage.CreateNew(out)
    stage.SetTimeCodesPerSecond(header["rate"])
    stage.SetStartTimeCode(0)
    stage.SetEndTimeCode(frames - 1)
    UsdGeom.SetStageMetersPerUnit(stage, 1.0)
    UsdGeom.SetStageUpAxis(stage, UsdGeom.Tokens.y)
    UsdSkel.Root.Define(stage, "/Rig")
    skeleton = UsdSkel.Skeleton.Define(stage, "/Rig/Skel")
    skeleton.CreateJointsAttr(joints)
    t, r, s = pose(0)
    rest = [UsdSkel.MakeTransform(Gf.Vec3f(t[j]), r[j], s[j]) for j in range(count)]
    skeleton.CreateRestTransformsAttr(Vt.Matrix4dArray(rest))
    skeleton.CreateBindTransformsAttr(Vt.Matrix4dArray(rest))
    animation = UsdSkel.Animation.Define(stage, "/Rig/Skel/Anim")
    animation.CreateJointsAttr(joints)
    UsdSkel.BindingAPI.Apply(skeleton.GetPrim()).CreateAnimationSourceRel().SetTargets([animation.GetPath()])
    translations = animation.CreateTranslationsAttr()
    rotations = animation.CreateRotationsAttr()
    scales = animation.CreateScalesAttr()
    for k in range(frames):
        t, r, s = pose(k + 1)
        translations.Set(Vt.Vec3fArray(t), k)
        rotations.Set(Vt.QuatfArray(r), k)
        scales.Set(Vt.Vec3hArray(s), k)
    stage.GetRootLayer().Save()


def timed(file):
    best = float("inf")
    for _ in range(3):
        start = time.perf_counter()
        stage = Usd.Stage.Open(file)
        cache = UsdSkel.Cache()
        for prim in stage.Traverse():
            if prim.IsA(UsdSkel.Skeleton):
                query = cache.GetSkelQuery(UsdSkel.Skeleton(prim))
                code = stage.GetStartTimeCode()
                while code <= stage.GetEndTimeCode():
                    query.ComputeJointWorldTransforms(UsdGeom.XformCache(code))
                    code += 1
        best = min(best, time.perf_counter() - start)
    print(f"{best:.4f}")


if __name__ == "__main__":
    if sys.argv[1] == "--time":
        timed(sys.argv[2])
    else:
        write(sys.argv[1], sys.argv[2])
