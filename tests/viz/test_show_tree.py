"""KinematicTree.show(): every link drawn from its parent, the tree's own clearance in red."""

from __future__ import annotations

import math
import warnings

import numpy as np
import pytest
from spatialmath import SE3

from kinegami import KinematicTree, RevoluteJoint, Waypoint
from kinegami.clearance.solids import chain_parts
from kinegami.errors import ClearanceWarning
from kinegami.viz import chain_geometry as geo
from kinegami.viz.style import linkSurfaceSides

try:  # tests/ is not a package: reachable as tests.tree from the checkout, else as tree
    from tests.tree.helpers import hand_tree
except ImportError:  # pragma: no cover
    from tree.helpers import hand_tree


@pytest.fixture(scope="module")
def hand() -> KinematicTree:
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # the paper's hand touches its palm (tests/tree)
        return hand_tree()


def _artist(ax, gid):
    found = [a for a in (*ax.collections, *ax.lines) if a.get_gid() == gid]
    assert len(found) == 1, f"expected one artist with gid {gid!r}, found {len(found)}"
    return found[0]


def _gids(ax):
    return {a.get_gid() for a in (*ax.collections, *ax.lines)}


def _pieces(line) -> list[np.ndarray]:
    """The NaN-separated pieces of a Line3D (data coordinates)."""
    x, y, z = (np.asarray(v, dtype=float) for v in line.get_data_3d())
    points = np.stack([x, y, z], axis=1)
    gaps = np.flatnonzero(np.isnan(points[:, 0]))
    pieces = [piece[~np.isnan(piece[:, 0])] for piece in np.split(points, gaps)]
    return [piece for piece in pieces if len(piece)]


def test_hand_draws_to_a_png(tmp_path, hand):
    fig, ax = hand.show()
    path = tmp_path / "hand.png"
    fig.savefig(path, dpi=60)
    assert path.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert {"joint-bodies", "joint-axes", "link-elbows", "link-tubes", "link-path"} <= _gids(ax)


def test_every_link_is_drawn_from_its_parent(hand):
    """One centreline per link, from the distal frame of joint Parents[i] to joint i."""
    fig, ax = hand.show(showJointPoses=False)
    pieces = _pieces(_artist(ax, "link-path"))
    assert len(pieces) == len(hand.Joints) - 1 == 11
    for k, piece in zip(range(1, len(hand.Joints)), pieces, strict=True):
        parent = hand.Joints[hand.Parents[k]]
        np.testing.assert_allclose(piece[0], parent.distal_dubins_frame()[:3, 3], atol=1e-9)
        np.testing.assert_allclose(piece[-1], hand.Joints[k].proximal_dubins_frame()[:3, 3],
                                   atol=1e-9)  # fmt: skip
    # the three fingers leave the palm's distal frame
    palm = hand.Joints[0].distal_dubins_frame()[:3, 3]
    assert sum(np.allclose(p[0], palm, atol=1e-9) for p in pieces) == 3
    markers = _artist(ax, "link-path-markers").get_data_3d()
    assert len(markers[0]) == 2 * 11


def test_every_joint_and_link_surface_is_drawn(hand):
    fig, ax = hand.show()
    fig.canvas.draw()  # a Poly3DCollection has its paths once projected
    faces = sum(len(geo.joint_body_faces(j)) for j in hand.Joints)
    assert len(_artist(ax, "joint-bodies").get_paths()) == faces
    elbows = sum(j.elbows1.count + j.elbows2.count for j in hand.Links[1:])
    tubes = sum(geo.tube_grid(link, linkSurfaceSides) is not None for link in hand.Links[1:])
    assert len(_artist(ax, "link-elbows").get_paths()) == 2 * linkSurfaceSides * elbows
    assert len(_artist(ax, "link-tubes").get_paths()) == linkSurfaceSides * tubes
    axes = sum(isinstance(j, RevoluteJoint) for j in hand.Joints)
    assert len(_artist(ax, "joint-axes").get_segments()) == axes == 8


def test_limits_contain_the_whole_tree(hand):
    fig, ax = hand.show(showSpheres=True)
    ball = hand.boundingBall
    c = np.asarray(ball.c, dtype=float)
    for axis, limits in enumerate((ax.get_xlim3d(), ax.get_ylim3d(), ax.get_zlim3d())):
        assert limits[0] <= c[axis] - ball.r and c[axis] + ball.r <= limits[1]


def test_hand_collisions_are_the_trees(hand):
    """showCollisions draws the pairs of tree.clearance(): the palm's revolute joint and the
    middle finger's tube (docs/trees.md), in red, with their closest points joined."""
    report = hand.clearance()
    assert not report.ok and len(report.pairs) == 1
    fig, ax = hand.show(showCollisions=True)
    assert ax.get_title() == f"clearance: {report.min_clearance:.3g} (1 colliding pair)"
    parts = {p.name: p for p in chain_parts(hand)}
    expected = len(parts["joint_1_proximal"].faces) + len(parts["link_5_tube"].faces)
    assert len(_artist(ax, "collision-parts").get_facecolor()) == expected
    (segment,) = _pieces(_artist(ax, "collision-lines"))
    np.testing.assert_allclose(segment, np.array(report.pairs[0].points), atol=1e-12)


def test_a_clear_tree_draws_nothing_red():
    tree = KinematicTree(Waypoint(4, 1, SE3()))
    ry = SE3.Ry(math.pi / 2)
    with warnings.catch_warnings():
        warnings.simplefilter("error", ClearanceWarning)
        tree.addJoint(0, RevoluteJoint(4, 1, math.pi, SE3.Trans(3, 0, 4) * ry))
        tree.addJoint(0, RevoluteJoint(4, 1, math.pi, SE3.Trans(-3, 0, 4) * ry))
    report = tree.clearance()
    assert report.ok and len(tree.Children[0]) == 2
    fig, ax = tree.show(showCollisions=True)
    assert ax.get_title().endswith("(clear)")
    assert not {"collision-parts", "collision-lines", "collision-points"} & _gids(ax)
