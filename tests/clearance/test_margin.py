"""The margin: the clearance a design requires between its parts (docs/clearance.md).

Margin 0 (the default) keeps every verdict and number as it was before the margin existed; a
margin makes parts closer than it a failure everywhere (reports, sweeps, placement under
requireClearance, compaction), and every verdict states the margin it used.
"""

from __future__ import annotations

import concurrent.futures
import math
import warnings
from pathlib import Path

import numpy as np
import pytest

from kinegami import KinematicChain, RevoluteJoint, StartTip, Waypoint
from kinegami.clearance import ClearanceReport, clearance_report, sweep
from kinegami.design import load_design
from kinegami.errors import ClearanceWarning, InvalidParameterError, InvalidTypeError
from kinegami.optimize import compact, tube_length

from .helpers import FIXED, frame, through, tip_pose
from .test_compact import random_safe_chain

DESIGNS = Path(__file__).resolve().parents[2] / "examples" / "designs"
PAPERS_HAND = Path(__file__).resolve().parents[1] / "design" / "data" / "papers_hand.json"

#: Every gallery design's verdict at its states before the margin existed (commit 4952e4a):
#: ok, min_clearance (float.hex; inf: nothing tested), number of overlapping pairs. hand.json
#: now has the palm's fitting slide written in: its number is that of the tree build made then
#: (fit_junctions of the paper's hand); the paper's hand as published is PAPERS_HAND.
BEFORE = {
    "algorithmic_hand.json": (True, "0x1.c2e8e3bc78400p-9", 0),
    "cylindrical_joint.json": (True, "inf", 0),
    "doubling_back.json": (True, "0x1.4000000000000p+5", 0),
    "example1.json": (True, "0x1.f87cee29233acp-1", 0),
    "gripper.json": (True, "0x1.6021c27040c00p-3", 0),
    "hand.json": (True, "0x1.c6daff280b400p-9", 0),
    "planar_joint.json": (True, "inf", 0),
    "prismatic_spiral.json": (True, "0x1.1b0ec5a85eb41p+7", 0),
    "puma.json": (True, "0x1.1c946ff60bea0p+1", 0),
    "quadruped.json": (True, "0x1.8f68386aca000p-5", 0),
    "revolute_spiral.json": (True, "0x1.f3f2c1a760f98p+3", 0),
    "spherical_joint.json": (True, "0x1.b5b3458d6a444p+4", 0),
    "spherical_limb.json": (True, "0x1.b5b3458d6a444p+4", 0),
    "spherical_series.json": (True, "0x1.e0160e58fe034p+3", 0),
}
#: The paper's hand as published, before and now: the palm 0.25 r into the pointer's tube.
PAPERS_HAND_BEFORE = (False, "-0x1.0000000000000p-2", 1)
#: sweep(example1, 300, seed 0) before the margin existed: colliding count and free intervals.
EXAMPLE1_SWEEP = (26, {2: ("-0x1.c1e24cc824c98p-1", "0x1.3e1db337db368p+0"),
                       4: ("-0x1.696b291d3f2aep+0", "0x1.696b291d3f2aep+0")})  # fmt: skip


def _load(path: Path):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ClearanceWarning)
        return load_design(path)


def _numbers(report: ClearanceReport) -> tuple:
    value = report.min_clearance
    return (report.ok, "inf" if math.isinf(value) else value.hex(), len(report.pairs))


def _same_numbers(now: tuple, before: tuple) -> bool:
    """The same verdict and pair count, and the same smallest clearance up to the last bits
    that numpy's vector kernels round differently on another processor (1e-12 relative: the
    algorithmic hand's tree distances differ in their last 12 bits between two machines)."""
    if now[0] != before[0] or now[2] != before[2] or ("inf" in (now[1], before[1])):
        return now == before
    a, b = float.fromhex(now[1]), float.fromhex(before[1])
    return abs(a - b) <= 1e-12 * max(abs(a), abs(b))


def serial():
    return concurrent.futures.ThreadPoolExecutor(max_workers=1)


# --- margin 0 changes nothing ------------------------------------------------------------------
#: Gallery designs added after the margin existed (nothing to compare them with).
ADDED_LATER = {"pick_and_place.json"}


def test_every_gallery_design_is_judged_as_before_at_margin_0():
    assert sorted(p.name for p in DESIGNS.glob("*.json")) == sorted({*BEFORE, *ADDED_LATER})
    for name, before in BEFORE.items():
        chain = _load(DESIGNS / name)
        assert chain.margin == 0.0
        report = chain.clearance()
        assert _same_numbers(_numbers(report), before), name
        assert report.margin == 0.0
        assert _same_numbers(_numbers(chain.clearance(margin=0)), before), name
    assert _numbers(_load(PAPERS_HAND).clearance()) == PAPERS_HAND_BEFORE


def test_a_sweep_at_margin_0_is_as_before():
    chain = _load(DESIGNS / "example1.json")
    colliding, intervals = EXAMPLE1_SWEEP
    for result in (sweep(chain, 300, 0, progress=False),
                   sweep(chain, 300, 0, progress=False, margin=0.0)):  # fmt: skip
        assert result.colliding == colliding and result.margin == 0.0
        for j, (low, high) in intervals.items():
            assert tuple(v.hex() for v in result.free_intervals[j]) == (low, high)


# --- a margin ----------------------------------------------------------------------------------
def test_a_margin_larger_than_the_clearance_fails_and_names_the_pairs():
    chain = _load(DESIGNS / "example1.json")  # min clearance 0.985 cm
    clear = chain.clearance(margin=0.5)
    assert clear.ok and clear.margin == 0.5 and clear.pairs == ()
    assert clear.min_clearance == chain.clearance().min_clearance  # the number is the geometry's
    tight = chain.clearance(margin=1.0)
    assert not tight.ok and tight.margin == 1.0
    assert tight.min_clearance == clear.min_clearance
    assert tight.pairs and all(0.0 <= p.clearance < 1.0 for p in tight.pairs)
    assert tight.pairs[0].clearance == tight.min_clearance
    # the chain's own margin is the default
    chain.margin = 1.0
    assert _numbers(chain.clearance()) == _numbers(tight)
    assert clearance_report(chain).ok is False


def test_every_verdict_states_its_margin():
    chain = _load(DESIGNS / "example1.json")
    assert chain.clearance().verdict("cm") == (
        "clear with margin 0 mm (0 cm): minimum clearance 9.9 mm (0.99 cm), between link 4, "
        "first elbow and link 4, fourth elbow"
    )
    assert chain.clearance(margin=0.02).verdict("cm").startswith(
        "clear with margin 0.2 mm (0.02 cm): minimum clearance 9.9 mm (0.99 cm)"
    )
    assert chain.clearance(margin=1.5).verdict("cm").startswith(
        "parts closer than the margin 15 mm (1.5 cm): minimum clearance 9.9 mm (0.99 cm), between"
    )
    assert str(chain.clearance(margin=1.5)).startswith("parts closer than the margin 1.5: ")
    colliding = through([((0, 0, 0), (1, 0, 0)), ((10, 0, 0), (1, 0, 0)),
                         ((10, 0, 4), (-1, 0, 0)), ((4, 0, 0), (-1, 0, 0))],
                        end=((2, 0, 0), (-1, 0, 0)))  # the end tip inside the way out
    words = colliding.clearance().verdict("mm")
    assert words.startswith("self-intersects, parts closer than the margin 0 mm: minimum "
                            "clearance -")  # fmt: skip
    nothing = KinematicChain(StartTip(4, 1.0, np.eye(4), 1.0))
    assert nothing.clearance(margin=0.1).verdict() == (
        "clear with margin 0.1: no two parts are far enough apart along the tube to collide"
    )


def test_a_sweep_with_a_margin_counts_more_configurations_as_colliding():
    chain = _load(DESIGNS / "example1.json")
    counts = [sweep(chain, 300, 0, progress=False, margin=m).colliding for m in (0.0, 0.5, 1.5)]
    assert counts[0] <= counts[1] <= counts[2]
    assert counts[2] == 300  # 1.5 cm is more than the chain's clearance anywhere
    tree = _load(DESIGNS / "gripper.json")  # trees: configuration by configuration
    assert sweep(tree, 4, 0, progress=False, margin=0.0).colliding <= sweep(
        tree, 4, 0, progress=False, margin=50.0
    ).colliding == 4  # fmt: skip


def test_a_trees_junction_covers_its_tubes_until_they_are_the_margin_apart():
    """The tubes leaving one junction touch where it ends (clearance about 0): with a margin
    the junction covers them until they are the margin apart, so the tree stays clear."""
    tree = _load(DESIGNS / "quadruped.json")
    assert tree.clearance().min_clearance < 0.1  # mm: they touch where the junction ends
    report = tree.clearance(margin=0.5)
    assert report.ok and report.min_clearance >= 0.5 - 1e-9, report.verdict("mm")
    assert "come out of its junction" in report.note


def _folding_back(**options) -> KinematicChain:
    """A start tip and a revolute joint; a waypoint folding the tube back beside the tip,
    2.5 r from its axis (0.5 r of clearance) is appended by the caller."""
    chain = KinematicChain(StartTip(4, 1, tip_pose((-6, 0, 0), (1, 0, 0)), 1.5), **options)
    assert chain.append(RevoluteJoint(4, 1, math.pi, frame((0, 0, 0), (1, 0, 0))), **FIXED)
    return chain


RETURN = Waypoint(4, 1, frame((-6, 2.5, 0), (-1, 0, 0)), pathIndex=0)


def test_requireClearance_refuses_an_edit_closer_than_the_margin():
    """The tube folded back 0.5 r from the start: clear at margin 0 and 0.4 r, refused under
    requireClearance at margin 0.6 r (the chain unchanged), warned about without it."""
    for margin in (0.0, 0.4):
        chain = _folding_back(requireClearance=True, margin=margin)
        assert chain.append(RETURN, **FIXED) is not None
        assert chain.clearance().ok
        assert chain.clearance().min_clearance == pytest.approx(0.5, abs=1e-9)
    strict = _folding_back(requireClearance=True, margin=0.6)
    before = strict.Joints
    with pytest.warns(UserWarning, match=r"are 0\.5 apart, closer than the margin 0\.6"):
        assert strict.append(RETURN, **FIXED) is None
    assert strict.Joints == before
    loose = _folding_back(margin=0.6)
    with pytest.warns(ClearanceWarning, match="closer than the margin 0.6"):
        assert loose.append(RETURN, **FIXED) is not None
    assert not loose.clearance().ok and loose.clearance(margin=0.4).ok


@pytest.mark.parametrize(
    ("value", "error"),
    [(-0.1, InvalidParameterError), (math.nan, InvalidParameterError),
     (math.inf, InvalidParameterError), ("0.2", InvalidTypeError), (True, InvalidTypeError),
     (None, InvalidTypeError)],
)  # fmt: skip
def test_a_bad_margin_is_refused_naming_it(value, error):
    chain = _load(DESIGNS / "example1.json")
    with pytest.raises(error, match="margin must be a finite number >= 0"):
        chain.margin = value
    assert chain.margin == 0.0
    if value is not None:
        with pytest.raises(error, match="margin must be a finite number >= 0"):
            chain.clearance(margin=value)
        with pytest.raises(error, match="margin must be a finite number >= 0"):
            sweep(chain, 2, margin=value, progress=False)
        with pytest.raises(error, match="margin must be a finite number >= 0"):
            compact(chain, margin=value, executor=serial(), progress=False)


# --- compaction ---------------------------------------------------------------------------------
def test_compaction_with_a_margin_keeps_the_closest_parts_that_far_apart():
    """A random chain whose compaction (margin 0) brings two parts within 0.002 r of touching:
    with margin 0.25 r, and 0.5 r, the closest parts stay at least that far apart."""
    chain = random_safe_chain(3, 4)
    plain = compact(chain, executor=serial(), starts=2, progress=False)
    assert plain.margin == 0.0 and plain.clearance().min_clearance < 0.01
    for margin in (0.25, 0.5):
        out = compact(chain, executor=serial(), starts=2, progress=False, margin=margin)
        assert out.margin == margin and chain.margin == 0.0  # the input keeps its own
        assert out.clearance(margin=0.0).min_clearance >= margin - 1e-9
        assert out.clearance().ok
        assert tube_length(plain) <= tube_length(out) < tube_length(chain)
