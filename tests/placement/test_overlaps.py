"""Placement's yes/no test of a candidate (kinegami.chain.bodies.overlaps) gives the answer of
the deepest-pair test (worst_overlap is not None) while measuring less: on random chains,
whole or from a joint on, with margins; and on a candidate that passes through the chain it
stops after its first chunk of pairs."""

from __future__ import annotations

import math
import warnings

from hypothesis import given, settings
from hypothesis import strategies as st
from spatialmath import SE3

import kinegami.chain.bodies as bodies
from kinegami import KinematicChain, RevoluteJoint, StartTip


def chain_of(turns, elbow) -> KinematicChain:
    chain = KinematicChain(StartTip(4, 1.0, SE3(), 1.0), maxAnglePerElbow=elbow)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        for k, (a, b, x) in enumerate(turns):
            pose = SE3.Trans(x, 2.0 * math.sin(a + k), 3.0 * k) * SE3.Rx(a) * SE3.Ry(b)
            chain.append(RevoluteJoint(4, 1.0, math.pi, pose), relative=False, safe=False)
    return chain


@settings(max_examples=60, deadline=None)
@given(turns=st.lists(st.tuples(st.floats(-3, 3), st.floats(-3, 3), st.floats(-4, 4)),
                      min_size=1, max_size=6),
       elbow=st.sampled_from([math.pi / 2, math.pi / 12]),
       margin=st.sampled_from([0.0, 0.3, 2.0]))  # fmt: skip
def test_overlaps_is_the_deepest_pair_test(turns, elbow, margin):
    chain = chain_of(turns, elbow)
    joints, links = chain.Joints, chain.Links
    for since in range(0, len(joints)):
        expected = bodies.worst_overlap(joints, links, 1.0, since=since, margin=margin)
        assert bodies.overlaps(joints, links, 1.0, since=since, margin=margin) == (
            expected is not None)


def test_a_colliding_candidate_stops_at_its_first_chunk(monkeypatch):
    """A straight tube laid back through a chain of small elbows: many overlapping pairs,
    one chunk measured."""
    chain = KinematicChain(StartTip(4, 1.0, SE3(), 1.0), maxAnglePerElbow=math.pi / 180)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        fixed = {"relative": False, "safe": False, "fixedPosition": True,
                 "fixedOrientation": True}  # fmt: skip
        chain.append(RevoluteJoint(4, 1.0, math.pi, SE3.Trans(0, 0, 30)), **fixed)
        chain.append(RevoluteJoint(4, 1.0, math.pi, SE3.Trans(0, 0.5, 2) * SE3.Rx(math.pi)),
                     **fixed)  # fmt: skip
    joints, links = chain.Joints, chain.Links
    assert bodies.worst_overlap(joints, links, 1.0, since=2) is not None
    measured = []
    distances = bodies.segment_distances

    def counted(a1, b1, a2, b2):
        measured.append(len(a1))
        return distances(a1, b1, a2, b2)

    monkeypatch.setattr(bodies, "segment_distances", counted)
    monkeypatch.setattr(bodies, "_OVERLAP_CHUNK", 64)
    assert bodies.overlaps(joints, links, 1.0, since=2)
    assert len(measured) == 1 and measured[0] <= 64
    first = measured[0]
    measured.clear()
    bodies.worst_overlap(joints, links, 1.0, since=2)
    assert sum(measured) > first  # the deepest pair measures every candidate pair
