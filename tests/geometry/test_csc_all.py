"""Every (short, short) CSC path between two frames: kinegami.geometry.csc.solve_csc_all.

Checked against solve_csc (its path is always in the list) and against an independent
brute-force oracle (tests/geometry/csc_oracle.py: a winding-number scan of the closure residual
over the first turn's direction and angle, refined with scipy).
"""

from __future__ import annotations

import math
import time
import warnings

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from test_csc import DEGENERATE

from kinegami.geometry.csc import CSCPath, solve_csc, solve_csc_all
from kinegami.geometry.frames import rotation_matrix

from .csc_oracle import oracle_paths

coordinates = st.floats(-12, 12, allow_nan=False)
vectors = st.tuples(coordinates, coordinates, coordinates)
directions = (
    st.tuples(*[st.floats(-1, 1)] * 3)
    .filter(lambda v: 0.1 < math.hypot(*v))
    .map(lambda v: np.array(v) / math.hypot(*v))
)
radii = st.floats(0.02, 50)


def assert_valid(path: CSCPath, p2, d2, r: float) -> None:
    """The path closes to 1e-9 r, turns by less than pi twice, has a straight part >= 0."""
    assert 0 <= path.theta1 < math.pi and 0 <= path.theta2 < math.pi and path.tMag >= 0
    end, tangent = path.reconstruct_end()
    np.testing.assert_allclose(end, p2, rtol=0, atol=1e-9 * r)
    np.testing.assert_allclose(tangent, d2, rtol=0, atol=1e-9)
    assert path.length == pytest.approx(r * path.theta1 + path.tMag + r * path.theta2)


def same_values(p: CSCPath, q: CSCPath) -> bool:
    return (p.theta1, p.theta2, p.tMag, p.tUnit.tolist()) == (
        q.theta1,
        q.theta2,
        q.tMag,
        q.tUnit.tolist(),
    )


# --- properties on random frames (hypothesis) ------------------------------------------------


@settings(deadline=None, max_examples=150)
@given(r=radii, p1=vectors, offset=vectors, d1=directions, d2=directions)
def test_every_returned_path_is_valid_sorted_and_distinct(r, p1, offset, d1, d2):
    p1 = np.array(p1) * r
    p2 = p1 + np.array(offset) * r
    paths = solve_csc_all(p1, d1, p2, d2, r)
    for path in paths:
        assert_valid(path, p2, d2, r)
    lengths = [p.length for p in paths]
    assert lengths == sorted(lengths)
    for i, p in enumerate(paths):
        for q in paths[i + 1 :]:
            assert (
                max(abs(p.theta1 - q.theta1), abs(p.theta2 - q.theta2), abs(p.tMag - q.tMag) / r)
                > 1e-9
                or np.max(np.abs(p.tUnit - q.tUnit)) > 1e-9
            )


@settings(deadline=None, max_examples=150)
@given(r=radii, p1=vectors, offset=vectors, d1=directions, d2=directions)
def test_solve_csc_path_is_among_them_and_first_when_shortest(r, p1, offset, d1, d2):
    p1 = np.array(p1) * r
    p2 = p1 + np.array(offset) * r
    first = solve_csc(p1, d1, p2, d2, r)
    paths = solve_csc_all(p1, d1, p2, d2, r)
    if first is None:
        return
    assert any(same_values(first, p) for p in paths)
    others = [p for p in paths if not same_values(first, p)]
    if all(first.length < p.length for p in others):
        assert same_values(paths[0], first)


turns = st.one_of(
    st.floats(0, math.pi - 1e-3),
    st.floats(-8, -0.5).map(lambda e: 10**e),  # nearly straight
    st.floats(-3, -0.5).map(lambda e: math.pi - 10**e),  # nearly U-turns
    st.just(0.0),
)


@settings(deadline=None, max_examples=300)
@given(
    r=radii,
    d1=directions,
    side1=directions,
    side2=directions,
    theta1=turns,
    theta2=turns,
    tMag=st.one_of(st.floats(1e-3, 12), st.floats(-3, 0).map(lambda e: 10**e)),
)
def test_every_path_built_forwards_is_found(r, d1, side1, side2, theta1, theta2, tMag):
    """Follow a path from (0, d1) (turns up to pi - 1e-3, straight part >= 1e-3 r): the frame
    it ends in gets that path back."""
    w1 = np.cross(d1, side1)
    u = rotation_matrix(np.cross(d1, w1), theta1) @ d1 if np.linalg.norm(w1) > 1e-6 else d1
    w2 = np.cross(u, side2)
    d2 = rotation_matrix(np.cross(u, w2), theta2) @ u if np.linalg.norm(w2) > 1e-6 else u
    if np.linalg.norm(w1) <= 1e-6 and theta1 > 0 or np.linalg.norm(w2) <= 1e-6 and theta2 > 0:
        return  # no turning plane drawn
    a, b = math.tan(theta1 / 2), math.tan(theta2 / 2)
    p2 = r * (a * (d1 + u) + tMag * u + b * (u + d2))
    paths = solve_csc_all(np.zeros(3), d1, p2, d2, r)
    errors = [
        max(abs(p.theta1 - theta1), abs(p.theta2 - theta2), abs(p.tMag / r - tMag)) for p in paths
    ]
    error = min(errors, default=math.inf)
    assert error <= 1e-8


@settings(deadline=None, max_examples=60)
@given(
    r=radii,
    p1=vectors,
    offset=vectors,
    d1=directions,
    d2=directions,
    quaternion=st.tuples(*[st.floats(-1, 1)] * 4).filter(lambda q: math.hypot(*q) > 0.1),
)
def test_paths_are_equivariant_under_rigid_motions(r, p1, offset, d1, d2, quaternion):
    from scipy.spatial.transform import Rotation

    R = Rotation.from_quat(quaternion).as_matrix()
    p1 = np.array(p1) * r
    p2 = p1 + np.array(offset) * r
    here = solve_csc_all(p1, d1, p2, d2, r)
    there = solve_csc_all(R @ p1, R @ d1, R @ p2, R @ d2, r)
    assert len(here) == len(there)
    for a, b in zip(here, there, strict=True):
        np.testing.assert_allclose(
            [b.theta1, b.theta2, b.tMag / r], [a.theta1, a.theta2, a.tMag / r], atol=1e-9
        )
        np.testing.assert_allclose(b.tUnit, R @ a.tUnit, rtol=0, atol=1e-9)


# --- the brute-force oracle ------------------------------------------------------------------

ORACLE_CASES = 240


def _random_unit(rng):
    v = rng.normal(size=3)
    return v / np.linalg.norm(v)


@pytest.fixture(scope="module")
def oracle_comparison():
    """solve_csc_all and the oracle on ORACLE_CASES seeded frame pairs, 0-3 r and 0-12 r apart."""
    rng = np.random.default_rng(20250214)
    records = []
    for k in range(ORACLE_CASES):
        r = float(10 ** rng.uniform(math.log10(0.02), math.log10(50)))
        p1 = rng.uniform(-5, 5, 3) * r
        p2 = p1 + rng.uniform(0, 3 if k % 2 else 12) * r * _random_unit(rng)
        d1, d2 = _random_unit(rng), _random_unit(rng)
        records.append({
            "frames": (p1, d1, p2, d2), "r": r, "paths": solve_csc_all(p1, d1, p2, d2, r),
            "oracle": oracle_paths(p1, d1, p2, d2, r),
        })  # fmt: skip
    return records


def test_the_oracle_finds_no_path_that_solve_csc_all_misses(oracle_comparison):
    missed = []
    for rec in oracle_comparison:
        r = rec["r"]
        for theta1, theta2, tMag, _ in rec["oracle"]:
            if not any(
                abs(p.theta1 - theta1) < 1e-7
                and abs(p.theta2 - theta2) < 1e-7
                and abs(p.tMag - tMag) < 1e-7 * r
                for p in rec["paths"]
            ):
                missed.append((rec["frames"], r, (theta1, theta2, tMag)))
    assert not missed, f"{len(missed)} oracle paths missing, first {missed[0]}"
    seen = sum(len(rec["oracle"]) for rec in oracle_comparison)
    assert seen >= ORACLE_CASES // 4  # the sample has paths to find (about 40% of the pairs)


def test_solve_csc_all_finds_nothing_the_oracle_cannot_confirm(oracle_comparison):
    """Every path solve_csc_all returns is also a root the oracle's grid sees."""
    unconfirmed = [
        rec
        for rec in oracle_comparison
        for p in rec["paths"]
        if not any(
            abs(p.theta1 - o[0]) < 1e-7 and abs(p.theta2 - o[1]) < 1e-7 for o in rec["oracle"]
        )
    ]
    counts = np.bincount([len(rec["paths"]) for rec in oracle_comparison])
    print(f"\nsolve_csc_all on {ORACLE_CASES} frame pairs: path counts {counts.tolist()}")
    assert not unconfirmed


# --- hand-made cases -----------------------------------------------------------------------


def test_identical_frames_give_only_the_empty_path():
    (path,) = solve_csc_all((1, 2, 3), (0, 1, 0), (1, 2, 3), (0, 1, 0), 0.5)
    assert (path.theta1, path.tMag, path.theta2) == (0.0, 0.0, 0.0)


def test_u_turn_has_no_path():
    assert solve_csc_all((0, 0, 0), (1, 0, 0), (0, 1, 0), (-1, 0, 0), 1.0) == []


@pytest.mark.parametrize("side", [0.0, 2.0, 3.9])
def test_frame_behind_facing_the_same_way_has_no_path(side):
    """Behind and less than 4 r to the side, an S-curve would need turns of pi or more."""
    assert solve_csc_all((0, 0, 0), (1, 0, 0), (-5, side, 0), (1, 0, 0), 1.0) == []


@pytest.mark.parametrize("side", [4.1, 6.0, 20.0])
def test_frame_behind_facing_the_same_way_and_aside_has_one_s_curve(side):
    (path,) = solve_csc_all((0, 0, 0), (1, 0, 0), (-5, side, 0), (1, 0, 0), 1.0)
    assert_valid(path, (-5, side, 0), (1, 0, 0), 1.0)
    assert path.theta1 == pytest.approx(path.theta2, abs=1e-9)  # symmetric S-curve
    assert path.theta1 > math.pi / 2
    np.testing.assert_allclose(path.tUnit[2], 0.0, atol=1e-12)  # in the plane of the frames


@pytest.mark.parametrize("angle", [0.3, math.pi / 2, 2.5])
@pytest.mark.parametrize("tilt", [0.0, 0.7])
def test_a_single_arc_is_one_path_not_a_family_of_splits(angle, tilt):
    """p2, d2 on one circle through (p1, d1): every split of the arc between the two turns (with
    no straight part) closes; they are one curve, returned once."""
    axis = rotation_matrix((1, 0, 0), tilt) @ np.array([0.0, 0.0, 1.0])
    centre = np.cross(axis, (1.0, 0.0, 0.0))
    R = rotation_matrix(axis, angle)
    p2 = centre + R @ -centre
    d2 = R @ np.array([1.0, 0.0, 0.0])
    (path,) = solve_csc_all(np.zeros(3), (1, 0, 0), p2, d2, 1.0)
    assert_valid(path, p2, d2, 1.0)
    assert path.theta1 + path.theta2 == pytest.approx(angle, abs=1e-9)
    assert path.tMag <= 1e-9
    assert path.length == pytest.approx(angle, abs=1e-9)


@pytest.mark.parametrize("args", DEGENERATE.values(), ids=DEGENERATE.keys())
def test_degenerate_inputs_return_quickly_without_raising(args):
    start = time.perf_counter()
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # no numpy overflow / invalid-value warnings either
        paths = solve_csc_all(*args)
    assert time.perf_counter() - start < 0.5
    first = solve_csc(*args)
    assert first is None or any(same_values(first, p) for p in paths)
    p1, _, p2, d2, r = args
    scale = max(float(np.linalg.norm(p1)), float(np.linalg.norm(p2)), r)
    for path in paths:
        end, tangent = path.reconstruct_end()
        np.testing.assert_allclose(
            end, p2, rtol=0, atol=1e-9 * r + 64 * np.finfo(float).eps * scale
        )
        np.testing.assert_allclose(tangent, d2, rtol=0, atol=1e-9)
        assert 0 <= path.theta1 < math.pi and 0 <= path.theta2 < math.pi and path.tMag >= 0
