"""The Python module against the command line and independent references, on the shared assets.

Run by `tests/python.rs` in a fresh environment with the wheel installed; `BONESCOPE_BIN` names the command line
built from the same sources, `BONESCOPE_ASSETS` the shared assets.
"""

import json
import os
import subprocess
import threading
import time
import _thread
from pathlib import Path

import numpy as np
import pytest
import scipy.linalg

import bonescope

BIN = os.environ["BONESCOPE_BIN"]
ASSETS = Path(os.environ["BONESCOPE_ASSETS"])
STRETCHY = ASSETS / "blender" / "stretchy_full.glb"
MAYA = ASSETS / "fbx-ufbx-data" / "maya_mixed_inherit_mode_7700_ascii.fbx"
NOINHERIT_FBX = ASSETS / "blender" / "stretchy_noinherit.fbx"
NOINHERIT_USD = ASSETS / "blender" / "stretchy_noinherit.usdc"


def cli(*args, expect=0):
    """The command line's JSON for `args`."""
    run = subprocess.run([BIN, *map(str, args), "--format", "json"], capture_output=True, text=True)
    assert run.returncode == expect, run.stderr
    return json.loads(run.stdout)


def cli_error(*args):
    """The command line's one-line error for `args` (exit 2)."""
    run = subprocess.run([BIN, *map(str, args)], capture_output=True, text=True)
    assert run.returncode == 2, run.stdout
    return run.stderr.strip().removeprefix("error: ")


@pytest.mark.parametrize(
    "path, options, cli_options",
    [
        (STRETCHY, {}, []),
        (STRETCHY, {"explain": True}, ["--explain"]),
        (STRETCHY, {"clip": "squash_stretch", "modes": "segment-compensate"}, ["--anim", "squash_stretch", "--inherit", "segment-compensate"]),
        (MAYA, {"explain": True, "rate": 120.0}, ["--explain", "--rate", "120"]),
        (NOINHERIT_USD, {"modes": {"forearm": "blender-none"}}, ["--inherit-bone", "forearm=blender-none"]),
        (STRETCHY, {"layers": {"uniform_scale": [4]}}, ["--uniform-scale", "chest"]),
    ],
)
def test_scan_is_the_command_lines(path, options, cli_options):
    assert bonescope.load(path).scan(**options) == cli("scan", path, *cli_options)[0]


@pytest.mark.parametrize(
    "path, bone, options, cli_options",
    [
        (STRETCHY, None, {}, []),
        (STRETCHY, "neck", {"time": 0.5}, ["--bone", "neck", "--time", "0.5"]),
        (MAYA, None, {}, []),
    ],
)
def test_explain_is_the_command_lines(path, bone, options, cli_options):
    assert bonescope.load(path).explain(bone, **options) == cli("explain", path, *cli_options)


def test_diff_is_the_command_lines():
    mine = bonescope.diff(NOINHERIT_FBX, NOINHERIT_USD, interp="nlerp")
    theirs = cli("diff", NOINHERIT_FBX, NOINHERIT_USD, "--interp", "nlerp")
    assert mine == theirs
    bvh = ASSETS / "blender" / "stretchy_full.bvh"
    options = {"anim_a": "squash_stretch", "anim_b": 0, "unit_b": "m", "up_b": "z"}
    mine = bonescope.diff(STRETCHY, bvh, **options)
    theirs = cli("diff", STRETCHY, bvh, "--anim-a", "squash_stretch", "--anim-b", "0", "--unit-b", "m", "--up-b", "z")
    assert mine == theirs


def test_bake_is_the_command_lines_and_writes_the_same_file(tmp_path):
    mine = bonescope.bake(MAYA, tmp_path / "mine.glb", "unity", tolerance=2e-4)
    theirs = cli("bake", MAYA, "--out", tmp_path / "theirs.glb", "--for", "unity", "--tolerance", "2e-4")
    assert mine == theirs
    assert (tmp_path / "mine.glb").read_bytes() == (tmp_path / "theirs.glb").read_bytes()


def test_a_bake_without_a_unit_is_the_command_lines_in_metres_and_what_it_refuses_it_refuses(tmp_path):
    walk = ASSETS / "bvh" / "cmu_12_01_walk.bvh"
    mine = bonescope.bake(walk, tmp_path / "mine.glb")
    theirs = cli("bake", walk, "--out", tmp_path / "theirs.glb")
    assert (tmp_path / "mine.glb").read_bytes() == (tmp_path / "theirs.glb").read_bytes()
    # The unit guessed, said the same way but for how each face chooses another.
    assert [n.replace("(unit= to choose)", "(--unit to choose)") for n in mine["notes"]] == theirs["notes"]
    assert any("the file states no unit: read in" in n for n in mine["notes"])
    assert {k: v for k, v in mine.items() if k != "notes"} == {k: v for k, v in theirs.items() if k != "notes"}
    with pytest.raises(bonescope.Error) as refused:
        bonescope.bake(STRETCHY, tmp_path / "x.fbx")
    assert str(refused.value) == cli_error("bake", STRETCHY, "--out", tmp_path / "x.fbx")
    assert not (tmp_path / "x.fbx").exists()


def test_a_bake_to_usd_is_the_command_lines(tmp_path):
    mine = bonescope.bake(STRETCHY, tmp_path / "mine.usdc")
    theirs = cli("bake", STRETCHY, "--out", tmp_path / "theirs.usdc")
    assert mine == theirs
    assert (tmp_path / "mine.usdc").read_bytes() == (tmp_path / "theirs.usdc").read_bytes()
    assert any("a USD stage plays one animation" in n for n in mine["notes"])


def test_evaluate_is_inspect_at_each_time():
    rig = bonescope.load(STRETCHY)
    times = [0.0, 0.25, 0.55, 1.9]
    evaluation = rig.evaluate("squash_stretch", times)
    inspected = cli("inspect", STRETCHY, "--anim", "squash_stretch", *[a for t in times for a in ("--time", t)])
    assert evaluation.bones == [b["name"] for b in inspected["samples"][0]["bones"]]
    for t, sample in enumerate(inspected["samples"]):
        assert evaluation.times[t] == sample["time"]
        for b, bone in enumerate(sample["bones"]):
            # inspect's matrices are column-major; the arrays are m[row, column]. The command line under test may
            # be built at another optimisation level than the wheel: the last bits may differ (1e-12).
            close = lambda mine, theirs: np.allclose(mine, theirs, rtol=0, atol=1e-12)
            assert close(evaluation.model[t, b], np.array(bone["model"]["matrix"]).reshape(4, 4).T)
            assert close(evaluation.local[t, b], np.array(bone["local"]["matrix"]).reshape(4, 4).T)
            for part in ("translation", "rotation", "stretch", "scale"):
                assert close(getattr(evaluation, part)[t, b], bone["model"][part]), part
            assert evaluation.sign[t, b] == bone["model"]["sign"]
            assert close(evaluation.shear_deg[t, b], bone["shear_deg"])
            assert evaluation.stretched[t, b] == bone["stretched"]


def test_the_decomposition_is_scipys_polar_decomposition():
    # M₃ = R·S (scipy.linalg.polar, side="right") with R = F·R_bonescope and S = U·K·Uᵀ, on every model matrix of
    # Blender's stretchy rig at every sampled time; the file is in metres, so the scale factors are the matrix's.
    evaluation = bonescope.load(STRETCHY).evaluate("squash_stretch")
    assert evaluation.model.shape == (121, 10, 4, 4) and evaluation.stretched.any()
    for m, q, u, k, f in zip(
        evaluation.model.reshape(-1, 4, 4),
        evaluation.rotation.reshape(-1, 4),
        evaluation.stretch.reshape(-1, 4),
        evaluation.scale.reshape(-1, 3),
        evaluation.sign.reshape(-1),
    ):
        rotation, stretch = scipy.linalg.polar(m[:3, :3], side="right")
        assert np.allclose(rotation, f * matrix_of(q), rtol=0, atol=1e-9)
        frame = matrix_of(u)
        assert np.allclose(stretch, frame @ np.diag(k) @ frame.T, rtol=0, atol=1e-9)
    assert np.array_equal(evaluation.translation, evaluation.model[:, :, :3, 3])


def matrix_of(q):
    """The rotation matrix of the unit quaternion [x, y, z, w]."""
    x, y, z, w = q
    return np.array(
        [
            [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
            [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
            [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
        ]
    )


def test_the_arrays_are_handed_over_without_copies():
    evaluation = bonescope.load(STRETCHY).evaluate()
    for name in ("local", "model", "translation", "rotation", "stretch", "scale", "sign", "shear_deg", "stretched"):
        array = getattr(evaluation, name)
        assert array.base is not None and not array.flags["OWNDATA"], name
        assert array.flags["C_CONTIGUOUS"], name


def test_what_the_rig_holds():
    rig = bonescope.load(STRETCHY)
    assert [c.name for c in rig.clips] == ["squash_stretch", "wave"] and rig.clips[0].frame_rate == 30.0
    assert rig.clips[0].key_times[0] == pytest.approx(1 / 30, abs=1e-7)
    forearm = next(b for b in rig.bones if b.name == "forearm")
    assert (forearm.mode, forearm.role, rig.bones[forearm.parent].name) == ("full", "joint", "upper_arm")
    assert [(m.skinned, m.vertices > 0) for m in rig.meshes] == [(True, True)]
    # What each one says when printed: what it is, not where it lies in memory.
    assert repr(forearm) == f'<bonescope.Bone {forearm.index} "forearm": joint, parent {forearm.parent}, mode full>'
    assert repr(rig.bones[0]).endswith(", parent None, mode full>")
    clip = rig.clips[0]
    keys = len(clip.key_times)
    assert repr(clip) == f'<bonescope.Clip 0 "squash_stretch": 2.000 s from 0.0333 s, 30 fps, {keys} key times>'
    mesh = rig.meshes[0]
    assert repr(mesh) == f'<bonescope.Mesh "{mesh.name}": {mesh.vertices} vertices on bone {mesh.bone}, skinned, 0 morph targets>'
    maya = bonescope.load(MAYA)
    assert "segment-compensate" in {b.mode for b in maya.bones} and maya.unit == "metres" and maya.notes


@pytest.mark.parametrize(
    "call, cli_args",
    [
        (lambda: bonescope.load(ASSETS / "missing.glb"), ["inspect", ASSETS / "missing.glb"]),
        (lambda: bonescope.load(STRETCHY).evaluate("nope"), ["inspect", STRETCHY, "--anim", "nope"]),
        (lambda: bonescope.load(STRETCHY).explain("nope"), None),
        (lambda: bonescope.load(STRETCHY).evaluate(modes="bogus"), None),
        (lambda: bonescope.load(STRETCHY, max_memory="1KiB"), ["inspect", "--max-memory", "1KiB", STRETCHY]),
        (lambda: bonescope.diff(STRETCHY, STRETCHY, anim_a="nope"), None),
        (lambda: bonescope.load(STRETCHY).scan(min_shear_deg=-1.0), None),
        (lambda: bonescope.load(STRETCHY).scan(min_non_uniform=-1.0), None),
        (lambda: bonescope.load(STRETCHY).evaluate(rate=0.0), None),
    ],
)
def test_bad_input_raises_bonescope_error_with_the_command_lines_message(call, cli_args):
    with pytest.raises(bonescope.Error) as raised:
        call()
    message = str(raised.value)
    assert "\n" not in message and message
    if cli_args is not None:
        assert message in cli_error(*cli_args)


def test_a_broken_file_raises_and_never_crashes(tmp_path):
    for name, content in [("a.glb", b"glTF\x02\x00\x00\x00\xff\xff\xff\xff"), ("b.fbx", b"Kaydara FBX Binary  \x00"), ("c.bvh", b"HIERARCHY\nROOT")]:
        broken = tmp_path / name
        broken.write_bytes(content)
        with pytest.raises(bonescope.Error, match=name):
            bonescope.load(broken)


def test_ctrl_c_stops_a_long_scan():
    rig = bonescope.load(ASSETS / "fbx-proanimationbank" / "locomotions.fbx")
    timer = threading.Timer(0.3, _thread.interrupt_main)
    started = time.monotonic()
    timer.start()
    with pytest.raises(KeyboardInterrupt):
        rig.scan(explain=True, rate=200000.0)
    assert time.monotonic() - started < 5.0


def test_blender_reads_the_shear_bonescope_reads(tmp_path):
    python = os.environ.get("BONESCOPE_BLENDER_PYTHON")
    if not python:
        pytest.skip("BONESCOPE_BLENDER_PYTHON names no Python with bpy")
    wheel = os.environ["BONESCOPE_WHEEL"]
    install = subprocess.run([python, "-m", "pip", "install", "-q", "--force-reinstall", "--no-deps", wheel], capture_output=True, text=True)
    assert install.returncode == 0, install.stderr
    script = Path(__file__).with_name("blender_shear.py")
    run = subprocess.run([python, str(script), str(tmp_path / "rig.glb")], capture_output=True, text=True)
    assert run.returncode == 0, run.stdout + run.stderr
    assert "sheared bones agree" in run.stdout, run.stdout


def test_the_version_is_the_wheels_and_the_command_lines():
    from importlib.metadata import version

    command_line = subprocess.run([BIN, "--version"], capture_output=True, text=True, check=True).stdout
    assert bonescope.__version__ == version("bonescope")
    assert command_line == f"bonescope {bonescope.__version__}\n"


@pytest.mark.parametrize(
    "readme, expected",
    [
        ("README.md", ["{'forearm': 18.66, 'hand': 18.66, 'neck': 13.7, 'head': 12.73}", "neck → componentwise", "exact"]),
        (
            "python/README.md",
            ["forearm: 18.66°", "hand: 18.66°", "neck: 13.70°", "head: 12.73°"]
            + ["forearm: 18.666° at 0.5539 s", "hand: 18.666° at 0.5539 s", "neck: 13.712° at 0.5720 s", "head: 12.734° at 0.5668 s"]
            + ["forearm → blender-aligned"],
        ),
    ],
)
def test_the_readme_examples_print_what_they_say(readme, expected, capsys, monkeypatch):
    root = Path(os.environ["BONESCOPE_README"]).parent
    page = root / readme
    block = page.read_text().split("```python\n", 1)[1].split("```", 1)[0]  # the first: the Blender one needs bpy
    monkeypatch.chdir(root)
    exec(compile(block, str(page), "exec"), {})
    assert capsys.readouterr().out.splitlines() == expected
