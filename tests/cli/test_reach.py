"""``kinegami reach`` (docs/cli.md, docs/reach.md): a target the design can reach clear of
itself exits 0, prints the states and writes the posed design with -o (the posed design's tip
is on the target); an unreachable one exits 3 with its reason; bad options are one line and
exit 1; a tree names one --tip per --target."""

from __future__ import annotations

import json
import math

import numpy as np
from gallery_designs import DESIGN_DIR

from kinegami.design import load_design
from kinegami.reach import kinematics

from .helpers import assert_clean_failure, run

PUMA = DESIGN_DIR / "puma.json"
HAND = DESIGN_DIR / "hand.json"


def clear_pose(design, seed: int) -> np.ndarray:
    compiled = kinematics(design)
    rng = np.random.default_rng(seed)
    low, high = compiled.ranges[:, 0], compiled.ranges[:, 1]
    while True:
        q = low + (high - low) * rng.random(low.size)
        if design.clearance(q.tolist()).ok:
            return compiled.fkine(q)


def spelled(T: np.ndarray) -> str:
    """X,Y,Z,RX,RY,RZ of a pose: fixed-axis XYZ angles in degrees (R = Rz Ry Rx)."""
    R = T[:3, :3]
    ry = -math.asin(max(-1.0, min(1.0, R[2, 0])))
    rx, rz = math.atan2(R[2, 1], R[2, 2]), math.atan2(R[1, 0], R[0, 0])
    return ",".join(repr(float(v)) for v in (*T[:3, 3], *map(math.degrees, (rx, ry, rz))))


def test_a_reachable_pose_is_reached_and_the_posed_design_written(tmp_path):
    puma = load_design(PUMA)
    T = clear_pose(puma, 1)
    out = tmp_path / "posed.json"
    result = run("reach", PUMA, f"--target={spelled(T)}", "-o", out)
    assert result.returncode == 0, result.stderr
    assert ": reached" in result.stdout and "joint 0" in result.stdout
    assert f"written: {out}" in result.stdout
    posed = load_design(out)
    tip = posed.Joints[-1].distal_dubins_frame()
    assert np.abs(tip[:3, 3] - T[:3, 3]).max() <= 1e-6 * posed.r  # the file's digits
    assert np.abs(tip[:3, :3] - T[:3, :3]).max() <= 1e-6
    assert posed.clearance().ok


def test_a_target_beyond_reach_exits_3_with_its_reason_and_writes_nothing(tmp_path):
    out = tmp_path / "posed.json"
    result = run("reach", PUMA, "--target", "1e5,0,0", "-o", out, "--json")
    assert result.returncode == 3, result.stderr
    data = json.loads(result.stdout)
    assert data["reached"] is False and data["reason"].startswith("beyond reach")
    assert len(data["states"]) == len(load_design(PUMA).Joints)
    assert not out.exists() and "not written" in result.stderr


def test_every_fingertip_of_the_hand():
    hand = load_design(HAND)
    compiled = kinematics(hand)
    compiled_q = None
    rng = np.random.default_rng(2)
    low, high = compiled.ranges[:, 0], compiled.ranges[:, 1]
    while compiled_q is None:
        q = low + (high - low) * rng.random(low.size)
        if hand.clearance(q.tolist()).ok:
            compiled_q = q
    poses = compiled.fkine(compiled_q)
    args = []
    for k, tip in enumerate(compiled.tips):
        # --target=... : a value that starts with a minus sign is not an option
        args += ["--tip", tip, "--target=" + ",".join(repr(float(v)) for v in poses[k][:3, 3])]
    result = run("reach", HAND, *args, "--json")
    assert result.returncode == 0, result.stdout + result.stderr
    assert json.loads(result.stdout)["tips"] == list(compiled.tips)


def test_bad_options_are_one_line():
    assert_clean_failure(run("reach", PUMA, "--target", "1,2"), "--target", "3 or 6")
    assert_clean_failure(run("reach", PUMA, "--target", "1,2,nan"), "--target")
    assert_clean_failure(run("reach", PUMA, "--target", "1,2,3", "--tip", "99"), "--tip", "99")
    assert_clean_failure(run("reach", PUMA, "--target", "1,2,3", "--axis", "0,0,0"), "axis")
    assert_clean_failure(run("reach", HAND, "--target", "1,2,3"), "give --tip J")
    assert_clean_failure(run("reach", PUMA, "--target", "1,2,3", "-o", "x.txt"), "-o", ".json")
    usage = run("reach", PUMA)
    assert usage.returncode == 2 and "--target" in usage.stderr


def test_workspace_writes_the_arrays_the_cloud_and_a_picture(tmp_path):
    out = tmp_path / "space"
    result = run("workspace", PUMA, "-o", out, "--samples", "2000", "--json")
    assert result.returncode == 0, result.stderr
    data = json.loads(result.stdout)
    assert data["samples"] == 2000 and 0 < data["clear"] < 2000
    assert data["volume"] == data["voxels"] * data["voxel"] ** 3
    with np.load(out / "puma_workspace.npz") as arrays:
        assert arrays["points"].shape == (data["clear"], 3)
    assert (out / "puma_workspace.ply").read_bytes().startswith(b"ply\n")
    assert (out / "puma_workspace.png").stat().st_size > 10_000
    words = run("workspace", PUMA, "-o", out, "--samples", "500")
    assert words.returncode == 0 and "lost to self-collision" in words.stdout


def test_workspace_options_are_checked_in_one_line(tmp_path):
    assert_clean_failure(run("workspace", PUMA, "-o", tmp_path, "--samples", "0"), "--samples")
    assert_clean_failure(run("workspace", PUMA, "-o", tmp_path, "--voxel", "-1"), "--voxel")
    assert_clean_failure(run("workspace", HAND, "-o", tmp_path, "--samples", "10"),
                         "give --tip J")
    assert not any(tmp_path.iterdir())
