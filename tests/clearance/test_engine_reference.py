"""The batched clearance engines (chains: ClearanceEngine; trees: TreeEngine behind TreeMotion)
against a slow reference kept here: at every configuration the design is set to it (a copy,
the way setJointStates moves it), its capsules are built again from the moved joints and links,
and every pair of capsules is measured by brute force with the pair rule (docs/clearance.md,
docs/trees.md). The engines move capsules by rigid-body motions, prune pairs by balls and
measure pairs inside one rigid body once; none of that is allowed to change an answer."""

from __future__ import annotations

import copy
import json
import math
import warnings
from pathlib import Path

import numpy as np
import pytest

import kinegami.clearance.engine as clearance_module
from kinegami import KinematicChain, RevoluteJoint
from kinegami.chain.bodies import TURN_TOLERANCE, capsule_model, clear_limit
from kinegami.clearance import ClearanceEngine, TreeMotion, sweep
from kinegami.clearance.engine import current_states
from kinegami.clearance.tree_bodies import tree_capsules
from kinegami.design import load_design, loads_design
from kinegami.errors import ClearanceWarning
from kinegami.geometry.segments import (
    segment_distance,
    segment_distances,
    segment_distances_xyz,
)

DESIGNS = sorted((Path(__file__).parents[2] / "examples" / "designs").glob("*.json"))
TOLERANCE = 1e-9  # in r


def reference_clearance(design, q, margin: float) -> float:
    """Smallest clearance over every tested pair of capsules at configuration ``q`` (inf when
    nothing is tested), by brute force over all pairs of the capsules built at ``q``."""
    r = float(design.r)
    if isinstance(design, KinematicChain):
        moved = copy.copy(design)
        moved.requireClearance = False
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", ClearanceWarning)
            assert moved.setJointStates(list(q))
        model = capsule_model(moved)
        kinks = np.concatenate([[0.0], np.cumsum([
            abs(j.state) if isinstance(j, RevoluteJoint) else 0.0 for j in moved.Joints])])
        tau = model.turning + kinks[model.start_body + 1]
        a, b = model.starts, model.ends
        i, j = np.triu_indices(model.count, 1)
        tested = tau[j] - tau[i] >= math.pi - TURN_TOLERANCE
        i, j = i[tested], j[tested]
        if i.size == 0:
            return math.inf
        return float(segment_distances(a[i], b[i], a[j], b[j])[0].min() - 2.0 * r)
    ranges = np.array([joint.stateRange() for joint in design.Joints])
    values = tuple(float(v) for v in np.clip(q, ranges[:, 0], ranges[:, 1]))
    joints, links = design._configured(values)
    caps = tree_capsules(joints, links, design.Parents, r, margin)
    tau = caps.turning + np.where(caps.start_joint >= 0,
                                  caps.hinge_turning(joints)[caps.start_joint], 0.0)
    i, j = np.triu_indices(caps.count, 1)
    nx, ny = caps.node[i], caps.node[j]
    same_path = caps.ancestor[nx, ny] | caps.ancestor[ny, nx]
    tested = ~same_path | (np.abs(tau[j] - tau[i]) >= math.pi - TURN_TOLERANCE)
    i, j = i[tested], j[tested]
    if i.size == 0:
        return math.inf
    dist = segment_distances(caps.starts[i], caps.ends[i], caps.starts[j], caps.ends[j])[0]
    junction = np.flatnonzero(caps.junction_pairs(i, j))
    dist[junction] = caps.beyond_junction(i[junction], j[junction])[0]
    return float(dist.min() - 2.0 * r)


def random_configurations(design, count: int, seed: int) -> np.ndarray:
    ranges = np.array([joint.stateRange() for joint in design.Joints], dtype=float)
    rng = np.random.default_rng(seed)
    return ranges[:, 0] + (ranges[:, 1] - ranges[:, 0]) * rng.random((count, len(ranges)))


def agree(found: float, expected: float, r: float) -> bool:
    if math.isinf(expected) or math.isinf(found):
        return found == expected
    return abs(found - expected) <= TOLERANCE * r


@pytest.mark.parametrize("path", DESIGNS, ids=lambda p: p.stem)
def test_engines_agree_with_the_brute_force_reference(path):
    """Every verdict and every depth of the batched engine (worst over a batch) and of the
    one-configuration report equal the reference, with margin 0 and 0.5 r."""
    design = load_design(path)
    r = float(design.r)
    chain = isinstance(design, KinematicChain)
    Q = random_configurations(design, 24 if chain else 8, seed=3)
    for margin in (0.0, 0.5 * r):
        if chain:
            worst, pairs = ClearanceEngine(design).worst(Q, margin)
        else:
            worst, pairs = TreeMotion(design, margin=margin).worst(Q)
        for q, w, pair in zip(Q, worst, pairs, strict=True):
            expected = reference_clearance(design, q, margin)
            closer = expected < clear_limit(r, margin)
            report = design.clearance(list(q), margin=margin)
            assert agree(report.min_clearance, expected, r), (path.stem, margin, q)
            assert report.ok is (not closer)
            assert math.isfinite(w) is closer
            if closer:
                assert agree(w, expected, r)
                assert pair.clearance == w
                assert (pair.first, pair.second) == (report.pairs[0].first,
                                                     report.pairs[0].second)


def test_the_large_assembly_broad_phase_gives_the_same_answers(monkeypatch):
    """Above a number of group pairs the engine finds near groups per configuration with a k-d
    tree instead of a list of all group pairs: the same answers."""
    design = load_design(DESIGNS[0].parent / "puma.json")
    Q = random_configurations(design, 60, seed=5)
    listed = ClearanceEngine(design)
    monkeypatch.setattr(clearance_module, "_GROUP_PAIRS_LISTED", 0)
    spatial = ClearanceEngine(design)
    assert listed._listed and not spatial._listed
    for margin in (0.0, 0.3):
        a, pa = listed.worst(Q, margin)
        b, pb = spatial.worst(Q, margin)
        assert np.array_equal(np.isfinite(a), np.isfinite(b)) and np.isfinite(a).any()
        assert np.allclose(a[np.isfinite(a)], b[np.isfinite(b)], rtol=0, atol=1e-12)
        assert [p and (p.first, p.second) for p in pa] == [p and (p.first, p.second) for p in pb]
    q = list(Q[0])
    assert listed.report(q).min_clearance == pytest.approx(spatial.report(q).min_clearance,
                                                           abs=1e-12)


@pytest.mark.parametrize("listed", [True, False], ids=["listed", "spatial"])
def test_capsule_pairs_measured_in_small_slices_give_the_same_bits(listed, monkeypatch):
    """Memory stays bounded however many capsule pairs come near: the engine measures them
    _PAIR_ENTRIES at a time (fuzz operations seed 401209 needed 613 MiB at once). Slices of
    7 pairs give the batch's and the report's answers bit for bit, pairs and words included."""
    design = load_design(DESIGNS[0].parent / "puma.json")
    Q = random_configurations(design, 40, seed=11)
    if not listed:
        monkeypatch.setattr(clearance_module, "_GROUP_PAIRS_LISTED", 0)
    whole = ClearanceEngine(design)
    assert whole._listed is listed
    expected = {m: whole.worst_arrays(Q, m) for m in (0.0, 0.3, 2.0)}
    reports = [whole.report(list(q), 0.3) for q in Q[:6]]
    monkeypatch.setattr(clearance_module, "_PAIR_ENTRIES", 7)
    sliced = ClearanceEngine(design)
    hits = 0
    for margin, found in expected.items():
        again = sliced.worst_arrays(Q, margin)
        for a, b in zip(found, again, strict=True):
            assert np.array_equal(a, b)
        hits += int(np.isfinite(found[0]).sum())
    assert hits > 10  # the margins make some configurations close
    if not listed:  # the general report measures through the same slices
        for q, report in zip(Q[:6], reports, strict=True):
            assert sliced.report(list(q), 0.3) == report


@pytest.mark.parametrize("listed", [True, False], ids=["listed", "spatial"])
def test_a_report_lists_at_most_the_closest_pairs_and_counts_the_rest(listed, monkeypatch):
    """A report lists the closest MAX_REPORTED_PAIRS pairs of parts and counts the others (a
    chain folded onto itself out of one-degree elbows had 631,583: 14 s to list): with the cap
    at 2, the pairs are the first two of the full list, and the count, the headline, the
    verdict and the summary's "... and N more" are the full report's."""
    from tests.cli.helpers import fold_back

    design = loads_design(json.dumps(fold_back(1.0)))
    if not listed:
        monkeypatch.setattr(clearance_module, "_GROUP_PAIRS_LISTED", 0)
    full = ClearanceEngine(design).report(current_states(design), 0.5)
    assert len(full.pairs) >= 4 and full.unlisted == 0
    monkeypatch.setattr(clearance_module, "MAX_REPORTED_PAIRS", 2)
    capped = ClearanceEngine(design).report(current_states(design), 0.5)
    assert capped.pairs == full.pairs[:2] and capped.closest == full.closest
    assert capped.unlisted == len(full.pairs) - 2 and capped.pair_count == len(full.pairs)
    assert capped.unlisted_overlapping == sum(p.clearance < 0 for p in full.pairs[2:])
    assert capped.headline("mm") == full.headline("mm")
    assert capped.verdict("mm") == full.verdict("mm")
    assert capped.summary("mm", listed=1) == full.summary("mm", listed=1)


def test_words_of_many_entries_are_each_entrys_own():
    """text_codes (the words of millions of pairs in a few array passes) gives every entry
    the words label gives it alone, including points on the breaks between pieces."""
    design = load_design(DESIGNS[0].parent / "puma.json")
    engine = ClearanceEngine(design)
    rng = np.random.default_rng(2)
    rows = rng.integers(0, engine._S, 3000)
    s = rng.random(3000)
    s[:200] = rng.choice([0.0, 1.0], 200)
    breaks = [(row, b / engine._lengths[row]) for row in range(engine._S)
              for b in engine._pieces[row][0].tolist()]  # fmt: skip
    for n, (row, at) in enumerate(breaks[:300]):
        rows[200 + n], s[200 + n] = row, at
    codes, texts = engine.text_codes(rows, s)
    assert len(set(texts)) == len(texts) > 3
    assert [texts[c] for c in codes.tolist()] == [engine.label(int(row), float(at))
                                                  for row, at in zip(rows, s, strict=True)]


def test_segment_distance_kernel_is_the_shared_one_bit_for_bit():
    """The engine's coordinate-array segment distances give the bits of
    kinegami.geometry.segments.segment_distances, degenerate pairs included."""
    rng = np.random.default_rng(0)
    n = 4000
    p = [rng.normal(size=(n, 3)) * rng.choice([1e-3, 1.0, 100.0], size=(n, 1)) for _ in range(4)]
    p[1][:500] = p[0][:500]  # a point
    p[3][500:1000] = p[2][500:1000] + 0.5 * (p[1][500:1000] - p[0][500:1000])  # parallel
    p[2][1000:1500] = p[0][1000:1500] + 0.3 * (p[1][1000:1500] - p[0][1000:1500])  # collinear
    p[3][1000:1500] = p[0][1000:1500] + 2.0 * (p[1][1000:1500] - p[0][1000:1500])
    p[2][1500:2000] = p[0][1500:2000]  # touching ends
    expected = segment_distances(*p)
    found = segment_distances_xyz(*[tuple(x[:, c] for c in range(3))
                                                      for x in p])
    for e, f in zip(expected, found, strict=True):
        assert np.array_equal(e, f)
    # a batch without points takes the kernel's unguarded branch: the same bits as in a batch
    # with points (the guarded branch), pair by pair
    proper = slice(500, n)
    alone = segment_distances(*(x[proper] for x in p))
    for e, f in zip(expected, alone, strict=True):
        assert np.array_equal(e[proper], f)
    # the plain-float kernel of one pair (the one-configuration report's few pairs)
    for k in range(0, n, 3):
        d, s, t = segment_distance(*(x[k].tolist() for x in p))
        assert (d, s, t) == (expected[0][k], expected[1][k], expected[2][k]), k
        assert np.signbit([s, t]).tolist() == np.signbit([expected[1][k],
                                                            expected[2][k]]).tolist()


@pytest.mark.parametrize("name", ["puma", "spherical_series", "hand", "quadruped"])
def test_one_configuration_report_is_the_batch_bit_for_bit(name):
    """The one-configuration report (bounds, then a few exact pairs) gives the bits of the
    batch: with a margin larger than the design every tested pair is closer than it, so the
    batch's deepest pair is the closest of all pairs, which the report names too; with margin
    0 the deepest overlap is the same number."""
    design = load_design(DESIGNS[0].parent / f"{name}.json")
    chain = isinstance(design, KinematicChain)
    Q = random_configurations(design, 30, seed=8)
    engine = ClearanceEngine(design) if chain else TreeMotion(design).engine
    huge = 1e3 * engine._extent()
    for margin in (0.0, huge):
        worst, pairs = engine.worst(Q, margin)
        for q, w, pair in zip(Q, worst, pairs, strict=True):
            report = engine.report(list(q), margin)
            if margin:
                assert report.min_clearance == w == report.closest.clearance
                assert (report.closest.first, report.closest.second) == (pair.first,
                                                                         pair.second)
                assert report.closest.points == pair.points
                assert report.pairs and len(report.pairs) == len(
                    {(p.first, p.second) for p in report.pairs})
            if np.isfinite(w):
                assert report.pairs[0].clearance == w
                assert report.min_clearance == w
            else:
                assert report.ok and not report.pairs


def test_sweep_of_a_tree_counts_as_one_configuration_reports():
    """A tree's sweep (batched) counts exactly the configurations whose report is not clear,
    and its deepest pair is the deepest of those reports."""
    design = load_design(DESIGNS[0].parent / "hand.json")
    Q = random_configurations(design, 40, seed=11)
    result = sweep(design, configurations=[list(q) for q in Q])
    reports = [design.clearance(list(q)) for q in Q]
    assert result.colliding == sum(not rep.ok for rep in reports) > 0
    deepest = min(rep.min_clearance for rep in reports)
    assert result.worst_pairs[0][0].clearance == pytest.approx(deepest, abs=TOLERANCE)
    assert sum(count for _, count in result.worst_pairs) <= result.colliding


def test_designs_with_no_capsules_are_clear():
    """A tree or a chain of one joint has no parts to test: clear, also over its motion (the
    engine's point layout is empty; it raised a ValueError)."""
    from kinegami import SE3, KinematicChain, KinematicTree, StartTip, Waypoint
    from kinegami.clearance import sweep

    for design in (KinematicTree(Waypoint(4, 1, SE3())), KinematicChain(StartTip(4, 1, SE3(), 1))):
        assert design.clearance().ok
        assert sweep(design, samples=5).colliding == 0


@pytest.mark.parametrize("name", ["puma", "spherical_limb", "algorithmic_hand", "quadruped"])
def test_free_intervals_test_only_the_pairs_a_joint_moves(name, monkeypatch):
    """The free-interval scans test, for each joint, only the pairs of parts that joint moves
    relative to each other (the others are as clear as at the current states) and that come
    near at some state of that joint: the intervals are those of scans that test every pair."""
    design = load_design(DESIGNS[0].parent / f"{name}.json")
    chain = isinstance(design, KinematicChain)
    motion = (clearance_module.ChainMotion(ClearanceEngine(design), 0.0) if chain
              else TreeMotion(design))  # fmt: skip
    engine = motion.engine
    states = np.array([joint.state for joint in design.Joints])
    fast = motion.free_intervals(states, 16)
    sizes = [int(np.count_nonzero(engine._affected(j)[1] <= 0.0))
             for j in engine.movable.tolist()]  # fmt: skip
    assert min(sizes) < engine._gp1.size  # some joint leaves pairs out
    monkeypatch.setattr(type(engine), "_affected", lambda self, joint: (
        np.arange(self._gp1.size), np.full(self._gp1.size, -np.inf)))
    every = motion.free_intervals(states, 16)
    assert fast == every
    assert any(interval is not None and interval[0] < interval[1] for interval in fast)


@pytest.mark.parametrize("path", DESIGNS, ids=lambda p: p.stem)
def test_group_pairs_left_out_never_come_near(path):
    """The batch leaves out the listed group pairs whose balls cannot come within the margin
    at any configuration: at random configurations every pair's ball gap is at least the
    bound it was left out by."""
    design = load_design(path)
    chain = isinstance(design, KinematicChain)
    engine = ClearanceEngine(design) if chain else TreeMotion(design).engine
    if not engine._listed or engine._gp1.size == 0:
        return
    bound = engine._closest_over_motion()
    Q = engine._configurations(random_configurations(design, 200, seed=13))
    centres = engine._centres.move(engine.body_transforms(Q))[:, :, engine._gcol]
    d = centres[:, :, engine._gp1] - centres[:, :, engine._gp2]
    gap = np.sqrt((d * d).sum(axis=0)) - engine._gradius[engine._gp1] \
        - engine._gradius[engine._gp2]  # fmt: skip
    scale = float(np.abs(engine._gcentre).max()) + float(engine._gradius.max())
    assert np.all(gap >= bound - 1e-9 * scale), path.stem
