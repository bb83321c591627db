"""TubularPattern.validate(): a report of every problem, and no false alarms on the catalog."""

import math

import numpy as np
import pytest

from kinegami.pattern import (
    ModuleRecord,
    RevoluteJointPattern,
    TubeFittingPattern,
    TubularPattern,
    ValidationReport,
)

from .helpers import find_vertex, prism_numbers


def _with(p, extra_vertices=(), extra_edges=(), extra_labels=None, **overrides):
    """A copy of ``p`` with vertices / creases added (indices may refer to new vertices)."""
    v = np.concatenate([p.vertices_coords, np.reshape(extra_vertices, (-1, 2))])
    e = np.concatenate([p.edges_vertices, np.reshape(extra_edges, (-1, 2)).astype(int)])
    labels = extra_labels or ["M"] * (len(e) - p.numEdges)
    kwargs = dict(
        numSides=p.numSides, r=p.r, vertices_coords=v, edges_vertices=e,
        edges_assignment=np.concatenate([p.edges_assignment, labels]),
        proximalBase=p.proximalBase, distalBase=p.distalBase, proximalMarker=p.proximalMarker,
        distalMarker=p.distalMarker, height=p.height, modules=p.modules,
    )  # fmt: skip
    kwargs.update(overrides)
    return TubularPattern(**kwargs)


def _tube():
    return TubeFittingPattern(6, 1.0, 2.0)


def _problems(p):
    report = p.validate()
    assert isinstance(report, ValidationReport)
    return report.problems


def test_valid_pattern_has_empty_report():
    report = _tube().validate()
    assert report.ok and report.problems == () and str(report) == "pattern OK"


def test_duplicate_vertex_is_reported():
    problems = _problems(_with(_tube(), extra_vertices=[[0.5, 0.0]], modules=()))
    assert any("duplicates" in p for p in problems)


def test_duplicate_vertex_across_the_seam_is_reported():
    p = _with(_tube(), extra_vertices=[[1e-5, 1.0], [6.0 - 1e-5, 1.0]], modules=())
    assert any("duplicates" in q for q in _problems(p))


def test_zero_length_crease_is_reported():
    problems = _problems(_with(_tube(), extra_edges=[[0, 0]], modules=()))
    assert any("zero-length" in p for p in problems)


def test_duplicate_crease_is_reported_in_either_order():
    problems = _problems(_with(_tube(), extra_edges=[[6, 0]], modules=()))
    assert any("duplicate creases" in p for p in problems)


def test_overlapping_collinear_creases_are_reported():
    # a vertex half way up tube edge 0, with creases along the edge to both ends
    p = _with(_tube(), extra_vertices=[[0.5, 1.0]], extra_edges=[[0, 12], [12, 6]], modules=())
    assert any("collinear overlapping" in q for q in _problems(p))


def test_vertex_inside_a_crease_is_reported():
    p = _with(_tube(), extra_vertices=[[0.5, 1.0], [0.9, 1.0]], extra_edges=[[12, 13]],
              modules=())  # fmt: skip
    assert any("inside a crease" in q for q in _problems(p))


def test_crease_wider_than_a_panel_is_reported():
    problems = _problems(_with(_tube(), extra_edges=[[0, 8]], modules=()))
    assert any("wider than one panel" in p for p in problems)


def test_wrapping_crease_within_a_panel_is_fine():
    # P_5 (x = 5.5) to P_0 (x = 0.5) crosses the seam with |dx| = b
    assert _with(_tube(), extra_edges=[[5, 0]], modules=()).validate().ok


def test_vertex_outside_the_strip_is_reported():
    p = _with(_tube(), extra_vertices=[[6.2, 1.0], [6.7, 1.0]], extra_edges=[[12, 13]],
              modules=())  # fmt: skip
    assert any("x outside [0, W" in q for q in _problems(p))


def test_vertex_above_the_height_is_reported():
    p = _with(_tube(), extra_vertices=[[1.0, 3.0], [1.2, 3.0]], extra_edges=[[12, 13]],
              modules=())  # fmt: skip
    assert any("y outside" in q for q in _problems(p))


def test_misplaced_distal_marker_is_reported():
    p = _with(_tube(), distalMarker=(0.3, 2.0))
    assert any("distal base" in q for q in _problems(p))


def test_misplaced_proximal_base_is_reported():
    t = _tube()
    p = _with(t, proximalBase=np.roll(t.proximalBase, 1))
    assert any("proximal base" in q for q in _problems(p))


def test_counts_differing_from_the_formula_are_reported():
    problems = _problems(_with(_tube(), extra_vertices=[[1.0, 1.0], [1.2, 1.3]],
                               extra_edges=[[12, 13]]))  # fmt: skip
    assert any("formula gives 12" in p for p in problems)
    assert any("formula gives 6" in p for p in problems)


def test_count_check_uses_module_records():
    p = _with(
        _tube(),
        modules=(ModuleRecord("tube", {"height": 1.0}),) * 2,
    )
    assert any("composite of 2 modules" in q for q in _problems(p))


def test_every_problem_is_listed_at_once():
    p = _with(_tube(), extra_vertices=[[0.5, 0.0]], extra_edges=[[0, 0], [6, 0], [0, 8]])
    problems = _problems(p)
    for word in ("duplicates", "zero-length", "duplicate creases", "wider than one panel",
                 "formula"):  # fmt: skip
        assert any(word in q for q in problems), word
    assert str(p.validate()).startswith(f"{len(problems)} problem(s)")


def test_reference_sink_quirk_b2_is_detected():
    """Adding back the four half-midlines the reference keeps for N >= 2 makes overlaps."""
    n = 6
    p = RevoluteJointPattern(n, 1.0, math.pi, numSinkLayers=2)
    b, a, _ = prism_numbers(n, 1.0)
    H = math.hypot(a, a * math.tan(math.pi / 4))
    M = lambda k: find_vertex(p, ((k + 0.5) * b, H))  # noqa: E731
    C = lambda k: find_vertex(p, (((k + 1) * b) % p.width, H))  # noqa: E731
    mp, ep = n // 2 - 1, n - 1
    extra = [[M(0), C(0)], [C(mp - 1), M(mp)], [M(mp + 1), C(mp + 1)], [C(ep - 1), M(ep)]]
    assert any("collinear overlapping" in q for q in _problems(_with(p, extra_edges=extra)))


@pytest.mark.parametrize("n", [4, 6, 8])
def test_reference_zero_length_elbow_b6_is_detected(n):
    """The reference keeps L_k apart from P_k at h_k = 0, joined by a zero-length crease."""
    p = TubeFittingPattern(n, 1.0, 1.0)
    q = _with(p, extra_vertices=[p.vertices_coords[0]], extra_edges=[[0, 2 * n]], modules=())
    problems = _problems(q)
    assert any("zero-length" in x for x in problems) and any("duplicates" in x for x in problems)
