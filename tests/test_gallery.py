"""The example gallery (docs/gallery.md): design files, the scripts that build the same chains,
and the numbers the gallery states about them.

* every ``examples/designs/*.json`` loads without a PlacementWarning and gives a crease pattern
  n * b wide;
* every design equals the chain its script's ``build()`` returns (types, poses, parameters);
  Example 1's equals the paper's listing (tests/conftest.py builders);
* the geometric claims of the gallery (axes that meet, are parallel or coincide; reference
  numbers of spec chain.md 11.5 and 11.6 at r = 10 mm; the PUMA on its DH axes, shortened);
* every script runs as a subprocess into a temporary folder and writes its three files; the
  scripts run concurrently (one process each, started together) so the whole file stays fast.
"""

from __future__ import annotations

import importlib.util
import json
import math
import os
import subprocess
import sys
import warnings
from pathlib import Path

import ezdxf
import numpy as np
import pytest
from ezdxf import bbox

from kinegami import *
from kinegami.design import load_design, load_design_with_info
from kinegami.dh import dh_joint_frames, dh_tool_frame

ROOT = Path(__file__).resolve().parents[1]
EXAMPLES = ROOT / "examples"


def source_env(**changes) -> dict[str, str]:
    """A script's environment: kinegami imported from this checkout, the Agg backend."""
    env = dict(os.environ, MPLBACKEND="Agg", **changes)
    env["PYTHONPATH"] = os.pathsep.join([str(ROOT), *filter(None, [os.environ.get("PYTHONPATH")])])
    return env


DESIGNS = EXAMPLES / "designs"

#: gallery entry -> its script (None: Example 1, whose script is the paper's listing).
ENTRIES = {
    "example1": None,
    "cylindrical_joint": "cylindrical_joint.py",
    "planar_joint": "planar_joint.py",
    "spherical_joint": "spherical_joint.py",
    "puma": "puma.py",
    "revolute_spiral": "revolute_spiral.py",
    "prismatic_spiral": "prismatic_spiral.py",
    "spherical_limb": "spherical_limb.py",
    "spherical_series": "spherical_series.py",
    "doubling_back": "doubling_back.py",
}
SCRIPTS = sorted(name for name, script in ENTRIES.items() if script)
#: the gallery's trees (also tested in tests/tree, tests/design/test_trees.py and
#: tests/cli/test_gallery_trees.py): entry -> joints, leaves, total link length (design units).
#: Each has a script examples/<entry>.py.
TREE_ENTRIES = {
    "hand": (12, 3, 32.276748),
    "algorithmic_hand": (16, 3, 754.588015),
    "quadruped": (18, 4, 774.985756),
    "gripper": (10, 2, 285.281991),
}

#: spec chain.md 11.5 and 11.6 (r = 1), and the PUMA 560 table of examples/puma.py.
SCALE = 10.0  # the gallery's r (mm) for the chain.md examples
CYLINDRICAL_PRISMATIC_ORIGIN = (0.0, 0.0, 7.125651)
CYLINDRICAL_TOTAL_WITHOUT_TIP = 7.287597
PLANAR_TOTAL = 4.535898
PLANAR_STRAIGHT_LINK = 2.267949
SPIRAL_ORIGINS = [
    (0.0, 0.0, 0.0),
    (5.377937, 0.0, 5.377937),
    (13.775869, 0.0, 5.377937),
    (20.665221, 0.0, -1.511414),
    (20.665221, 0.0, -13.240251),
]
SPIRAL_Z = [(0, 0, 1), (0.707107, 0, 0.707107), (1, 0, 0), (0.707107, 0, -0.707107), (0, 0, -1)]
SPIRAL_TOTAL = 28.196046
PI = math.pi
PUMA_560 = [
    (PI / 2, -PI / 2, 0, 0),
    (0, 0, 431.8, 149.09),
    (PI / 2, PI / 2, -20.32, 0),
    (0, -PI / 2, 0, 433.07),
    (0, PI / 2, 0, 0),
    (0, 0, 0, 56.25),
]
PUMA_COMPACT_LENGTH = 1714.666427  # from_dh(PUMA_560, 6, 25) before the slides (mm)
PUMA_SHORTENED_LENGTH = 1367.768999  # clearance-aware shortening (was 1367.768238)
LIMB_LENGTH = 143.839746  # the straight tube of the spherical limb (mm)

#: The table of docs/gallery.md: joints, structural joints, total path length, sheet w x h
#: (pattern width plus one side for the glue tab, pattern height), rounded as printed there.
GALLERY_TABLE = {
    "example1": (7, 2, 22.20, 7.07, 52.77),
    "cylindrical_joint": (4, 2, 72.88, 70, 302),
    "planar_joint": (3, 3, 45.36, 70, 119),
    "spherical_joint": (3, 3, 108.33, 70, 236),
    "puma": (7, 6, 1367.77, 175, 2435),
    "revolute_spiral": (7, 7, 648.26, 70, 1057),
    "prismatic_spiral": (5, 5, 281.96, 70, 1182),
    "spherical_limb": (5, 3, 276.01, 70, 438),
    "doubling_back": (8, 6, 304.45, 70, 823),
    "spherical_series": (11, 9, 475.52, 70, 985),
}


def test_every_design_is_a_gallery_entry():
    assert sorted(p.stem for p in DESIGNS.glob("*.json")) == sorted([*ENTRIES, *TREE_ENTRIES])
    for script in SCRIPTS:
        assert (EXAMPLES / f"{script}.py").is_file()


@pytest.mark.parametrize("name", sorted(TREE_ENTRIES))
def test_tree_entries(name):
    from kinegami import ClearanceWarning, KinematicTree

    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ClearanceWarning)  # the paper's hand: one near contact
        tree = load_design(DESIGNS / f"{name}.json")
    joints, leaves, length = TREE_ENTRIES[name]
    assert isinstance(tree, KinematicTree)
    assert len(tree.Joints) == joints
    assert sum(1 for c in tree.Children if not c) == leaves
    assert tree.totalPathLength() == pytest.approx(length, abs=1e-6)


# --- loading ----------------------------------------------------------------------------------
def load_strict(name: str) -> KinematicChain:
    """The chain of examples/designs/<name>.json; any warning (PlacementWarning or other) fails."""
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        return load_design(DESIGNS / f"{name}.json")


@pytest.fixture(scope="module")
def designs() -> dict[str, KinematicChain]:
    return {name: load_strict(name) for name in ENTRIES}


@pytest.mark.parametrize("name", sorted(ENTRIES))
def test_design_builds_chain_and_pattern(name, designs):
    chain = designs[name]
    _, info = load_design_with_info(DESIGNS / f"{name}.json")
    assert info.name  # every entry has a display name
    pattern = chain.creasePattern()
    side = 2.0 * chain.r * math.sin(math.pi / chain.numSides)
    assert pattern.width == pytest.approx(chain.numSides * side, rel=1e-9)
    assert pattern.height > chain.totalPathLength() > 0.0
    for link in chain.Links[1:]:  # every link is a CSC path with turns below pi
        assert 0.0 <= link.path.theta1 < math.pi and 0.0 <= link.path.theta2 < math.pi


@pytest.mark.parametrize("name", sorted(ENTRIES))
def test_gallery_table(name, designs):
    joints, structural_joints, length, width, height = GALLERY_TABLE[name]
    chain = designs[name]
    pattern = chain.creasePattern()
    decimals = 2 if name == "example1" else 0
    assert len(chain.Joints) == joints
    assert len(structural(chain)) == structural_joints
    assert round(chain.totalPathLength(), 2) == length
    assert round(pattern.width * (1 + 1 / chain.numSides), decimals) == width
    assert round(pattern.height, decimals) == height


# --- each design is its script's chain ---------------------------------------------------------
@pytest.fixture(scope="module")
def scripts():
    """``scripts(name)``: the module examples/<name>.py, imported (its ``build`` not run)."""
    sys.path.insert(0, str(EXAMPLES))  # the scripts import examples/_common.py
    loaded = {}

    def load(name):
        if name not in loaded:
            spec = importlib.util.spec_from_file_location(
                f"gallery_{name}", EXAMPLES / f"{name}.py"
            )
            module = importlib.util.module_from_spec(spec)
            spec.loader.exec_module(module)
            loaded[name] = module
        return loaded[name]

    yield load
    sys.path.remove(str(EXAMPLES))


def assert_same_chain(actual: KinematicChain, expected: KinematicChain) -> None:
    assert (actual.numSides, actual.r) == (expected.numSides, expected.r)
    assert actual.maxAnglePerElbow == expected.maxAnglePerElbow
    assert [type(j).__name__ for j in actual.Joints] == [type(j).__name__ for j in expected.Joints]
    for k, (a, b) in enumerate(zip(actual.Joints, expected.Joints, strict=True)):
        np.testing.assert_allclose(
            a.pose_matrix, b.pose_matrix, rtol=0, atol=1e-9, err_msg=f"joint {k}"
        )
        assert a.state == b.state
        assert a.neutralLength == pytest.approx(b.neutralLength, rel=1e-12)
        assert a.stateRange() == pytest.approx(b.stateRange(), rel=1e-12)
    assert actual.totalPathLength() == pytest.approx(expected.totalPathLength(), rel=1e-12)


@pytest.mark.parametrize("name", SCRIPTS)
def test_design_equals_script(name, designs, scripts):
    with warnings.catch_warnings():
        warnings.simplefilter("error", PlacementWarning)
        built = scripts(name).build()
    assert_same_chain(designs[name], built)


def test_example1_design_is_the_papers_example_1b(designs, example_1b):
    assert_same_chain(designs["example1"], example_1b)
    _, info = load_design_with_info(DESIGNS / "example1.json")
    assert info.units == "cm"  # r = 1 as in the paper; 1 cm makes a sheet one can fold


# --- what the gallery says about each chain ----------------------------------------------------
def axis_line(joint) -> tuple[np.ndarray, np.ndarray]:
    T = joint.pose_matrix
    return T[:3, 3], T[:3, 2]


def distance_to_line(point, joint) -> float:
    p, z = axis_line(joint)
    return float(np.linalg.norm(np.cross(np.asarray(point, float) - p, z)))


def structural(chain) -> list:
    return [j for j in chain.Joints if isinstance(j, RevoluteJoint | PrismaticJoint)]


def test_cylindrical_joint_shares_one_axis(designs):
    chain = designs["cylindrical_joint"]
    revolute, prismatic = structural(chain)
    assert isinstance(revolute, RevoluteJoint) and isinstance(prismatic, PrismaticJoint)
    np.testing.assert_allclose(axis_line(prismatic)[1], axis_line(revolute)[1], atol=1e-12)
    assert distance_to_line(axis_line(prismatic)[0], revolute) < 1e-9
    np.testing.assert_allclose(
        prismatic.pose_matrix[:3, 3], np.multiply(CYLINDRICAL_PRISMATIC_ORIGIN, SCALE), atol=1e-5
    )
    assert chain.totalPathLength() == pytest.approx(CYLINDRICAL_TOTAL_WITHOUT_TIP * SCALE, abs=1e-5)


def test_planar_joint_axes_parallel_and_joints_in_one_plane(designs):
    chain = designs["planar_joint"]
    joints = chain.Joints
    assert len(joints) == 3 and all(isinstance(j, RevoluteJoint) for j in joints)
    for joint, x in zip(joints, (0, 40, 80), strict=True):
        np.testing.assert_allclose(axis_line(joint)[1], (0, 0, 1), atol=1e-12)
        np.testing.assert_allclose(axis_line(joint)[0], (x, 0, 0), atol=1e-9)
    for link in chain.Links[1:]:
        assert link.path.theta1 == pytest.approx(0, abs=1e-9)
        assert link.path.theta2 == pytest.approx(0, abs=1e-9)
        assert link.path.length == pytest.approx(PLANAR_STRAIGHT_LINK * SCALE, abs=1e-5)
    assert chain.totalPathLength() == pytest.approx(PLANAR_TOTAL * SCALE, abs=1e-5)


def test_planar_script_follows_chain_md_11_5(scripts, capsys):
    scripts("planar_joint").build(verbose=True)
    out = capsys.readouterr().out
    assert "safe placement 196.38888" in out  # chain.md 11.5: 19.638888, 16.189197, 4.535898
    assert "waypoints deleted 161.89197" in out
    assert "joints in one plane 45.35898" in out


def assert_spherical(joints, centre) -> None:
    """Three revolute joints whose axes are orthogonal and pass through ``centre``."""
    assert len(joints) == 3 and all(isinstance(j, RevoluteJoint) for j in joints)
    for joint in joints:
        assert distance_to_line(centre, joint) < 1e-9
    z = np.array([axis_line(j)[1] for j in joints])
    np.testing.assert_allclose(z @ z.T, np.eye(3), atol=1e-12)


def test_spherical_joint_axes_meet_at_the_origin(designs):
    assert_spherical(list(designs["spherical_joint"].Joints), (0, 0, 0))


def test_spherical_limb(designs):
    chain = designs["spherical_limb"]
    assert isinstance(chain.Joints[0], StartTip) and isinstance(chain.Joints[-1], EndTip)
    assert_spherical(list(chain.Joints[1:4]), (0, 0, 0))
    limb = chain.Links[-1].path  # a straight tube from the last joint to the end tip
    assert limb.theta1 == pytest.approx(0, abs=1e-9) and limb.theta2 == pytest.approx(0, abs=1e-9)
    assert limb.tMag == pytest.approx(LIMB_LENGTH, abs=1e-5)


def test_spherical_series(designs):
    chain = designs["spherical_series"]
    joints = structural(chain)
    assert len(joints) == 9
    for k in range(3):
        assert_spherical(joints[3 * k : 3 * k + 3], (0, 80 * k, 40 * k))


def test_doubling_back(designs):
    chain = designs["doubling_back"]
    heights = [j.pose_matrix[2, 3] for j in chain.Joints]
    assert heights == pytest.approx([0, 0, 0, 0, 60, 60, 60, 60], abs=1e-9)
    x = [j.pose_matrix[0, 3] for j in chain.Joints]
    assert x[:4] == sorted(x[:4]) and x[4:] == sorted(x[4:], reverse=True)  # out, then back
    uturn = chain.Links[4].path
    assert uturn.theta1 == pytest.approx(math.pi / 2) and uturn.theta2 == pytest.approx(math.pi / 2)
    # the end tip comes back above the start tip, pointing the other way
    np.testing.assert_allclose(chain.Joints[-1].pose_matrix[:3, 3], (0, 0, 60), atol=1e-9)
    assert chain.Joints[-1].pose_matrix[:3, 2] @ chain.Joints[0].pose_matrix[:3, 2] == -1


def test_prismatic_spiral_is_chain_md_11_6(designs):
    chain = designs["prismatic_spiral"]
    for joint, origin, z in zip(chain.Joints, SPIRAL_ORIGINS, SPIRAL_Z, strict=True):
        assert isinstance(joint, PrismaticJoint)
        np.testing.assert_allclose(joint.pose_matrix[:3, 3], np.multiply(origin, SCALE), atol=1e-5)
        np.testing.assert_allclose(joint.pose_matrix[:3, 2], z, atol=1e-6)
    assert chain.totalPathLength() == pytest.approx(SPIRAL_TOTAL * SCALE, abs=1e-5)


def test_revolute_spiral_axes_turn_45_degrees(designs):
    chain = designs["revolute_spiral"]
    joints = chain.Joints
    assert len(joints) == 7 and all(isinstance(j, RevoluteJoint) for j in joints)
    for k, joint in enumerate(joints):
        angle = k * math.pi / 4  # about y, from z
        np.testing.assert_allclose(
            joint.pose_matrix[:3, 2], (math.sin(angle), 0, math.cos(angle)), atol=1e-12
        )
    # compact placement: each joint at least 4r beyond the ball of the chain before it
    r = chain.r
    partial = KinematicChain(RevoluteJoint(6, r, math.pi, SE3()))
    for joint in joints[1:]:
        ball = partial.boundingBall
        gap = np.linalg.norm(joint.pose_matrix[:3, 3] - ball.c)
        assert gap >= ball.r + 4 * r + joint.boundingBall().r - 1e-9 * r
        partial.append(RevoluteJoint(6, r, math.pi, SE3.Ry(math.pi / 4)), safe=False)
    assert_same_chain(partial, chain)


def test_puma_joints_on_the_dh_axes_and_shorter(designs):
    chain = designs["puma"]
    joints = chain.Joints
    assert len(joints) == 7 and isinstance(joints[-1], EndTip)
    frames = [*dh_joint_frames(PUMA_560), dh_tool_frame(PUMA_560)]
    for joint, G in zip(joints, frames, strict=True):
        np.testing.assert_allclose(joint.pose_matrix[:3, :3], G[:3, :3], atol=1e-12)
        assert distance_to_line(G[:3, 3], joint) < 1e-9 * 1000
    compact = KinematicChain.from_dh(PUMA_560, 6, 25)
    assert compact.totalPathLength() == pytest.approx(PUMA_COMPACT_LENGTH, abs=1e-5)
    assert chain.totalPathLength() == pytest.approx(PUMA_SHORTENED_LENGTH, abs=1e-5)
    document = json.loads((DESIGNS / "puma.json").read_text())
    assert len(document["edits"]) == 5  # the slides, one per joint moved
    assert all(edit["propagate"] is False for edit in document["edits"])


# --- the scripts, run as programs -------------------------------------------------------------
@pytest.fixture(scope="module")
def script_runs(tmp_path_factory):
    """Every script started at once (``python examples/<name>.py <tmp>/<name>``); waited on in
    the tests. Returns name -> (process, output folder)."""
    env = source_env()
    runs = {}
    for name in SCRIPTS:
        folder = tmp_path_factory.mktemp("gallery") / name
        process = subprocess.Popen(
            [sys.executable, str(EXAMPLES / f"{name}.py"), str(folder)],
            stdout=subprocess.PIPE,
            stderr=subprocess.PIPE,
            text=True,
            env=env,
            cwd=tmp_path_factory.getbasetemp(),
        )
        runs[name] = (process, folder)
    yield runs
    for process, _ in runs.values():
        if process.poll() is None:
            process.kill()
            process.wait()


@pytest.mark.parametrize("name", SCRIPTS)
def test_script_writes_its_files(name, script_runs, designs):
    process, folder = script_runs[name]
    out, err = process.communicate(timeout=300)
    assert process.returncode == 0, err
    files = [folder / f"{name}.png", folder / f"{name}_pattern.png", folder / f"{name}.dxf"]
    assert sorted(folder.iterdir()) == sorted(files)  # and no temporary file left over
    for path in files:
        assert str(path) in out
    for path in files[:2]:
        assert path.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    # the DXF is the sheet: n b wide plus half a glue panel on each side, as long as the pattern
    chain = designs[name]
    pattern = chain.creasePattern()
    side = pattern.width / chain.numSides
    size = bbox.extents(ezdxf.readfile(files[2]).modelspace()).size
    assert size.x == pytest.approx(pattern.width + side, rel=1e-6)
    assert size.y == pytest.approx(pattern.height, rel=1e-6)


def test_script_rejects_extra_arguments(tmp_path):
    result = subprocess.run(
        [sys.executable, str(EXAMPLES / "planar_joint.py"), "a", "b"],
        capture_output=True,
        text=True,
        cwd=tmp_path,
        env=source_env(),
    )
    assert result.returncode != 0
    assert "usage: python planar_joint.py [output-folder]" in result.stderr
    assert not (tmp_path / "a").exists()


def test_make_gallery_writes_both_pictures(tmp_path):
    result = subprocess.run(
        [
            sys.executable,
            str(EXAMPLES / "make_gallery.py"),
            "planar_joint",
            "--output",
            str(tmp_path),
        ],
        capture_output=True,
        text=True,
        cwd=tmp_path,
        env=source_env(),
    )
    assert result.returncode == 0, result.stderr
    assert sorted(p.name for p in tmp_path.iterdir()) == [
        "planar_joint.png",
        "planar_joint_pattern.png",
    ]
    assert "1 gallery entries" in result.stdout


def test_make_gallery_unknown_name(tmp_path):
    result = subprocess.run(
        [sys.executable, str(EXAMPLES / "make_gallery.py"), "nosuch", "--output", str(tmp_path)],
        capture_output=True,
        text=True,
        cwd=tmp_path,
        env=source_env(),
    )
    assert result.returncode == 2
    assert "no design file for nosuch" in result.stderr
    assert list(tmp_path.iterdir()) == []


def test_gallery_pictures_do_not_depend_on_the_process_or_the_cpu(tmp_path):
    """make_gallery.py writes byte-identical pictures in two fresh processes, the second with
    another hash seed and another OpenBLAS kernel (what another CPU picks): the tracked PNGs only
    change when the chain does. The PNGs carry no matplotlib version stamp either."""
    runs = {
        "a": {"PYTHONHASHSEED": "0"},
        "b": {"PYTHONHASHSEED": "7", "OPENBLAS_CORETYPE": "Prescott"},
    }
    processes = {
        key: subprocess.Popen(
            [sys.executable, str(EXAMPLES / "make_gallery.py"), "spherical_joint", "--output",
             str(tmp_path / key)],
            stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True,
            env=source_env(**extra),
        )
        for key, extra in runs.items()
    }  # fmt: skip
    for process in processes.values():
        _, err = process.communicate(timeout=600)
        assert process.returncode == 0, err
    pictures = [{p.name: p.read_bytes() for p in (tmp_path / key).iterdir()} for key in runs]
    assert sorted(pictures[0]) == ["spherical_joint.png", "spherical_joint_pattern.png"]
    assert pictures[0] == pictures[1]
    for data in pictures[0].values():
        assert b"Software" not in data and b"atplotlib" not in data


def test_example1_script_says_which_size_is_which(tmp_path):
    """examples/example1.py prints the crease pattern without the glue tab and the sheet with
    it, in cm, and the sheet in mm as ``kinegami build`` prints it for the design file."""
    from kinegami.pattern.sheet import flatten

    result = subprocess.run(
        [sys.executable, str(EXAMPLES / "example1.py"), str(tmp_path / "out")],
        capture_output=True, text=True, cwd=tmp_path, env=source_env(), timeout=600,
    )  # fmt: skip
    assert result.returncode == 0, result.stderr
    chain, info = load_design_with_info(DESIGNS / "example1.json")
    assert info.units == "cm"
    pattern = chain.creasePattern()
    xmin, ymin, xmax, ymax = flatten(pattern).bounds
    w, h, sw, sh = pattern.width, pattern.height, xmax - xmin, ymax - ymin
    text = result.stdout
    assert f"crease pattern: {w:.3f} cm x {h:.3f} cm, without the glue tab" in text
    assert f"sheet: {sw:.3f} cm x {sh:.3f} cm with the glue tab" in text
    assert f"{10 * sw:.1f} mm x {10 * sh:.1f} mm" in text
    assert (tmp_path / "out" / "examplePatterns" / "example1.dxf").is_file()
