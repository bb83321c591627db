"""Inverse kinematics (kinegami.reach.inverse, docs/reach.md): targets that are tip poses of
random clear configurations are reached, and every ok answer is checked through
setJointStates and the design's own clearance, not the solver's numbers; unreachable targets
say why without raising; trees reach every fingertip at once; solve_many gives solve's
answers, also on an executor; bad input is one clear line."""

from __future__ import annotations

import math
import warnings
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import numpy as np
import pytest
from spatialmath import SE3

from kinegami.design import load_design
from kinegami.errors import InvalidParameterError, InvalidTypeError
from kinegami.reach import Target, kinematics, solve, solve_many

DESIGNS = Path(__file__).resolve().parents[2] / "examples" / "designs"


def clear_configurations(design, count: int, seed: int) -> list[np.ndarray]:
    compiled = kinematics(design)
    rng = np.random.default_rng(seed)
    low, high = compiled.ranges[:, 0], compiled.ranges[:, 1]
    found = []
    while len(found) < count:
        q = low + (high - low) * rng.random(low.size)
        if design.clearance(q.tolist()).ok:
            found.append(q)
    return found


def check(path: Path, answer, goals: dict) -> None:
    """An ok answer, checked by the design itself: setJointStates accepts it (with
    requireClearance on), the tips are on the targets, the design is clear."""
    assert answer.ok, answer.reason
    moved = load_design(path)
    moved.requireClearance = True
    assert moved.setJointStates(list(answer.states))
    assert moved.clearance().ok
    r = float(moved.r)
    for tip, target in goals.items():
        frame = moved.Joints[tip].distal_dubins_frame()
        assert np.linalg.norm(frame[:3, 3] - target.position) <= 1e-9 * r + 1e-12 * r
        if target.rotation is not None:
            R = target.rotation @ frame[:3, :3].T
            w = np.array([R[2, 1] - R[1, 2], R[0, 2] - R[2, 0], R[1, 0] - R[0, 1]])
            assert math.atan2(0.5 * np.linalg.norm(w), 0.5 * (np.trace(R) - 1)) <= 2e-9
        if target.axis is not None:  # (atan2: acos near 1 cannot tell apart below 2e-8 rad)
            z, a = frame[:3, 2], target.axis
            assert math.atan2(np.linalg.norm(np.cross(z, a)), float(z @ a)) <= 2e-9


@pytest.mark.parametrize("name", ["puma", "prismatic_spiral", "example1"])
def test_poses_of_clear_configurations_are_reached(name):
    path = DESIGNS / f"{name}.json"
    design = load_design(path)
    compiled = kinematics(design)
    tip = compiled.tips[0]
    for q in clear_configurations(design, 6, seed=1):
        target = Target.of(compiled.fkine(q))
        answer = solve(design, compiled.fkine(q))
        check(path, answer, {tip: target})
        assert answer.position_error <= 1e-9 * design.r and answer.angle_error <= 1e-9
        assert answer.clearance >= 0.0 and answer.reason == ""


def test_positions_and_axes_and_se3_targets():
    path = DESIGNS / "puma.json"
    design = load_design(path)
    compiled = kinematics(design)
    (q,) = clear_configurations(design, 1, seed=2)
    T = compiled.fkine(q)
    for target in (T[:3, 3], Target(T[:3, 3], axis=T[:3, 2]), SE3(T, check=False)):
        answer = design.ikine(target)  # the chain's own word
        check(path, answer, {compiled.tips[0]: Target.of(target)})


@pytest.mark.parametrize("compiled_path", [True, False], ids=["compiled", "numpy"])
@pytest.mark.parametrize("kind", ["pose", "position", "axis"])
def test_both_descents_reach_every_kind_of_target(compiled_path, kind, monkeypatch):
    """A target of one tip runs the compiled descent (kinegami.reach.kernels) where numba can
    run and the batched numpy one where it cannot: both reach poses, positions and axes on the
    9-joint spherical series and on one fingertip of the hand, checked by the designs."""
    import kinegami.reach.inverse as inverse

    if not compiled_path:
        monkeypatch.setattr(inverse, "_KERNEL", [None])
    assert (inverse._kernel() is not None) is compiled_path
    for name, tip in (("spherical_series", None), ("hand", 4)):
        path = DESIGNS / f"{name}.json"
        design = load_design(path)
        compiled = kinematics(design, tip)
        for q in clear_configurations(design, 3, seed=5):
            T = compiled.fkine(q)
            target = {"pose": T, "position": T[:3, 3],
                      "axis": Target(T[:3, 3], axis=T[:3, 2])}[kind]  # fmt: skip
            answer = solve(design, target, tip=compiled.tips[0])
            check(path, answer, {compiled.tips[0]: Target.of(target)})


def test_a_redundant_arm_moves_along_its_solutions_away_from_itself(monkeypatch):
    """The 9-joint spherical series has three joints more than a pose fixes: an exact
    solution that passes through itself is moved along the Jacobian's null space, up the
    clearance's gradient, and brought back onto the target. Target 4 of these (seed 0) is
    reached from its first start (the design's states) that way, its only start here;
    without the moves that start's solution passes through itself. (Other starts reach it
    directly: random ones since a step holds the joints at their limits.)"""
    import kinegami.reach.inverse as inverse

    path = DESIGNS / "spherical_series.json"
    design = load_design(path)
    compiled = kinematics(design)
    T = compiled.fkine(clear_configurations(design, 5, seed=0)[4])
    check(path, solve(design, T), {compiled.tips[0]: Target.of(T)})  # with every start
    monkeypatch.setattr(inverse, "MAX_STARTS", 1)
    answer = solve(design, T)
    check(path, answer, {compiled.tips[0]: Target.of(T)})
    assert answer.restarts == 0
    monkeypatch.setattr(inverse, "ESCAPES", 0)
    blind = solve(design, T)
    assert not blind.ok and blind.reason.startswith("every solution found passes through")


#: Clear configurations (benchmarks/reach_success.py's, seed 0) whose tip poses the solver
#: did not reach while its steps were only clipped at the joints' limits: every start stopped
#: at a limit (7R targets 1198 and 3916), or every exact solution found passed through the arm
#: (9R targets 787 and 1451). Holding a joint at its limit when a step pushes it beyond, the
#: step solved again without it, reaches them.
NEAR_LIMITS = {
    "revolute_spiral": [
        [-1.4603612535892974, 1.5584153495562183, 0.5728295915433046, -1.4726219527578734,
         -1.492027949905758, -1.425696533795577, 1.0127362242988127],
        [0.4233205434926446, -1.5438788998874633, -0.29256570425405926, 1.4649739903171213,
         -0.6530832297131103, -1.3622121423697866, 0.29972440436438164],
    ],
    "spherical_series": [
        [0.0, -1.4974081986268797, -1.0406869374499204, 1.428109715931222,
         -0.29983041667350774, 1.1269751883984873, 0.3512560105393676, 1.539927889926048,
         -0.22092805143493965, 0.38021355465531825, 0.0],
        [0.0, 0.9041267057291131, 1.416783272600929, 0.024573397642021932, -1.2173027516281762,
         -0.6520002421301451, 1.4481670869847951, 0.6716946370977857, 0.7634046501822578,
         0.8698294372632778, 0.0],
    ],
}  # fmt: skip


@pytest.mark.parametrize("name, k", [(name, k) for name in NEAR_LIMITS for k in range(2)])
def test_targets_whose_starts_stopped_at_joint_limits_are_reached(name, k):
    path = DESIGNS / f"{name}.json"
    design = load_design(path)
    compiled = kinematics(design)
    T = compiled.fkine(np.array(NEAR_LIMITS[name][k]))
    answer = solve(design, T)
    check(path, answer, {compiled.tips[0]: Target.of(T)})


def test_random_starts_take_turns_with_the_seed_table(monkeypatch):
    """After the seed table's first TABLE_FIRST configurations, random starts take every
    other turn: the PUMA's target 1137 of benchmarks/reach_success.py (seed 0), whose 63
    nearest table configurations all stop at joint limits, is reached; with the table's
    turns only, it is not."""
    import kinegami.reach.inverse as inverse

    path = DESIGNS / "puma.json"
    design = load_design(path)
    compiled = kinematics(design)
    T = compiled.fkine(np.array([-1.3917002833779568, -1.5557739445204641, 0.04949994135196811,
                                 -1.2593825661356983, -0.3879779214323096, -1.3495348459861591,
                                 0.0]))  # fmt: skip
    answer = solve(design, T)
    check(path, answer, {compiled.tips[0]: Target.of(T)})
    assert answer.restarts > inverse.TABLE_FIRST
    monkeypatch.setattr(inverse, "TABLE_FIRST", inverse.MAX_STARTS)
    assert not solve(design, T).ok


def test_a_step_holds_the_joints_at_limits_that_it_pushes_beyond():
    """The numpy path's steps (several tips, or no numba): a joint at a limit is never pushed
    beyond it; the step is the damped step of the Jacobian without the held joints, which
    makes up for them; a step that pushes no joint beyond is the plain damped step."""
    import kinegami.reach.inverse as inverse

    rng = np.random.default_rng(11)
    k, E, P = 40, 6, 7
    J, e = rng.normal(size=(k, E, P)), rng.normal(size=(k, E))
    lam = np.full(k, 1e-3)
    low, high = -np.ones(P), np.ones(P)
    q = rng.uniform(-0.5, 0.5, (k, P))
    q[:, 2], q[:20, 4] = 1.0, -1.0  # joint 2 at its upper limit, joint 4 at its lower one
    plain = inverse._damped_steps(J, e, lam)
    held = inverse._held_steps(J, e, lam, q, low, high)
    assert not np.any(held[:, 2] > 0) and not np.any(held[:20, 4] < 0)
    pushed = (plain[:, 2] > 0) | ((plain[:, 4] < 0) & (np.arange(k) < 20))
    assert pushed.any() and (~pushed).any()
    np.testing.assert_array_equal(held[~pushed], plain[~pushed])
    for row in np.flatnonzero(pushed):
        still = held[row] == 0.0
        Jh = J[row] * ~still
        expected = Jh.T @ np.linalg.solve(Jh @ Jh.T + lam[row] * np.eye(E), e[row])
        np.testing.assert_allclose(held[row], expected, rtol=1e-10, atol=1e-12)


def test_every_fingertip_of_a_hand_at_once():
    path = DESIGNS / "hand.json"
    hand = load_design(path)
    compiled = kinematics(hand)
    for q in clear_configurations(hand, 3, seed=3):
        poses = compiled.fkine(q)
        goals = {tip: Target(poses[k][:3, 3]) for k, tip in enumerate(compiled.tips)}
        answer = solve(hand, goals)
        check(path, answer, goals)
        assert answer.tips == compiled.tips


def test_a_target_beyond_reach_says_so_and_does_not_raise():
    design = load_design(DESIGNS / "puma.json")
    answer = solve(design, [1e5, 0.0, 0.0])
    assert not answer.ok and answer.reason.startswith("beyond reach: the target is 100000")
    assert answer.restarts == 0 and len(answer.states) == len(design.Joints)
    low = [j.stateRange()[0] for j in design.Joints]
    high = [j.stateRange()[1] for j in design.Joints]
    assert all(lo <= s <= hi for s, lo, hi in zip(answer.states, low, high, strict=True))
    assert design.setJointStates(list(answer.states)) in (True, False)  # accepted as input


def test_an_orientation_the_tip_cannot_take_is_not_a_false_success():
    """The example chain's tip cannot point every way at every position: a pose target whose
    position is reachable but whose rotation is turned far away is not ok, and says why."""
    design = load_design(DESIGNS / "example1.json")
    compiled = kinematics(design)
    (q,) = clear_configurations(design, 1, seed=4)
    T = compiled.fkine(q) @ SE3.Rx(2.5).A @ SE3.Ry(1.2).A
    answer = solve(design, T)
    if answer.ok:  # then it really is exact: check it
        check(DESIGNS / "example1.json", answer, {compiled.tips[0]: Target.of(T)})
    else:
        assert answer.reason and answer.angle_error > 1e-9


def test_clear_false_accepts_a_colliding_answer_and_clear_true_never_does():
    design = load_design(DESIGNS / "puma.json")
    compiled = kinematics(design)
    rng = np.random.default_rng(8)
    low, high = compiled.ranges[:, 0], compiled.ranges[:, 1]
    while True:
        q = low + (high - low) * rng.random(low.size)
        if not design.clearance(q.tolist()).ok:
            break
    target = compiled.fkine(q)
    loose = solve(design, target, q0=q, clear=False)
    assert loose.ok and loose.position_error <= 1e-9 * design.r
    strict = solve(design, target, q0=q)
    if strict.ok:
        assert design.clearance(list(strict.states)).ok
    else:
        assert "passes through itself" in strict.reason


def test_answers_are_deterministic_and_solve_many_is_solve_on_any_executor():
    design = load_design(DESIGNS / "prismatic_spiral.json")
    compiled = kinematics(design)
    targets = [compiled.fkine(q) for q in clear_configurations(design, 5, seed=5)]
    targets.append([1e6, 0.0, 0.0])
    one_by_one = [solve(design, t, seed=3) for t in targets]
    assert [a.states for a in one_by_one] == [solve(design, t, seed=3).states for t in targets]
    assert solve_many(design, targets, seed=3, chunk=1) == one_by_one
    batched = solve_many(design, targets, seed=3, chunk=2)
    with ThreadPoolExecutor(2) as pool:
        spread = solve_many(design, targets, seed=3, executor=pool, chunk=2)
    assert spread == batched
    assert [a.ok for a in batched] == [a.ok for a in one_by_one] == [True] * 5 + [False]
    assert solve_many(design, targets[::-1], seed=3, chunk=1) == one_by_one[::-1]


def test_solve_many_on_a_dask_cluster():
    distributed = pytest.importorskip("distributed")
    design = load_design(DESIGNS / "prismatic_spiral.json")
    compiled = kinematics(design)
    targets = [compiled.fkine(q) for q in clear_configurations(design, 4, seed=6)]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        with distributed.LocalCluster(n_workers=1, threads_per_worker=1, processes=False,
                                      dashboard_address=None) as cluster:  # fmt: skip
            with distributed.Client(cluster) as client:
                answers = solve_many(design, targets, executor=client.get_executor(), chunk=2)
    assert all(a.ok for a in answers)
    assert [a.states for a in answers] == [a.states for a in solve_many(design, targets,
                                                                        chunk=2)]  # fmt: skip


@pytest.mark.parametrize("target, tip, error, words", [
    ("here", None, InvalidTypeError, "target must be a 4x4 pose"),
    ([1.0, 2.0], None, InvalidParameterError, "got shape \\(2,\\)"),
    ([1.0, math.nan, 2.0], None, InvalidParameterError, "3 finite numbers"),
    (np.ones((4, 4)), None, InvalidParameterError, "target"),
    ([1.0, 2.0, 3.0], 99, InvalidParameterError, "tip 99 is not a joint index"),
    ({99: [1.0, 2.0, 3.0]}, None, InvalidParameterError, "target tip 99"),
])  # fmt: skip
def test_bad_targets_are_one_clear_line(target, tip, error, words):
    design = load_design(DESIGNS / "puma.json")
    with pytest.raises(error, match=words) as raised:
        solve(design, target, tip=tip)
    assert "\n" not in str(raised.value)


def test_bad_options_are_one_clear_line():
    design = load_design(DESIGNS / "puma.json")
    with pytest.raises(InvalidParameterError, match="tol must be two positive numbers"):
        solve(design, [0.0, 0.0, 500.0], tol=(0.0, 1e-9))
    with pytest.raises(InvalidTypeError, match="seed must be an int"):
        solve(design, [0.0, 0.0, 500.0], seed=1.5)
    with pytest.raises(InvalidParameterError, match="q must have shape"):
        solve(design, [0.0, 0.0, 500.0], q0=[0.0])
    with pytest.raises(InvalidParameterError, match="tips"):
        solve(load_design(DESIGNS / "hand.json"), [0.0, 0.0, 1.0])  # a tree: which tip?


def test_a_margin_is_kept_or_refused():
    path = DESIGNS / "prismatic_spiral.json"
    design = load_design(path)
    compiled = kinematics(design)
    (q,) = clear_configurations(design, 1, seed=9)
    margin = 0.05 * design.r
    answer = solve(design, compiled.fkine(q), margin=margin)
    if answer.ok:
        assert design.clearance(list(answer.states), margin).ok
        assert answer.clearance >= margin - 1e-9 * design.r
    else:
        assert "passes through itself" in answer.reason
    with pytest.raises(InvalidParameterError, match="margin"):
        solve(design, compiled.fkine(q), margin=-1.0)


def test_the_seed_table_gives_clear_configurations_nearest_first():
    """Restarts begin with the seed table's configurations whose tip poses are nearest the
    target's: each is in range and clear (a chain; asked of the engine when first used, and
    the same verdict as the design's), they come nearest first by the table's features and
    are the nearest of the table's clear configurations, and the same seed gives the same
    table."""
    import kinegami.reach.inverse as inverse
    from kinegami.clearance.engine import engine_for

    design = load_design(DESIGNS / "puma.json")
    compiled = kinematics(design)
    tip = compiled.tips[0]
    table = inverse._seed_table(design, compiled, (tip,), 0)
    assert table.Q.shape[0] == inverse.SEED_TABLE and np.all(table.clear == -1)
    low, high = compiled.ranges[:, 0], compiled.ranges[:, 1]
    assert np.all(table.Q >= low) and np.all(table.Q <= high)
    T = compiled.fkine(clear_configurations(design, 1, seed=9)[0])
    goal = {tip: Target.of(T)}
    near = table.nearest(goal, ("pose",), 5)
    assert near.shape == (5, compiled.n)
    for q in near:
        assert design.clearance(q.tolist()).ok
    asked = np.flatnonzero(table.clear >= 0)  # only the nearest were asked, and rightly
    assert 5 <= asked.size < 100
    for row in asked:
        assert bool(table.clear[row]) == design.clearance(table.Q[row].tolist()).ok
    wanted = table.features(T[None, None], ("pose",))[0]
    clear = ~engine_for(design).colliding(table.Q, 0.0)
    every = np.linalg.norm(table.features(table.T[clear], ("pose",)) - wanted, axis=1)
    gaps = np.linalg.norm(table.features(compiled.tip_poses(near), ("pose",)) - wanted, axis=1)
    np.testing.assert_array_equal(gaps, np.sort(every)[:5])
    assert [q.tolist() for q in table.starts(goal, ("pose",), 3)] == near[:3].tolist()
    assert inverse._seed_table(design, compiled, (tip,), 0) is table  # made once
    again = inverse._SeedTable(design, compiled, (tip,), 0)
    assert np.array_equal(again.Q, table.Q)


def test_a_start_made_exact_by_its_last_step_is_judged_not_replaced(monkeypatch):
    """The batched path (several tips at once) replaces a start that has used its iterations;
    one whose last step has just made it exact is judged first. (With one iteration per start
    and a start a step from the answer, the answer was thrown away: the hand's fingertips
    were then 'not attainable' at errors of 1e-12.)"""
    import kinegami.reach.inverse as inverse

    path = DESIGNS / "hand.json"
    hand = load_design(path)
    compiled = kinematics(hand)
    q = clear_configurations(hand, 1, seed=5)[0]
    poses = compiled.fkine(q)
    goals = {tip: Target(poses[k][:3, 3]) for k, tip in enumerate(compiled.tips)}
    near = q.copy()
    near[compiled.movable] += 1e-6  # one damped step from the answer
    monkeypatch.setattr(inverse, "ITERATIONS", 1)
    monkeypatch.setattr(inverse, "MAX_STARTS", 1)
    monkeypatch.setattr(inverse, "STARTS", 1)
    check(path, solve(hand, goals, q0=near), goals)
