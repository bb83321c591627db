"""The 3D CSC Dubins solvers: ``solve_csc`` (the shortest path) and ``solve_csc_all`` (every
(short, short) path between two frames), docs/theory/csc.md.

``solve_csc`` is checked on the published unit cases (tests/reference_values.py) and against the
reference algorithm implemented literally (tests/geometry/csc_reference.py); ``solve_csc_all``
against ``solve_csc`` (its path is always in the list) and an independent brute-force oracle
(tests/geometry/csc_oracle.py: a winding-number scan of the closure residual over the first
turn's direction and angle, refined with scipy). Both share the degenerate inputs and the
hypothesis strategies below.
"""

from __future__ import annotations

import math
import time
import warnings

import numpy as np
import pytest
import reference_values as ref
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.spatial.transform import Rotation

from kinegami import SE3, LinkCSC, NoPathError
from kinegami.geometry.csc import CSCPath, solve_csc, solve_csc_all
from kinegami.geometry.frames import rotation_matrix

from .csc_oracle import oracle_paths
from .csc_reference import polish, reference_accepts, reference_csc

coordinates = st.floats(-12, 12, allow_nan=False)
vectors = st.tuples(coordinates, coordinates, coordinates)
directions = (
    st.tuples(*[st.floats(-1, 1)] * 3)
    .filter(lambda v: 0.1 < math.hypot(*v))
    .map(lambda v: np.array(v) / math.hypot(*v))
)
radii = st.floats(0.02, 50)
quaternions = st.tuples(*[st.floats(-1, 1)] * 4).filter(lambda q: math.hypot(*q) > 0.1)


def frames_of(case):
    return case["p1"], case["d1"], case["p2"], case["d2"]


def _random_unit(rng):
    v = rng.normal(size=3)
    return v / np.linalg.norm(v)


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


# --- solve_csc: the published unit cases ----------------------------------------------


def test_planar_s_curve():
    case = ref.CSC_PLANAR_S
    path = solve_csc(*frames_of(case), 1.0)
    assert path is not None
    np.testing.assert_allclose(
        [path.theta1, path.theta2, path.tMag, path.length],
        [case["theta1"], case["theta2"], case["s"], case["length"]],
        rtol=0,
        atol=ref.ATOL_CSC,
    )
    # the closed form of the planar S-curve
    closed = math.atan(2 / 10) + math.asin(2 / math.sqrt(104))
    assert path.theta1 == pytest.approx(closed, abs=1e-12)


def test_3d_case():
    case = ref.CSC_3D
    path = solve_csc(*frames_of(case), 1.0)
    assert path is not None
    np.testing.assert_allclose(
        [path.theta1, path.tMag, path.theta2, path.length],
        [case["theta1"], case["s"], case["theta2"], case["length"]],
        rtol=0,
        atol=ref.ATOL_CSC,
    )
    np.testing.assert_allclose(path.tUnit, case["u"], rtol=0, atol=ref.ATOL)


def test_identical_frames_give_the_empty_path_and_only_it():
    path = solve_csc((1, 2, 3), (0, 1, 0), (1, 2, 3), (0, 1, 0), 0.5)
    assert path is not None
    assert (path.theta1, path.tMag, path.theta2, path.length) == (0.0, 0.0, 0.0, 0.0)
    (only,) = solve_csc_all((1, 2, 3), (0, 1, 0), (1, 2, 3), (0, 1, 0), 0.5)
    assert (only.theta1, only.tMag, only.theta2) == (0.0, 0.0, 0.0)


def test_u_turns_have_no_path():
    case = ref.CSC_U_TURN
    assert solve_csc(*frames_of(case), 1.0) is None
    start = SE3.Trans(*case["p1"]) * SE3.Ry(-math.pi / 2)  # x along +z
    end = SE3.Trans(*case["p2"]) * SE3.Ry(math.pi / 2)  # x along -z
    with pytest.raises(NoPathError):
        LinkCSC(1, start, end)
    assert solve_csc_all((0, 0, 0), (1, 0, 0), (0, 1, 0), (-1, 0, 0), 1.0) == []


def test_directions_need_not_be_normalised():
    case = ref.CSC_3D
    unit = solve_csc(*frames_of(case), 1.0)
    scaled = solve_csc(
        case["p1"], np.multiply(case["d1"], 3.0), case["p2"], np.multiply(case["d2"], 0.2), 1.0
    )
    assert (scaled.theta1, scaled.tMag, scaled.theta2) == pytest.approx(
        (unit.theta1, unit.tMag, unit.theta2), abs=1e-12
    )


# --- solve_csc against the reference algorithm (tests/geometry/csc_reference.py) ---------


@pytest.mark.parametrize("case", [ref.CSC_PLANAR_S, ref.CSC_3D], ids=["planar", "3d"])
def test_oracle_reproduces_the_unit_cases(case):
    chosen = reference_csc(*frames_of(case), 1.0)
    assert chosen["signs"] == (1, 1)  # (short, short)
    assert reference_accepts(chosen, 1.0)
    np.testing.assert_allclose(
        [chosen["theta1"], chosen["tMag"], chosen["theta2"]],
        [case["theta1"], case["s"], case["theta2"]],
        rtol=0,
        atol=1e-7,
    )


def test_oracle_rejects_the_u_turn():
    chosen = reference_csc(*frames_of(ref.CSC_U_TURN), 1.0)
    assert not reference_accepts(chosen, 1.0)


# --- solve_csc vs the reference on random frame pairs --------------------------------------

ORACLE_PAIRS = 300


@pytest.fixture(scope="module")
def reference_comparison():
    """Both solvers on ORACLE_PAIRS seeded random frame pairs (distance 0-12 r)."""
    rng = np.random.default_rng(20240611)
    records = []
    for _ in range(ORACLE_PAIRS):
        r = float(10 ** rng.uniform(math.log10(0.02), math.log10(50)))
        p1 = rng.uniform(-5, 5, 3) * r
        p2 = p1 + rng.uniform(0, 12) * r * _random_unit(rng)
        d1, d2 = _random_unit(rng), _random_unit(rng)
        chosen = reference_csc(p1, d1, p2, d2, r)
        records.append({
            "frames": (p1, d1, p2, d2), "r": r, "reference": chosen,
            "accepted": reference_accepts(chosen, r), "path": solve_csc(p1, d1, p2, d2, r),
        })  # fmt: skip
    return records


def test_solver_finds_every_path_the_reference_accepts(reference_comparison):
    missed = [rec for rec in reference_comparison if rec["accepted"] and rec["path"] is None]
    assert not missed, f"{len(missed)} frame pairs with a reference path but none from kinegami"
    accepted = sum(rec["accepted"] for rec in reference_comparison)
    assert accepted >= ORACLE_PAIRS // 2  # sanity of the sample (about 70% at 0-12 r)


def test_solver_matches_the_reference_values(reference_comparison):
    worst_raw = worst_polished = 0.0
    for rec in reference_comparison:
        if not (rec["accepted"] and rec["path"] is not None):
            continue
        r, path, chosen = rec["r"], rec["path"], rec["reference"]
        assert chosen["signs"] == (1, 1)  # only (short, short) can be accepted
        mine = np.array([path.theta1, path.theta2, path.tMag / r])
        raw = np.array([chosen["theta1"], chosen["theta2"], chosen["tMag"] / r])
        polished = polish(*rec["frames"], r, chosen)
        exact = np.array([polished["theta1"], polished["theta2"], polished["tMag"] / r])
        # the reference's own iterate is only as good as its residual
        raw_error = float(np.max(np.abs(mine - raw)))
        assert raw_error <= 1e-9 + 10 * chosen["residual"] / r
        polished_error = float(np.max(np.abs(mine - exact)))
        assert polished_error <= 1e-9, (rec["frames"], r)
        worst_raw, worst_polished = max(worst_raw, raw_error), max(worst_polished, polished_error)
    print(
        f"\nCSC vs reference: max |difference| {worst_raw:.2e} (reference iterate), "
        f"{worst_polished:.2e} (polished reference root)"
    )


def test_paths_found_beyond_the_reference_are_valid(reference_comparison):
    extra = [rec for rec in reference_comparison if rec["path"] is not None and not rec["accepted"]]
    for rec in extra:
        path, r = rec["path"], rec["r"]
        end, tangent = path.reconstruct_end()
        np.testing.assert_allclose(end, rec["frames"][2], rtol=0, atol=1e-9 * r)
        np.testing.assert_allclose(tangent, rec["frames"][3], rtol=0, atol=1e-9)
        assert path.theta1 < math.pi and path.theta2 < math.pi and path.tMag >= 0
    both = sum(rec["accepted"] and rec["path"] is not None for rec in reference_comparison)
    neither = sum(not rec["accepted"] and rec["path"] is None for rec in reference_comparison)
    print(
        f"\nCSC vs reference on {len(reference_comparison)} pairs: both {both}, "
        f"kinegami only {len(extra)}, reference only 0, neither {neither}"
    )


# --- solve_csc_all against the brute-force oracle (tests/geometry/csc_oracle.py) ---------

ORACLE_CASES = 240


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


# --- degenerate inputs ---------------------------------------------------------------------

DEGENERATE = {
    "coincident": ((0, 0, 0), (1, 0, 0), (0, 0, 0), (1, 0, 0), 1.0),
    "coincident antiparallel": ((0, 0, 0), (1, 0, 0), (0, 0, 0), (-1, 0, 0), 1.0),
    "coincident perpendicular": ((0, 0, 0), (1, 0, 0), (0, 0, 0), (0, 1, 0), 1.0),
    "nearly coincident": ((0, 0, 0), (1, 0, 0), (1e-13, 0, 0), (1, 0, 0), 1.0),
    "straight ahead": ((0, 0, 0), (1, 0, 0), (5, 0, 0), (1, 0, 0), 1.0),
    "parallel behind": ((0, 0, 0), (1, 0, 0), (-5, 0, 0), (1, 0, 0), 1.0),
    "parallel offset": ((0, 0, 0), (1, 0, 0), (0, 5, 0), (1, 0, 0), 1.0),
    "parallel tiny offset": ((0, 0, 0), (1, 0, 0), (5, 1e-12, 0), (1, 0, 0), 1.0),
    "antiparallel ahead": ((0, 0, 0), (1, 0, 0), (5, 0, 0), (-1, 0, 0), 1.0),
    "antiparallel far ahead": ((0, 0, 0), (1, 0, 0), (500, 0, 0), (-1, 0, 0), 1.0),
    "antiparallel behind": ((0, 0, 0), (1, 0, 0), (-5, 0, 0), (-1, 0, 0), 1.0),
    "antiparallel beside, 2r": ((0, 0, 0), (1, 0, 0), (0, 2, 0), (-1, 0, 0), 1.0),
    "antiparallel beside, < 2r": ((0, 0, 0), (1, 0, 0), (0, 1.9999999, 0), (-1, 0, 0), 1.0),
    "tiny r": ((0, 0, 0), (1, 0, 0), (10, 4, 0), (1, 0, 0), 1e-12),
    "tiny r, 3d": ((0, 0, 0), (1, 0, 0), (0, 10, 5), (0, 0, 1), 1e-9),
    "huge r": ((0, 0, 0), (1, 0, 0), (10, 4, 0), (1, 0, 0), 1e12),
    "huge distance": ((0, 0, 0), (1, 0, 0), (1e12, 4e11, 3), (0, 1, 0), 1.0),
    "huge distance straight": ((0, 0, 0), (1, 0, 0), (1e15, 0, 0), (1, 0, 0), 1.0),
    "huge distance behind": ((0, 0, 0), (1, 0, 0), (-1e12, 0, 0), (0, 1, 0), 1.0),
    "denormal offset": ((0, 0, 0), (1, 0, 0), (1e-300, 0, 0), (1, 0, 0), 1.0),
}


@pytest.mark.parametrize("args", DEGENERATE.values(), ids=DEGENERATE.keys())
def test_degenerate_inputs_return_quickly_without_raising(args):
    """Both solvers, no warning, solve_csc within 0.2 s and solve_csc_all within 0.5 s; every path
    closes and solve_csc's is among solve_csc_all's."""
    p1, _, p2, d2, r = args
    scale = max(float(np.linalg.norm(p1)), float(np.linalg.norm(p2)), r)
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # no numpy overflow / invalid-value warnings either
        start = time.perf_counter()
        first = solve_csc(*args)
        assert time.perf_counter() - start < 0.2
        start = time.perf_counter()
        paths = solve_csc_all(*args)
        assert time.perf_counter() - start < 0.5
    assert first is None or any(same_values(first, p) for p in paths)
    for path in [first] * (first is not None) + paths:
        end, tangent = path.reconstruct_end()
        np.testing.assert_allclose(
            end, p2, rtol=0, atol=1e-9 * r + 64 * np.finfo(float).eps * scale
        )
        np.testing.assert_allclose(tangent, d2, rtol=0, atol=1e-9)
        assert 0 <= path.theta1 < math.pi and 0 <= path.theta2 < math.pi and path.tMag >= 0


@pytest.mark.parametrize(
    "args",
    [
        DEGENERATE["straight ahead"],
        DEGENERATE["parallel offset"],
        DEGENERATE["antiparallel beside, 2r"],
    ],
    ids=["straight", "parallel offset", "half circles"],
)
def test_degenerate_inputs_with_known_paths(args):
    path = solve_csc(*args)
    assert path is not None
    p1, _, p2, _, r = args
    # a planar path: both turns are equal by symmetry; straight: no turn at all
    assert path.theta1 == pytest.approx(path.theta2, abs=1e-9)
    assert path.length >= np.linalg.norm(np.subtract(p2, p1)) - 1e-12


# --- solve_csc_all: hand-made cases --------------------------------------------------


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


# --- solve_csc: properties on random frames (hypothesis) ---------------------------------


@settings(deadline=None, max_examples=150)
@given(r=radii, p1=vectors, offset=vectors, d1=directions, d2=directions)
def test_returned_paths_are_valid(r, p1, offset, d1, d2):
    p1 = np.array(p1) * r
    p2 = p1 + np.array(offset) * r
    path = solve_csc(p1, d1, p2, d2, r)
    if path is None:
        return
    tol = 1e-9 * r
    assert 0 <= path.theta1 < math.pi and 0 <= path.theta2 < math.pi and path.tMag >= 0
    end, tangent = path.reconstruct_end()
    np.testing.assert_allclose(end, p2, rtol=0, atol=tol)
    np.testing.assert_allclose(tangent, d2, rtol=0, atol=1e-9)
    # centre-based description (docs/theory/csc.md, "The closure equation")
    for w, d, k in ((path.w1, d1, path.k1), (path.w2, d2, path.k2)):
        assert abs(np.linalg.norm(w) - 1) < 1e-12 and abs(w @ d) < 1e-9
        np.testing.assert_allclose(k, np.cross(d, w), rtol=0, atol=1e-12)
    np.testing.assert_allclose(np.linalg.norm(path.c1 - path.q1), r, rtol=0, atol=tol)
    np.testing.assert_allclose(np.linalg.norm(path.c2 - path.q2), r, rtol=0, atol=tol)
    np.testing.assert_allclose(
        rotation_matrix(path.k1, path.theta1) @ d1, path.tUnit, rtol=0, atol=1e-9
    )
    np.testing.assert_allclose(path.q1 + path.tMag * path.tUnit, path.q2, rtol=0, atol=tol)
    assert path.length == pytest.approx(r * path.theta1 + path.tMag + r * path.theta2)


@settings(deadline=None, max_examples=100)
@given(r=radii, scale=st.floats(0.05, 20), p1=vectors, offset=vectors, d1=directions, d2=directions)
def test_solution_scales_with_r(r, scale, p1, offset, d1, d2):
    p1 = np.array(p1) * r
    p2 = p1 + np.array(offset) * r
    a = solve_csc(p1, d1, p2, d2, r)
    b = solve_csc(p1 * scale, d1, p2 * scale, d2, r * scale)
    if a is None or b is None:
        return
    np.testing.assert_allclose(
        [b.theta1, b.theta2, b.tMag / (r * scale)],
        [a.theta1, a.theta2, a.tMag / r],
        rtol=0,
        atol=2e-9,  # a straight part of ~3e-7 r next to near-pi turns moves by 1.2e-9 r (find)
    )


@settings(deadline=None, max_examples=100)
@given(
    r=radii,
    p1=vectors,
    offset=vectors,
    d1=directions,
    d2=directions,
    quaternion=quaternions,
    shift=vectors,
)
def test_solution_is_equivariant_under_rigid_motions(r, p1, offset, d1, d2, quaternion, shift):
    R = Rotation.from_quat(quaternion).as_matrix()
    t = np.array(shift) * r
    p1 = np.array(p1) * r
    p2 = p1 + np.array(offset) * r
    a = solve_csc(p1, d1, p2, d2, r)
    b = solve_csc(R @ p1 + t, R @ d1, R @ p2 + t, R @ d2, r)
    if a is None or b is None:
        return
    np.testing.assert_allclose(
        [b.theta1, b.theta2, b.tMag / r], [a.theta1, a.theta2, a.tMag / r], rtol=0, atol=1e-9
    )
    np.testing.assert_allclose(b.tUnit, R @ a.tUnit, rtol=0, atol=1e-9)
    np.testing.assert_allclose(b.q1, R @ a.q1 + t, rtol=0, atol=1e-9 * r)


def test_nearly_straight_turn_keeps_centre_directions_perpendicular():
    """Regression (hypothesis): d2 tilted by 7e-11 from d1 at the same point."""
    d1 = np.array([1.0, 1.0, 0.0]) / math.sqrt(2)
    d2 = np.array([0.70710678118654757, 0.70710678118654757, 7.0710678118654752e-11])
    path = solve_csc(np.zeros(3), d1, np.zeros(3), d2 / np.linalg.norm(d2), 1.0)
    assert path is not None
    for w, d in ((path.w1, d1), (path.w2, d2)):
        assert abs(np.linalg.norm(w) - 1) < 1e-12 and abs(w @ d) < 1e-12


def test_near_u_turn_root_that_misses_the_end_is_rejected():
    """Regression (hypothesis): both turns ~ pi - 1e-6; the Newton root's angle residuals are
    tiny but the end point missed by 1.4e-8 r. Either no path, or one that ends within 1e-9 r."""
    R1 = Rotation.from_quat((0, 0, 1, 0)).as_matrix()
    R2 = Rotation.from_quat((-1.192092896e-07, 0, 0.75, 1e-6)).as_matrix()
    p2 = np.array([0.0, 1.0, 3.25])
    path = solve_csc(np.zeros(3), R1[:, 0], p2, R2[:, 0], 1.0)
    if path is not None:
        end, tangent = path.reconstruct_end()
        assert np.max(np.abs(end - p2)) <= 1e-9


# --- solve_csc_all: properties on random frames (hypothesis) -----------------------------


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
    quaternion=quaternions,
)
def test_paths_are_equivariant_under_rigid_motions(r, p1, offset, d1, d2, quaternion):
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
