"""The 3D CSC Dubins solver (spec/chain.md section 2, checks 11.7).

Besides the unit cases, kinegami's ``solve_csc`` is compared with an oracle written here: the
reference algorithm of chain.md 2.2, implemented literally (four sign candidates, scipy
``fsolve`` with default settings from the reference's initial guess, convergence at 0.001 r,
shortest converged candidate, the (+,+) candidate if none converged).
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
from scipy.optimize import fsolve

from kinegami import SE3, LinkCSC, NoPathError
from kinegami.geometry.csc import solve_csc
from kinegami.geometry.frames import rotation_matrix

# --- the reference algorithm (chain.md 2.2), as an oracle -----------------------------------

#: Candidate order of the reference: (circle1sign, circle2sign) = (+,+), (+,-), (-,+), (-,-),
#: i.e. (sigma1, sigma2) = (short, long), (short, short), (long, long), (long, short).
REFERENCE_SIGNS = ((1, -1), (1, 1), (-1, -1), (-1, 1))
EPS_SELECT = 1e-3  # x r: a candidate counts as converged
EPS_LINK = 1e-2  # x r: a link accepts a candidate


def _angle(a, b) -> float:
    return math.atan2(float(np.linalg.norm(np.cross(a, b))), float(a @ b))


def _wrap(angle: float) -> float:
    w = angle % (2 * math.pi)
    return 0.0 if 2 * math.pi - w < 1e-5 else w


def _closure(p1, d1, p2, d2, r, signs):
    """F(x) of chain.md 2.2 for one sign pair, and a decoder of x."""
    sigma1, sigma2 = signs

    def decode(x):
        v = x[:3]
        norm = float(np.linalg.norm(v))
        u = v / norm
        g1, g2 = _angle(d1, u), _angle(u, d2)
        q1 = p1 + sigma1 * r * math.tan(g1 / 2) * (d1 + u)
        q2 = p2 - sigma2 * r * math.tan(g2 / 2) * (u + d2)
        return u, abs(x[3]), g1, g2, q1, q2, norm

    def F(x):
        u, s, _, _, q1, q2, norm = decode(x)
        return np.concatenate([s * u - (q2 - q1), [norm - 1.0]])

    return F, decode


def reference_csc(p1, d1, p2, d2, r) -> dict:
    """The candidate the reference selects (chain.md 2.2), with its residual |F|."""
    p1, p2 = np.asarray(p1, float), np.asarray(p2, float)
    d1 = np.asarray(d1, float) / np.linalg.norm(d1)
    d2 = np.asarray(d2, float) / np.linalg.norm(d2)
    delta = p2 - p1
    distance = float(np.linalg.norm(delta))
    if distance == 0.0:
        v0, s0 = d1.copy(), r
    else:
        v0, s0 = delta / distance, distance
    x0 = np.concatenate([v0, [s0]])
    candidates = []
    for signs in REFERENCE_SIGNS:
        F, decode = _closure(p1, d1, p2, d2, r, signs)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")  # fsolve's "not making progress"
            x = fsolve(F, x0)
            residual = float(np.linalg.norm(F(x)))
        u, s, g1, g2, _, _, _ = decode(x)
        theta1 = g1 if signs[0] > 0 else _wrap(2 * math.pi - g1)
        theta2 = g2 if signs[1] > 0 else _wrap(2 * math.pi - g2)
        candidates.append({
            "signs": signs, "theta1": theta1, "theta2": theta2, "tMag": s, "u": u,
            "residual": residual, "length": r * theta1 + s + r * theta2, "x": x,
        })  # fmt: skip
    converged = [c for c in candidates if c["residual"] <= EPS_SELECT * r]
    if not converged:
        return candidates[0]
    return min(converged, key=lambda c: c["length"])  # min keeps the first of ties


def reference_accepts(candidate: dict, r: float) -> bool:
    """chain.md 2.3: the link accepts the selected candidate."""
    return (
        candidate["residual"] <= EPS_LINK * r
        and candidate["theta1"] < math.pi
        and candidate["theta2"] < math.pi
    )


def polish(p1, d1, p2, d2, r, candidate) -> dict:
    """fsolve restarted from the selected iterate (same sign family).

    fsolve stops once its step is below 1.49e-8 relative, so the reference's own values are
    accurate to ~1e-8 only; restarting once brings the residual to round-off, which makes a
    1e-9 comparison meaningful.
    """
    p1, p2 = np.asarray(p1, float), np.asarray(p2, float)
    d1 = np.asarray(d1, float) / np.linalg.norm(d1)
    d2 = np.asarray(d2, float) / np.linalg.norm(d2)
    F, decode = _closure(p1, d1, p2, d2, r, candidate["signs"])
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        x = fsolve(F, candidate["x"])
    u, s, g1, g2, _, _, _ = decode(x)
    return {"theta1": g1, "theta2": g2, "tMag": s, "residual": float(np.linalg.norm(F(x)))}


# --- unit cases (chain.md 11.7) ------------------------------------------------------------


def frames_of(case):
    return case["p1"], case["d1"], case["p2"], case["d2"]


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
    # the closed form quoted by the spec
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


def test_identical_frames_give_the_empty_path():
    path = solve_csc((1, 2, 3), (0, 1, 0), (1, 2, 3), (0, 1, 0), 0.5)
    assert path is not None
    assert (path.theta1, path.tMag, path.theta2, path.length) == (0.0, 0.0, 0.0, 0.0)


def test_u_turn_has_no_path():
    case = ref.CSC_U_TURN
    assert solve_csc(*frames_of(case), 1.0) is None
    start = SE3.Trans(*case["p1"]) * SE3.Ry(-math.pi / 2)  # x along +z
    end = SE3.Trans(*case["p2"]) * SE3.Ry(math.pi / 2)  # x along -z
    with pytest.raises(NoPathError):
        LinkCSC(1, start, end)


def test_directions_need_not_be_normalised():
    case = ref.CSC_3D
    unit = solve_csc(*frames_of(case), 1.0)
    scaled = solve_csc(
        case["p1"], np.multiply(case["d1"], 3.0), case["p2"], np.multiply(case["d2"], 0.2), 1.0
    )
    assert (scaled.theta1, scaled.tMag, scaled.theta2) == pytest.approx(
        (unit.theta1, unit.tMag, unit.theta2), abs=1e-12
    )


# --- the oracle itself -----------------------------------------------------------------------


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


# --- kinegami vs the oracle on random frame pairs --------------------------------------------

ORACLE_PAIRS = 300


def _random_unit(rng):
    v = rng.normal(size=3)
    return v / np.linalg.norm(v)


@pytest.fixture(scope="module")
def oracle_comparison():
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


def test_solver_finds_every_path_the_reference_accepts(oracle_comparison):
    missed = [rec for rec in oracle_comparison if rec["accepted"] and rec["path"] is None]
    assert not missed, f"{len(missed)} frame pairs with a reference path but none from kinegami"
    accepted = sum(rec["accepted"] for rec in oracle_comparison)
    assert accepted >= ORACLE_PAIRS // 2  # sanity of the sample (spec: ~70% at 0-12 r)


def test_solver_matches_the_reference_values(oracle_comparison):
    worst_raw = worst_polished = 0.0
    for rec in oracle_comparison:
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


def test_paths_found_beyond_the_reference_are_valid(oracle_comparison):
    extra = [rec for rec in oracle_comparison if rec["path"] is not None and not rec["accepted"]]
    for rec in extra:
        path, r = rec["path"], rec["r"]
        end, tangent = path.reconstruct_end()
        np.testing.assert_allclose(end, rec["frames"][2], rtol=0, atol=1e-9 * r)
        np.testing.assert_allclose(tangent, rec["frames"][3], rtol=0, atol=1e-9)
        assert path.theta1 < math.pi and path.theta2 < math.pi and path.tMag >= 0
    both = sum(rec["accepted"] and rec["path"] is not None for rec in oracle_comparison)
    neither = sum(not rec["accepted"] and rec["path"] is None for rec in oracle_comparison)
    print(
        f"\nCSC vs reference on {len(oracle_comparison)} pairs: both {both}, "
        f"kinegami only {len(extra)}, reference only 0, neither {neither}"
    )


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
    start = time.perf_counter()
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # no numpy overflow / invalid-value warnings either
        path = solve_csc(*args)
    assert time.perf_counter() - start < 0.2
    if path is not None:
        p1, _, p2, d2, r = args
        scale = max(float(np.linalg.norm(p1)), float(np.linalg.norm(p2)), r)
        end, tangent = path.reconstruct_end()
        np.testing.assert_allclose(
            end, p2, rtol=0, atol=1e-9 * r + 64 * np.finfo(float).eps * scale
        )
        np.testing.assert_allclose(tangent, d2, rtol=0, atol=1e-9)
        assert 0 <= path.theta1 < math.pi and 0 <= path.theta2 < math.pi
        assert path.tMag >= 0


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


# --- properties on random frames (hypothesis) ------------------------------------------------

coordinates = st.floats(-12, 12, allow_nan=False)
vectors = st.tuples(coordinates, coordinates, coordinates)
directions = (
    st.tuples(*[st.floats(-1, 1)] * 3)
    .filter(lambda v: 0.1 < math.hypot(*v))
    .map(lambda v: np.array(v) / math.hypot(*v))
)
radii = st.floats(0.02, 50)


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
    # centre-based description (chain.md 2.1)
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
    quaternion=st.tuples(*[st.floats(-1, 1)] * 4).filter(lambda q: math.hypot(*q) > 0.1),
    shift=vectors,
)
def test_solution_is_equivariant_under_rigid_motions(r, p1, offset, d1, d2, quaternion, shift):
    from scipy.spatial.transform import Rotation

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
    from scipy.spatial.transform import Rotation

    R1 = Rotation.from_quat((0, 0, 1, 0)).as_matrix()
    R2 = Rotation.from_quat((-1.192092896e-07, 0, 0.75, 1e-6)).as_matrix()
    p2 = np.array([0.0, 1.0, 3.25])
    path = solve_csc(np.zeros(3), R1[:, 0], p2, R2[:, 0], 1.0)
    if path is not None:
        end, tangent = path.reconstruct_end()
        assert np.max(np.abs(end - p2)) <= 1e-9
