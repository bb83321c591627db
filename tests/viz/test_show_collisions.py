"""KinematicChain.show(showCollisions=True): colliding parts in red, closest points joined."""

import math

import numpy as np
import pytest
from matplotlib.colors import to_rgba
from numpy.testing import assert_allclose

from kinegami import KinematicChain, RevoluteJoint, StartTip, Waypoint
from kinegami.chain.bodies import _ordinal
from kinegami.clearance.solids import chain_parts
from kinegami.errors import ClearanceWarning, InvalidTypeError
from kinegami.viz.chain_plot import ARTIST_GIDS, _labelled_parts, resolve_chain_options

FIXED = {"relative": False, "safe": False, "fixedPosition": True, "fixedOrientation": True}
COLLISION_GIDS = ("collision-parts", "collision-lines", "collision-points")


def _pose(p, z, x) -> np.ndarray:
    T = np.eye(4)
    T[:3, 0], T[:3, 2], T[:3, 3] = x, z, p
    T[:3, 1] = np.cross(T[:3, 2], T[:3, 0])
    return T


def fold_back(degrees: float) -> KinematicChain:
    """Start tip along +x, a revolute joint (axis z) at the origin, a waypoint 2.5 r back
    beside the incoming tube: clear at 0, the return leg swings into the start at 20 deg."""
    chain = KinematicChain(StartTip(4, 1, _pose((-6, 0, 0), (1, 0, 0), (0, 1, 0)), 1.5))
    assert chain.append(RevoluteJoint(4, 1, math.pi, _pose((0, 0, 0), (0, 0, 1), (1, 0, 0))),
                        **FIXED)  # fmt: skip
    waypoint = Waypoint(4, 1, _pose((-6, 2.5, 0), (0, 0, 1), (-1, 0, 0)), pathIndex=0)
    assert chain.append(waypoint, **FIXED) is not None
    if degrees:
        with pytest.warns(ClearanceWarning):
            assert chain.setJointState(1, math.radians(degrees))
    return chain


def _artist(ax, gid):
    found = [a for a in (*ax.collections, *ax.lines) if a.get_gid() == gid]
    assert len(found) == 1, f"expected one artist with gid {gid!r}, found {len(found)}"
    return found[0]


def _gids(ax):
    return {a.get_gid() for a in (*ax.collections, *ax.lines)}


def test_collision_artists_are_declared():
    assert set(COLLISION_GIDS) <= set(ARTIST_GIDS)


def test_the_option_is_off_by_default_and_must_be_a_bool():
    assert resolve_chain_options({})["showCollisions"] is False
    with pytest.raises(InvalidTypeError, match="showCollisions"):
        resolve_chain_options({"showCollisions": 1})


def test_a_fold_back_is_drawn_in_red_with_its_closest_points_joined():
    chain = fold_back(20)
    report = chain.clearance()
    assert len(report.pairs) >= 1
    fig, ax = chain.show(showCollisions=True)
    fig.canvas.draw()
    red = to_rgba("red")
    parts = _artist(ax, "collision-parts")
    colours = parts.get_facecolor()
    assert len(colours) > 0
    # shaded red: no green or blue, some red
    assert np.all(colours[:, 1:3] == 0.0) and np.all(colours[:, 0] > 0.0)
    line = _artist(ax, "collision-lines")
    assert to_rgba(line.get_color()) == red
    drawn = np.column_stack(line.get_data_3d())
    ends = drawn[~np.isnan(drawn).any(axis=1)].reshape(-1, 2, 3)
    assert_allclose(ends, [pair.points for pair in report.pairs], rtol=0, atol=0)
    points = _artist(ax, "collision-points")
    assert to_rgba(points.get_color()) == red
    assert (
        ax.get_title()
        == f"clearance: {report.min_clearance:.3g} ({len(report.pairs)} colliding pairs)"
    )


def test_the_red_parts_are_the_named_ones():
    chain = fold_back(20)
    parts = chain_parts(chain)
    by_name = {p.name: p for p in parts}
    assert [p.name for p in _labelled_parts(chain, "joint 0, StartTip", parts)] == ["joint_0"]
    half = _labelled_parts(chain, "joint 1, RevoluteJoint, proximal half", parts)
    assert [p.name for p in half] == ["joint_1_proximal"]
    assert [p.name for p in _labelled_parts(chain, "link 2, straight tube", parts)] == [
        "link_2_tube"
    ]
    elbows1 = chain.Links[2].elbows1.count
    assert elbows1 >= 1 and chain.Links[2].elbows2.count >= 1
    first = _labelled_parts(chain, "link 2, first elbow", parts)
    assert [p.name for p in first] == ["link_2_arc1"]
    later = _labelled_parts(chain, f"link 2, {_ordinal(elbows1 + 1)} elbow", parts)
    assert [p.name for p in later] == ["link_2_arc2"]
    # the drawn red faces are those of the parts named in the report
    report = chain.clearance()
    named = {p.name for pair in report.pairs for label in (pair.first, pair.second)
             for p in _labelled_parts(chain, label, parts)}  # fmt: skip
    _, ax = chain.show(showCollisions=True)
    faces = sum(len(by_name[name].faces) for name in named)
    assert len(_artist(ax, "collision-parts").get_facecolor()) == faces


def test_a_clear_chain_draws_nothing_red_and_says_so():
    chain = fold_back(0)
    report = chain.clearance()
    assert report.ok
    _, ax = chain.show(showCollisions=True)
    assert not set(COLLISION_GIDS) & _gids(ax)
    assert ax.get_title() == f"clearance: {report.min_clearance:.3g} (clear)"


def test_without_the_option_there_is_no_title_and_nothing_red():
    _, ax = fold_back(20).show()
    assert not set(COLLISION_GIDS) & _gids(ax)
    assert ax.get_title() == ""
