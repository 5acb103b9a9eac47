"""Writes a binary USD layer of a 20-joint skeleton whose SkelAnimation moves its root along x over 2,000 time codes
(every other joint holds), for the test of what the memory budget counts: each time code's translations are an array
of their own (usd-core shares none), 480 kB in all, of which one joint's column, 24 kB, is kept.

Usage: python long_clip.py OUT.usdc
"""
import sys

from pxr import Gf, Usd, UsdSkel, Vt

JOINTS = ["root"] + ["root/j%d" % k for k in range(1, 20)]
FRAMES = 2000

stage = Usd.Stage.CreateNew(sys.argv[1])
UsdSkel.Root.Define(stage, "/Rig")
skeleton = UsdSkel.Skeleton.Define(stage, "/Rig/Skel")
skeleton.CreateJointsAttr(JOINTS)
rest = Vt.Matrix4dArray([Gf.Matrix4d(1)] * len(JOINTS))
skeleton.CreateRestTransformsAttr(rest)
skeleton.CreateBindTransformsAttr(rest)
animation = UsdSkel.Animation.Define(stage, "/Rig/Skel/Anim")
animation.CreateJointsAttr(JOINTS)
animation.CreateRotationsAttr(Vt.QuatfArray([Gf.Quatf(1)] * len(JOINTS)))
animation.CreateScalesAttr(Vt.Vec3hArray([Gf.Vec3h(1)] * len(JOINTS)))
translations = animation.CreateTranslationsAttr()
for frame in range(FRAMES):
    held = [Gf.Vec3f(0, 1, 0)] * (len(JOINTS) - 1)
    translations.Set(Vt.Vec3fArray([Gf.Vec3f(frame, 0, 0)] + held), frame)
UsdSkel.BindingAPI.Apply(skeleton.GetPrim()).CreateAnimationSourceRel().SetTargets([animation.GetPath()])
stage.SetStartTimeCode(0)
stage.SetEndTimeCode(FRAMES - 1)
stage.GetRootLayer().Save()
