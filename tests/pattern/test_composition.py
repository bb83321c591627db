"""Composition (section 2.2): append, concatenate, duplicate creases, markers, errors, speed."""

import math
import time

import numpy as np
import pytest
from numpy.testing import assert_allclose, assert_array_equal

from kinegami.errors import InvalidParameterError, InvalidTypeError
from kinegami.pattern import (
    ElbowFittingPattern,
    EndTipPattern,
    RevoluteJointPattern,
    StartTipPattern,
    TubeFittingPattern,
    TubularPattern,
    TwistFittingPattern,
    WaypointPattern,
)

from .helpers import crease_set
from .reference_values import (
    ATOL,
    COMPOSITE,
    COMPOSITE_SPEC,
    MERGED_RING_LABEL,
    REVOLUTE_TWIST_MERGED_E,
    REVOLUTE_TWIST_MERGED_RINGS,
)

BUILDERS = {
    "tube": TubeFittingPattern,
    "twist": TwistFittingPattern,
    "elbow": ElbowFittingPattern,
    "revolute": RevoluteJointPattern,
}


def _modules(n, spec=COMPOSITE_SPEC):
    return [BUILDERS[kind](n, 1.0, *args) for kind, *args in spec]


def _chain(n, count, seed=0):
    rng = np.random.default_rng(seed)
    mods = [StartTipPattern(n, 1.0, 0.5)]
    while len(mods) < count - 1:
        mods += [
            ElbowFittingPattern(n, 1.0, rng.uniform(0.1, 1.5), rng.uniform(0, 2 * math.pi)),
            TwistFittingPattern(n, 1.0, rng.uniform(-3, 3), 0.3),
            TubeFittingPattern(n, 1.0, rng.uniform(0.0, 2.0)),
            RevoluteJointPattern(n, 1.0, math.pi, numSinkLayers=int(rng.integers(1, 3))),
            WaypointPattern(n, 1.0),
        ]
    return mods[: count - 1] + [EndTipPattern(n, 1.0, 0.5)]


def _append_all(mods):
    out = mods[0]
    for m in mods[1:]:
        out = out.append(m)
    return out


@pytest.mark.parametrize("n", sorted(COMPOSITE))
def test_composite_reference_values(n):
    ref = COMPOSITE[n]
    p = _append_all(_modules(n))
    assert (p.numVertices, p.numEdges, p.numMountains) == (ref["V"], ref["E"], ref["M"])
    assert_allclose(p.height, ref["height"], atol=ATOL)
    assert_allclose(p.distalMarker[0], ref["marker_x"], atol=ATOL)
    assert p.validate().ok


def test_composite_counts_add_up():
    mods = _modules(6)
    p = _append_all(mods)
    assert p.numVertices == 6 + sum(m.numVertices - 6 for m in mods)
    assert p.numEdges == sum(m.numEdges for m in mods) - p.removedDuplicates


@pytest.mark.parametrize("n", [4, 6, 8])
def test_concatenate_equals_repeated_append(n):
    mods = _chain(n, 60, seed=n)
    a, c = _append_all(mods), TubularPattern.concatenate(mods)
    assert_array_equal(a.vertices_coords, c.vertices_coords)
    assert_array_equal(a.edges_vertices, c.edges_vertices)
    assert_array_equal(a.edges_assignment, c.edges_assignment)
    assert_array_equal(a.proximalBase if a.proximalBase is not None else [], [])
    assert (a.distalBase, c.distalBase) == (None, None)
    assert_allclose([a.height, *a.distalMarker], [c.height, *c.distalMarker])
    assert a.modules == c.modules and a.removedDuplicates == c.removedDuplicates


def test_concatenate_is_associative_with_append():
    mods = _modules(6)
    left = TubularPattern.concatenate(mods[:3]).append(TubularPattern.concatenate(mods[3:]))
    whole = TubularPattern.concatenate(mods)
    assert crease_set(left) == crease_set(whole)
    assert left.numVertices == whole.numVertices


def test_concatenate_of_one_pattern_is_itself():
    p = TubeFittingPattern(6, 1.0, 1.0)
    assert TubularPattern.concatenate([p]) is p


def test_long_chain_is_valid():
    assert TubularPattern.concatenate(_chain(6, 80, seed=3)).validate().ok


def test_append_does_not_modify_operands():
    a, b = TubeFittingPattern(6, 1.0, 1.0), TwistFittingPattern(6, 1.0, 0.5, 0.5)
    before = (a.vertices_coords.copy(), b.vertices_coords.copy(), a.numEdges, b.numEdges)
    a.append(b)
    assert_array_equal(a.vertices_coords, before[0])
    assert_array_equal(b.vertices_coords, before[1])
    assert (a.numEdges, b.numEdges) == before[2:]


def test_next_module_base_lands_on_previous_distal_base():
    """Section 7.1 item 9: B's proximal base coincides with A's distal base, cyclically."""
    a = TubeFittingPattern(6, 1.0, 1.0).append(TwistFittingPattern(6, 1.0, 2.2, 0.4))
    b = ElbowFittingPattern(6, 1.0, 1.0, 0.3)
    p = a.append(b)
    shared = set(a.distalBase.tolist())
    new_edges = p.edges_vertices[a.numEdges :]
    used = set(new_edges.ravel().tolist()) & set(range(a.numVertices))
    assert used == shared


def test_module_offset_is_sum_of_twist_shifts():
    n = 6
    twists = [TwistFittingPattern(n, 1.0, alpha, 0.2) for alpha in (0.3, 1.9, -0.7)]
    p = TubularPattern.concatenate([TubeFittingPattern(n, 1.0, 1.0), *twists])
    W = p.width
    assert_allclose(p.distalMarker[0], sum(t.distalMarker[0] for t in twists) % W, atol=1e-9)


def test_duplicate_ring_keeps_earlier_label():
    r = RevoluteJointPattern(6, 1.0, math.pi)
    t = TwistFittingPattern(6, 1.0, 0.5, 0.5)
    for first, second, key in ((r, t, "revolute_first"), (t, r, "twist_first")):
        p = first.append(second)
        assert p.numEdges == REVOLUTE_TWIST_MERGED_E
        assert p.removedDuplicates == REVOLUTE_TWIST_MERGED_RINGS
        base = set(first.distalBase.tolist())
        ring = [i for i, (u, v) in enumerate(p.edges_vertices.tolist()) if u in base and v in base]
        assert len(ring) == 6 and set(p.edges_assignment[ring]) == {MERGED_RING_LABEL[key]}


def test_waypoint_append_changes_nothing():
    a = TubeFittingPattern(6, 1.0, 1.0).append(TwistFittingPattern(6, 1.0, 0.5, 0.5))
    assert a.append(WaypointPattern(6, 1.0)) is a


def test_zero_height_tube_adds_nothing():
    """Fix B6: a tube of height 0 (a link with t = 0) adds no vertices and no creases."""
    a = ElbowFittingPattern(6, 1.0, 1.0, 0.0)
    p = a.append(TubeFittingPattern(6, 1.0, 0.0)).append(ElbowFittingPattern(6, 1.0, 0.5, 1.0))
    q = a.append(ElbowFittingPattern(6, 1.0, 0.5, 1.0))
    assert (p.numVertices, p.numEdges) == (q.numVertices, q.numEdges)
    assert p.validate().ok


def test_relabelling_twist_carries_its_marker_shift():
    n = 6
    shift = TwistFittingPattern(n, 1.0, 2 * 2 * math.pi / n, 0.0)
    p = TubeFittingPattern(n, 1.0, 1.0).append(shift).append(TubeFittingPattern(n, 1.0, 1.0))
    assert_allclose(p.distalMarker, [2.0, 2.0], atol=1e-9)
    assert p.numVertices == 3 * n and p.validate().ok


def test_start_tip_then_end_tip():
    p = StartTipPattern(6, 1.0, 0.5).append(EndTipPattern(6, 1.0, 0.5))
    assert p.proximalBase is None and p.distalBase is None
    assert p.numVertices == 2 * 20 - 6 and p.validate().ok


def test_append_after_end_tip_is_rejected():
    with pytest.raises(InvalidParameterError, match="end tip"):
        EndTipPattern(6, 1.0, 0.5).append(TubeFittingPattern(6, 1.0, 1.0))


def test_append_start_tip_is_rejected():
    with pytest.raises(InvalidParameterError, match="start tip"):
        TubeFittingPattern(6, 1.0, 1.0).append(StartTipPattern(6, 1.0, 0.5))


def test_append_different_num_sides_is_rejected():
    with pytest.raises(InvalidParameterError, match="numSides=4 .* numSides=6"):
        TubeFittingPattern(6, 1.0, 1.0).append(TubeFittingPattern(4, 1.0, 1.0))


def test_append_different_radius_is_rejected():
    with pytest.raises(InvalidParameterError, match="r=2.0 .* r=1.0"):
        TubeFittingPattern(6, 1.0, 1.0).append(TubeFittingPattern(6, 2.0, 1.0))


def test_append_non_pattern_is_rejected():
    with pytest.raises(InvalidTypeError):
        TubeFittingPattern(6, 1.0, 1.0).append("tube")


def test_concatenate_rejects_empty_list_and_bad_order():
    with pytest.raises(InvalidParameterError, match="at least one"):
        TubularPattern.concatenate([])
    tube = TubeFittingPattern(6, 1.0, 1.0)
    with pytest.raises(InvalidParameterError, match="end tip"):
        TubularPattern.concatenate([tube, EndTipPattern(6, 1.0, 0.5), tube])


def test_append_with_mismatched_bases_is_rejected():
    a = TubeFittingPattern(6, 1.0, 1.0)
    b = TubeFittingPattern(6, 1.0, 1.0)
    bad = TubularPattern(6, 1.0, b.vertices_coords, b.edges_vertices, b.edges_assignment,
                         b.proximalBase, b.distalBase, (0.25, 0.0), (0.0, 1.0), 1.0)  # fmt: skip
    with pytest.raises(InvalidParameterError, match="cyclic shift"):
        a.append(bad)


def test_composing_150_modules_is_fast():
    """Requirement: a ~150-module chain composes in well under 20 ms (best of 5 runs)."""
    mods = _chain(4, 150)
    TubularPattern.concatenate(mods)
    best = math.inf
    for _ in range(5):
        start = time.perf_counter()
        TubularPattern.concatenate(mods)
        best = min(best, time.perf_counter() - start)
    assert best < 0.020
