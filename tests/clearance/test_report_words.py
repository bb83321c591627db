"""The reports' own words (kinegami.clearance.reports): the headline of each kind of verdict,
how many pairs a summary lists, a pair's separation, the editor's Markdown, a sweep's lines and
which joints move. What the command line prints with them: tests/cli/test_report_words.py."""

from __future__ import annotations

import math

import numpy as np
import pytest

from kinegami import EndTip, KinematicChain, PrismaticJoint, RevoluteJoint, StartTip
from kinegami.clearance import ClearanceReport, CollidingPair, Lengths, SweepReport, sweep
from kinegami.clearance.reports import moving_joints

POINTS = ((0.0, 0.0, 0.0), (1.0, 0.0, 0.0))


def _pair(first: str, clearance: float) -> CollidingPair:
    return CollidingPair(first, "link 5, twist", clearance, POINTS)


def _report(*clearances: float, margin: float = 0.0) -> ClearanceReport:
    """A report in cm with r = 1 whose pairs closer than the margin have ``clearances``."""
    pairs = tuple(_pair(f"link {i}, straight tube", c) for i, c in enumerate(clearances))
    closest = pairs[0] if pairs else _pair("joint 0, StartTip", 3.0)
    return ClearanceReport(ok=not pairs, min_clearance=closest.clearance, pairs=pairs,
                           closest=closest, states=(0.0,), margin=margin, r=1.0)  # fmt: skip


@pytest.mark.parametrize(
    "clearances, margin, headline",
    [
        ((), 0.0, "clear at its states"),
        ((-0.5,), 0.0, "self-intersects at its states (1 pair of parts overlap)"),
        ((-0.5, -0.25), 0.0, "self-intersects at its states (2 pairs of parts overlap)"),
        ((0.1, 0.2), 0.5, "not clear at its states (2 pairs of parts closer than the margin "
                          "5 mm (0.5 cm))"),
        ((-0.1, 0.2), 0.5, "self-intersects at its states (2 pairs of parts closer than the "
                           "margin 5 mm (0.5 cm))"),
    ],  # fmt: skip
)
def test_headline(clearances, margin, headline):
    assert _report(*clearances, margin=margin).headline("cm") == headline


def test_summary_lists_at_most_listed_pairs_and_how_many_more():
    report = _report(-0.5, -0.25, -0.12)
    verdict = f"  clearance: {report.verdict('cm')}"
    assert report.summary("cm", title="Arm (arm.json)") == [
        "Arm (arm.json): self-intersects at its states (3 pairs of parts overlap)",
        verdict,
        "  parts closer than the margin (closest first):",
        "    link 0, straight tube and link 5, twist: overlap 5.0 mm (0.50 cm)",
        "    link 1, straight tube and link 5, twist: overlap 2.5 mm (0.25 cm)",
        "    link 2, straight tube and link 5, twist: overlap 1.2 mm (0.12 cm)",
    ]
    assert report.summary("cm", listed=2)[1:] == [
        "  parts closer than the margin (closest first):",
        "    link 0, straight tube and link 5, twist: overlap 5.0 mm (0.50 cm)",
        "    link 1, straight tube and link 5, twist: overlap 2.5 mm (0.25 cm)",
        "    ... and 1 more",
    ]
    assert report.summary("cm", listed=0) == [verdict]  # build's and compact's line
    assert report.summary("cm", listed=3) == report.summary("cm")  # no "... and 0 more"


def test_summary_of_a_clear_report_is_its_verdict():
    report = _report()
    assert report.summary("cm", title="t") == ["t: clear at its states",
                                                f"  clearance: {report.verdict('cm')}"]  # fmt: skip
    assert report.summary(listed=None) == [f"  clearance: {report.verdict()}"]


def test_separation():
    length = Lengths(1.0, "cm")
    assert _pair("a", -0.07).separation(length) == "overlap 0.7 mm (0.07 cm)"
    assert _pair("a", 0.22).separation(length) == "2.2 mm (0.22 cm) apart"
    assert _pair("a", 0.22).separation(Lengths(1.0)) == "0.22 apart"  # chain units


def test_markdown_is_the_verdict_then_the_first_pairs():
    assert _report().markdown("cm") == _report().verdict("cm")  # clear: no bold, no list
    report = _report(-0.5, -0.25, -0.12)
    assert report.markdown("cm", listed=2).splitlines() == [
        f"**{report.verdict('cm')}**",
        "",
        "- link 0, straight tube and link 5, twist overlap by 0.5",
        "- link 1, straight tube and link 5, twist overlap by 0.25",
    ]
    assert len(report.markdown("cm").splitlines()) == 2 + 3


@pytest.fixture(scope="module")
def arm() -> KinematicChain:
    """A start tip, a revolute joint, a prismatic joint and an end tip, r = 1."""
    chain = KinematicChain(StartTip(4, 1, Pose=np.eye(4), length=1.5))
    T = np.eye(4)
    T[:3, 3] = (0.0, 0.0, 6.0)
    chain.append(RevoluteJoint(4, 1, math.pi, T))
    T[:3, 3] = (0.0, 0.0, 14.0)
    chain.append(PrismaticJoint(4, 1, 3, 3, math.pi / 4, T))
    T[:3, 3] = (0.0, 0.0, 22.0)
    chain.append(EndTip(4, 1, T, 1.5))
    return chain


def test_moving_joints(arm):
    moving = moving_joints(arm.Joints)
    assert moving == [i for i, j in enumerate(arm.Joints) if type(j).__name__ in
                      ("RevoluteJoint", "PrismaticJoint")]  # fmt: skip
    assert len(moving) == 2


def test_sweep_summary_words_each_moving_joint(arm):
    report = sweep(arm, 50, 4)
    names = [None] * len(arm.Joints)
    revolute, prismatic = moving_joints(arm.Joints)
    names[revolute] = "elbow"
    lines = report.summary(arm, "cm", names=names, seed=4)
    share = f"{100.0 * report.colliding_fraction:.1f}%"
    assert lines[0] == (f"  motion: {report.colliding} of 50 sampled configurations "
                        f"self-intersect ({share}; seed 4)")  # fmt: skip
    joints = lines[lines.index("  free intervals (each joint moved alone from its state, the "
                               "others kept):") + 1 :]  # fmt: skip
    assert joints[0].startswith(f"    joint {revolute}, RevoluteJoint 'elbow': ")
    assert joints[0].endswith(" deg, its whole range") or " deg, of its range " in joints[0]
    assert joints[1].startswith(f"    joint {prismatic}, PrismaticJoint: ")
    assert " mm (" in joints[1] and " cm)" in joints[1]
    assert len(joints) == 2


def test_sweep_words_without_free_intervals(arm):
    stuck = SweepReport(10, 10, (), (None,) * len(arm.Joints))
    assert stuck.summary(arm)[-1] == ("  free intervals: none (the design self-intersects at its "
                                      "states)")  # fmt: skip
    assert stuck.markdown(arm).splitlines()[-1] == ("Free intervals: none (the design "
                                                    "self-intersects at its states).")  # fmt: skip
    still = KinematicChain(StartTip(4, 1, Pose=np.eye(4), length=1.5))
    assert SweepReport(10, 0, (), (None,)).summary(still) == [
        "  motion: 0 of 10 sampled configurations self-intersect (0.0%; seed 0)",
        "  free intervals: none (no joint moves)",
    ]
    assert SweepReport(10, 0, (), (None,)).markdown(still) == (
        "**Motion check:** 0 of 10 random configurations self-intersect (0.0%, seed 0)"
    )


def test_sweep_markdown_lists_the_first_pairs_and_joints(arm):
    revolute, prismatic = moving_joints(arm.Joints)
    free = [None] * len(arm.Joints)
    free[revolute] = (-math.pi / 4, math.pi / 2)
    free[prismatic] = tuple(float(v) for v in arm.Joints[prismatic].stateRange())
    worst = ((_pair("a", -0.5), 3), (_pair("b", -0.25), 1))
    report = SweepReport(20, 4, worst, tuple(free))
    names = ["base"] + [""] * (len(arm.Joints) - 1)  # an empty name: the joint's kind
    assert report.markdown(arm, names=names, seed=7, listed=1).splitlines() == [
        "**Motion check:** 4 of 20 random configurations self-intersect (20.0%, seed 7)",
        "",
        "Deepest overlaps over the motion:",
        "",
        "- a and link 5, twist: up to 0.5 (3 configurations)",
        "",
        "Free interval of each joint moved alone from its state:",
        "",
        f"- {revolute} RevoluteJoint: [-45.0 deg, 90.0 deg]",
        f"- {prismatic} PrismaticJoint: [{free[prismatic][0]:.3g}, {free[prismatic][1]:.3g}] "
        "(its whole range)",
    ]
    last = report.markdown(arm, joints_listed=1).splitlines()
    assert last[-2:] == [f"- {revolute} RevoluteJoint: [-45.0 deg, 90.0 deg]",
                         "- ... and 1 more joints"]  # fmt: skip
    assert "- b and link 5, twist: up to 0.25 (1 configuration)" in report.markdown(arm)
