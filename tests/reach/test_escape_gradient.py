"""A redundant arm's escape from its own body (kinegami.reach.inverse._escape,
kinegami.reach.kernels.escape_step): the clearance engine's closest pairs
(ClearanceEngine.closest_pairs) agree with its report, their clearances' analytic gradients
with central finite differences, an escape keeps the tip exact while it pushes the pairs apart,
a start that stalls is cut short, and answers stay the same for solve and solve_many."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from kinegami.chain.model import KinematicChain
from kinegami.clearance.engine import engine_for, tree_engine
from kinegami.design import load_design
from kinegami.geometry.segments import segment_distance
from kinegami.reach import Target, kinematics, solve, solve_many

DESIGNS = Path(__file__).resolve().parents[2] / "examples" / "designs"


def random_configurations(compiled, count: int, seed: int) -> list[np.ndarray]:
    rng = np.random.default_rng(seed)
    low, high = compiled.ranges[:, 0], compiled.ranges[:, 1]
    return [low + (high - low) * rng.random(low.size) for _ in range(count)]


def engine_of(design):
    if isinstance(design, KinematicChain):
        return engine_for(design)
    return tree_engine(design, None, float(design.margin))


@pytest.mark.parametrize("compiled_kernel", [True, False], ids=["compiled", "numpy"])
@pytest.mark.parametrize("name", ["spherical_series", "prismatic_spiral", "hand"])
def test_closest_pairs_are_the_reports_and_where_they_are(name, compiled_kernel, monkeypatch):
    """The first pair is the report's closest (the same words) and its clearance the report's
    smallest to the bit (with the compiled kernel and without), every pair's clearance is
    the distance of its points less 2r, the pairs are those closer than the margin (and the
    closest), closest first."""
    import kinegami.clearance.engine as engine_module

    if not compiled_kernel:
        monkeypatch.setattr(engine_module, "_KERNEL", [None, None])
    design = load_design(DESIGNS / f"{name}.json")
    engine = engine_of(design)
    r = float(design.r)
    for margin in (0.0, 0.5 * r):
        states = np.array([joint.state for joint in design.Joints])  # ties, often
        for q in [states] + random_configurations(kinematics(design), 12, seed=2):
            report = engine.report(q.tolist(), margin)
            clearance, ends, bodies, s, t, capsules = engine.closest_pairs(q, margin)
            assert clearance[0] == report.min_clearance
            assert engine.label(capsules[0, 0], s[0]) == report.closest.first
            assert engine.label(capsules[0, 1], t[0]) == report.closest.second
            assert np.all(np.diff(clearance) >= 0.0)
            limit = margin - 1e-9 * r
            assert np.all((clearance < limit) | (clearance == clearance[0]))
            assert (clearance < limit).any() == (not report.ok)
            first = ends[:, 0] + s[:, None] * (ends[:, 1] - ends[:, 0])
            second = ends[:, 2] + t[:, None] * (ends[:, 3] - ends[:, 2])
            np.testing.assert_allclose(np.linalg.norm(first - second, axis=1) - 2.0 * r,
                                       clearance, atol=1e-9 * r)  # fmt: skip
            assert bodies.shape == clearance.shape + (4,)
            assert np.all((bodies >= 0) & (bodies < engine.screws.bodies))


def test_closest_pairs_refuse_states_out_of_range():
    design = load_design(DESIGNS / "spherical_series.json")
    q = [joint.state for joint in design.Joints]
    q[1] = 3.0
    with pytest.raises(ValueError, match="range"):
        engine_for(design).closest_pairs(q)


@pytest.mark.parametrize("compiled_kernel", [True, False], ids=["compiled", "numpy"])
@pytest.mark.parametrize("name", ["spherical_series", "puma", "hand"])
def test_closest_pairs_of_many_configurations_are_each_ones(name, compiled_kernel, monkeypatch):
    """ClearanceEngine.closest_pairs_many (a solver's batch of targets asks together) gives
    closest_pairs' arrays at each configuration, to the bit, and checks the states."""
    import kinegami.clearance.engine as engine_module

    if not compiled_kernel:
        monkeypatch.setattr(engine_module, "_KERNEL", [None, None])
    design = load_design(DESIGNS / f"{name}.json")
    engine = engine_of(design)
    states = np.array([joint.state for joint in design.Joints])
    Q = np.array([states] + random_configurations(kinematics(design), 12, seed=4))
    for margin in (0.0, 0.5 * float(design.r)):
        many = engine.closest_pairs_many(Q, margin)
        assert len(many) == Q.shape[0]
        for q, got in zip(Q, many, strict=True):
            for mine, theirs in zip(got, engine.closest_pairs(q, margin), strict=True):
                assert mine.dtype == theirs.dtype and np.array_equal(mine, theirs)
    assert engine.closest_pairs_many(Q[:0]) == []
    bad = Q[:3].copy()
    bad[2, 1] = 1e3
    with pytest.raises(ValueError, match=r"Q\[2\].*range"):
        engine.closest_pairs_many(bad)


def _capsule_rows(engine, q, ends) -> tuple[int, int]:
    """The capsules (rows of engine.segments) whose segments are a pair's ``ends`` at q."""
    a, b = engine.segments(q[None, :])
    a, b = a[0], b[0]
    i = int(np.argmin(np.abs(a - ends[0]).sum(1) + np.abs(b - ends[1]).sum(1)))
    j = int(np.argmin(np.abs(a - ends[2]).sum(1) + np.abs(b - ends[3]).sum(1)))
    assert np.abs(a[i] - ends[0]).max() < 1e-9 and np.abs(b[j] - ends[3]).max() < 1e-9
    return i, j


@pytest.mark.parametrize("name, tip", [("spherical_series", None), ("prismatic_spiral", None),
                                       ("hand", 4)])  # fmt: skip
def test_the_analytic_gradient_is_the_finite_differences_one(name, tip):
    """Each listed pair's clearance gradient with respect to the tip path's joints (the
    closest points moved by the joints' screws, kinegami.reach.kernels.clearance_gradients)
    against central differences of that pair's own segment distance (step 1e-6): within 1e-5
    of the gradient's size, on seeded configurations of a chain and of a tree's finger."""
    import kinegami.reach.inverse as inverse
    from kinegami.reach.kernels import clearance_gradients

    design = load_design(DESIGNS / f"{name}.json")
    compiled = kinematics(design, tip)
    tip = compiled.tips[0]
    engine = engine_of(design)
    steps, path, revolute, reference, E, columns = inverse._tip_path(compiled, tip)[:6]
    moves = inverse._moves(engine, compiled, path)
    r, h = float(design.r), 1e-6
    checked = 0
    for q in random_configurations(compiled, 6, seed=11):
        clearance, ends, bodies, s, t, _ = engine.closest_pairs(q, 2.0 * r)
        G = clearance_gradients(steps, path, revolute, reference, E, q[columns], ends, bodies,
                                s, t, moves)  # fmt: skip
        for k in range(min(clearance.size, 8)):
            if clearance[k] < 1e-3 * r - 2.0 * r:  # the segments (nearly) cross: no direction
                continue
            i, j = _capsule_rows(engine, q, ends[k])
            numeric = np.empty(columns.size)
            for m, c in enumerate(columns.tolist()):
                sides = []
                for sign in (1.0, -1.0):
                    nudged = q.copy()
                    nudged[c] += sign * h
                    a, b = engine.segments(nudged[None, :])
                    sides.append(segment_distance(a[0, i], b[0, i], a[0, j], b[0, j])[0])
                numeric[m] = (sides[0] - sides[1]) / (2.0 * h)
            scale = max(float(np.abs(numeric).max()), 1e-3 * r)
            assert np.abs(G[k] - numeric).max() <= 1e-5 * scale, (k, G[k], numeric)
            checked += 1
    assert checked >= 12


def _colliding_solution(design, compiled, count: int):
    """(target pose, an exact solution that passes through itself) of the 9R: clear
    configurations' tip poses, each solved from random starts until a solution collides."""
    import kinegami.reach.inverse as inverse

    rng = np.random.default_rng(21)
    tip = compiled.tips[0]
    steps, path, revolute, reference, E, columns, low_p, high_p = inverse._tip_path(compiled, tip)
    found = []
    for q in random_configurations(compiled, 200, seed=23):
        if not design.clearance(q.tolist()).ok:
            continue
        T = compiled.fkine(q)
        target = Target.of(T)
        arguments = (steps, path, revolute, reference, E, low_p, high_p, 2, target.position,
                     target.rotation, np.zeros(3), float(design.r), 1e-9, 1e-9)  # fmt: skip
        start = compiled.ranges[:, 0] + np.ptp(compiled.ranges, axis=1) * rng.random(q.size)
        exact, _, _, _, near, _, _ = inverse._kernel()(
            *arguments, start[columns].copy(), 200, inverse.DAMPING, inverse.DAMPING_MIN,
            inverse.DAMPING_MAX)  # fmt: skip
        solution = start.copy()
        solution[columns] = near
        if exact and not design.clearance(solution.tolist()).ok:
            found.append((T, solution, arguments))
        if len(found) == count:
            return found
    raise AssertionError("no colliding solutions found")


def test_an_escape_keeps_the_tip_exact_and_lessens_the_overlap():
    """From exact solutions of the 9R that pass through themselves, the escape ends on an
    exact solution in range whose overlap (the sum of the clearances' shortfalls below the
    margin) is no larger, and clear for most of them."""
    import kinegami.reach.inverse as inverse

    design = load_design(DESIGNS / "spherical_series.json")
    compiled = kinematics(design)
    tip = compiled.tips[0]
    columns = inverse._tip_path(compiled, tip)[5]
    engine = engine_for(design)
    r = float(design.r)
    limit = -1e-9 * r
    apart = inverse.ESCAPE_BUFFER * r
    cleared = 0
    cases = _colliding_solution(design, compiled, 6)
    for T, q, arguments in cases:
        pairs = engine.closest_pairs(q, apart)
        before = inverse._shortfall(pairs[0], limit)
        assert before > 0.0
        moved, after_pairs, _ = inverse._escape(engine, compiled, tip, q, columns, arguments,
                                                pairs, limit, apart)  # fmt: skip
        after = inverse._shortfall(after_pairs[0], limit)
        assert after <= before
        assert np.abs(compiled.fkine(moved) - T).max() <= 1e-9 * r
        low, high = compiled.ranges[:, 0], compiled.ranges[:, 1]
        assert np.all(moved >= low) and np.all(moved <= high)
        report = design.clearance(moved.tolist())
        assert report.min_clearance == after_pairs[0][0]
        cleared += report.ok
    assert cleared >= len(cases) // 2


def test_a_stalled_start_is_cut_short():
    """A start whose error stops falling (a position the 9R's tip cannot reach, inside the
    reach bound) is given up before its iterations run out, and its nearest iterate comes
    back; a start that converges is not cut."""
    import kinegami.reach.inverse as inverse
    from kinegami.reach.kernels import descend

    design = load_design(DESIGNS / "spherical_series.json")
    compiled = kinematics(design)
    tip = compiled.tips[0]
    steps, path, revolute, reference, E, columns, low_p, high_p = inverse._tip_path(compiled, tip)
    radius, centre = inverse.reach_bound(compiled, tip)
    r = float(design.r)
    q0 = np.array([joint.state for joint in design.Joints])
    target = centre + np.array([0.0, 0.0, -0.99 * radius])  # below the base: out of reach
    # (arguments of the solver's own types, contiguous: no second compilation of descend)
    exact, count, pos, ang, best, best_pos, _ = descend(
        steps, path, revolute, reference, E, low_p, high_p, 0, target, np.eye(3), np.zeros(3),
        r, 1e-9, 1e-9, q0[columns].copy(), inverse.ITERATIONS, inverse.DAMPING,
        inverse.DAMPING_MIN, inverse.DAMPING_MAX)  # fmt: skip
    assert not exact and count < inverse.ITERATIONS
    nearest = q0.copy()
    nearest[columns] = best
    assert best_pos <= pos
    assert best_pos == pytest.approx(np.linalg.norm(compiled.fkine(nearest)[:3, 3] - target))
    # a reachable target from the same start converges
    (q,) = random_configurations(compiled, 1, seed=3)
    pose = Target.of(compiled.fkine(q))
    exact, count, *_ = descend(
        steps, path, revolute, reference, E, low_p, high_p, 2, pose.position, pose.rotation,
        np.zeros(3), r, 1e-9, 1e-9, q0[columns].copy(), inverse.ITERATIONS, inverse.DAMPING,
        inverse.DAMPING_MIN, inverse.DAMPING_MAX)  # fmt: skip
    assert exact


def test_the_9r_answers_are_deterministic_and_solve_many_is_solve():
    """Targets whose first start is an exact solution that passes through the arm (so the
    escape runs): the same answers twice, and from solve_many in any chunks; each answer
    checked by the design."""
    design = load_design(DESIGNS / "spherical_series.json")
    compiled = kinematics(design)
    cases = _colliding_solution(design, compiled, 3)
    for T, q, _ in cases:
        answer = solve(design, T, q0=q, seed=1)
        assert answer.ok and solve(design, T, q0=q, seed=1) == answer
        assert solve_many(design, [T], q0=q, seed=1) == [answer]
    targets = [T for T, _, _ in cases]
    one_by_one = [solve(design, T, seed=1) for T in targets]
    assert all(answer.ok for answer in one_by_one)
    assert [solve(design, T, seed=1) for T in targets] == one_by_one
    assert solve_many(design, targets, seed=1, chunk=1) == one_by_one
    assert solve_many(design, targets, seed=1) == one_by_one
    for answer, T in zip(one_by_one, targets, strict=True):
        assert design.clearance(list(answer.states)).ok
        assert np.abs(compiled.fkine(np.array(answer.states)) - T).max() <= 1e-9 * design.r
        assert math.isfinite(answer.clearance) and answer.pair
