"""Bakes a stage's skinning with Pixar's own `UsdSkel.BakeSkinning`, as Pixar's tests bake their baselines: every
skinned mesh's points (and blend shapes) written per time code, for bonescope's tests to compare with.

Usage: python bake_skinning.py IN OUT
"""
import sys

from pxr import Usd, UsdSkel


def main(source, out):
    stage = Usd.Stage.Open(source)
    if not UsdSkel.BakeSkinning(stage.Traverse()):
        sys.exit(f"UsdSkel.BakeSkinning failed on {source}")
    stage.GetRootLayer().Export(out)


if __name__ == "__main__":
    main(sys.argv[1], sys.argv[2])
