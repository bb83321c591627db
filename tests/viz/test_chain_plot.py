"""KinematicChain.show(): what ends up on the matplotlib axes (chain.md section 6)."""

import time

import matplotlib.pyplot as plt
import numpy as np
import pytest
from matplotlib.colors import to_rgba
from matplotlib.figure import Figure
from mpl_toolkits.mplot3d.axes3d import Axes3D
from numpy.testing import assert_allclose
from spatialmath import SE3

from kinegami.errors import InvalidParameterError, InvalidTypeError
from kinegami.viz import _backend, style
from kinegami.viz.chain_plot import CHAIN_PLOT_OPTIONS, show_chain

from .conftest import build_long_chain


def _artist(ax, gid):
    found = [a for a in (*ax.collections, *ax.lines) if a.get_gid() == gid]
    assert len(found) == 1, f"expected one artist with gid {gid!r}, found {len(found)}"
    return found[0]


def _gids(ax):
    return {a.get_gid() for a in (*ax.collections, *ax.lines)}


def _axes_shown(ax) -> bool:
    """Axes3D keeps its own on/off flag for the panes, ticks and labels."""
    return bool(getattr(ax, "_axis3don", ax.axison))


def _legend_labels(ax):
    legend = ax.get_legend()
    return [] if legend is None else [t.get_text() for t in legend.get_texts()]


def test_show_returns_figure_and_axes3d(example_1a):
    fig, ax = example_1a.show()
    assert isinstance(fig, Figure)
    assert isinstance(ax, Axes3D)
    assert ax.figure is fig


def test_default_drawing_has_joints_links_and_path(example_1a):
    _, ax = example_1a.show()
    assert {
        "joint-bodies",
        "joint-axes",
        "link-elbows",
        "link-tubes",
        "link-path",
        "link-path-markers",
        "joint-frame-x",
    } <= _gids(ax)
    assert "global-frame-x" not in _collection_gids(ax)
    assert not _axes_shown(ax)


BOOLEAN_FLIPS = [
    {"showJointPoses": False},
    {"showJointSurface": False},
    {"showLinkSurface": False},
    {"showLinkPath": False},
    {"showPathCircles": True},
    {"showLinkPoses": True},
    {"showSpheres": True},
    {"showGlobalFrame": True},
    {"showGroundPlane": True},
    {"showAxisGrids": True},
    {"block": False},
    {
        "xColor": "red",
        "yColor": "green",
        "zColor": "blue",
        "proximalColor": "k",
        "centerColor": "k",
        "distalColor": "k",
        "jointColor": "purple",
        "linkColor": "orange",
        "pathColor": "gray",
        "sphereColor": "navy",
        "groundPlaneColor": "brown",
    },
    {"surfaceOpacity": 1.0, "jointAxisScale": 3, "globalAxisScale": 2.5, "groundPlaneScale": 4},
]


@pytest.mark.parametrize("options", BOOLEAN_FLIPS, ids=lambda o: ",".join(o))
def test_every_option_draws(example_1a, options):
    fig, ax = example_1a.show(**options)
    fig.canvas.draw()
    assert isinstance(ax, Axes3D)


def test_every_option_is_covered_by_the_style_module():
    assert set(CHAIN_PLOT_OPTIONS) == set(style.CHAIN_PLOT_DEFAULTS)
    assert style.CHAIN_PLOT_DEFAULTS["xColor"] == "orangered"
    assert style.CHAIN_PLOT_DEFAULTS["surfaceOpacity"] == 0.5
    assert style.CHAIN_PLOT_DEFAULTS["showJointPoses"] is True
    assert style.CHAIN_PLOT_DEFAULTS["block"] is None


@pytest.mark.parametrize(
    ("option", "gids"),
    [
        ("showPathCircles", {"path-circles-start", "path-circles-end"}),
        ("showLinkPoses", {"link-pose-a", "link-rotation-axes", "link-tangents"}),
        ("showSpheres", {"joint-spheres", "chain-sphere"}),
        ("showGlobalFrame", {"global-frame-x", "global-frame-y", "global-frame-z"}),
        ("showGroundPlane", {"ground-plane"}),
    ],
)
def test_optional_parts_appear_only_when_asked(example_1a, option, gids):
    _, ax = example_1a.show()
    assert not gids & _gids(ax)
    _, ax = example_1a.show(**{option: True})
    assert gids <= _gids(ax)


def test_hidden_parts_are_not_drawn(example_1a):
    _, ax = example_1a.show(showJointPoses=False, showJointSurface=False, showLinkSurface=False,
                            showScaleBar=False)  # fmt: skip
    assert _gids(ax) == {"link-path", "link-path-markers"}


def test_data_limits_contain_every_joint_origin(example_1a):
    _, ax = example_1a.show()
    low = np.array([ax.get_xlim3d()[0], ax.get_ylim3d()[0], ax.get_zlim3d()[0]])
    high = np.array([ax.get_xlim3d()[1], ax.get_ylim3d()[1], ax.get_zlim3d()[1]])
    for joint in example_1a.Joints:
        for frame in (joint.proximal_frame(), joint.distal_frame()):
            assert np.all(low <= frame[:3, 3]) and np.all(frame[:3, 3] <= high)


def test_box_aspect_is_equal(example_1a):
    _, ax = example_1a.show()
    ranges = np.array([np.ptp(ax.get_xlim3d()), np.ptp(ax.get_ylim3d()), np.ptp(ax.get_zlim3d())])
    aspect = np.asarray(ax.get_box_aspect())
    assert_allclose(aspect / aspect.max(), ranges / ranges.max())


def test_number_of_elbow_surfaces_equals_elbow_count(example_1a):
    fig, ax = example_1a.show()
    fig.canvas.draw()
    elbows = sum(link.elbows1.count + link.elbows2.count for link in example_1a.Links)
    quads_per_elbow = 2 * style.linkSurfaceSides
    assert len(_artist(ax, "link-elbows").get_paths()) == elbows * quads_per_elbow
    tubes = sum(link.path.tMag > 0.01 * link.r for link in example_1a.Links)
    assert len(_artist(ax, "link-tubes").get_paths()) == tubes * style.linkSurfaceSides


def test_link_path_passes_through_q1_and_q2(example_1a):
    _, ax = example_1a.show()
    pts = np.column_stack(_artist(ax, "link-path").get_data_3d())
    pts = pts[np.all(np.isfinite(pts), axis=1)]
    markers = np.column_stack(_artist(ax, "link-path-markers").get_data_3d())
    assert _artist(ax, "link-path-markers").get_marker() == "*"
    for link in example_1a.Links[1:]:
        for q in (link.path.q1, link.path.q2):
            assert np.linalg.norm(pts - q, axis=1).min() < 1e-9
            assert np.linalg.norm(markers - q, axis=1).min() < 1e-9


def test_joint_axes_are_dashed_silver_lines(example_1a):
    fig, ax = example_1a.show()
    fig.canvas.draw()
    axes = _artist(ax, "joint-axes")
    moving = [
        j for j in example_1a.Joints if type(j).__name__ in ("RevoluteJoint", "PrismaticJoint")
    ]
    assert len(axes.get_segments()) == len(moving) == 2
    assert axes.get_linestyle()[0][1] is not None  # a dash pattern
    assert_allclose(axes.get_colors()[0], to_rgba("silver"))


def test_savefig_png(example_1a, tmp_path):
    fig, _ = example_1a.show(showGlobalFrame=True)
    path = tmp_path / "example1A.png"
    fig.savefig(path)
    assert path.stat().st_size > 1000
    assert path.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_unknown_option_is_a_type_error_naming_it(example_1a):
    with pytest.raises(TypeError) as info:
        example_1a.show(showJointPose=True)
    assert isinstance(info.value, InvalidTypeError)
    message = str(info.value)
    assert "'showJointPose'" in message
    assert "showJointPoses" in message and "groundPlaneScale" in message


@pytest.mark.parametrize(
    ("options", "error"),
    [
        ({"showSpheres": "yes"}, InvalidTypeError),
        ({"block": 1}, InvalidTypeError),
        ({"surfaceOpacity": 2.0}, InvalidParameterError),
        ({"jointAxisScale": -1}, InvalidParameterError),
        ({"globalAxisScale": "big"}, InvalidTypeError),
        ({"xColor": "not-a-colour"}, InvalidParameterError),
    ],
)
def test_bad_option_values(example_1a, options, error):
    with pytest.raises(error):
        example_1a.show(**options)


def test_no_elbow_chain_with_link_poses(straight_chain):
    assert all(link.elbows1.count + link.elbows2.count == 0 for link in straight_chain.Links)
    _, ax = straight_chain.show(showLinkPoses=True)
    assert "link-pose-a" not in _collection_gids(ax)
    assert "link-tangents" in _gids(ax)
    assert _legend_labels(ax) == [r"$\hat{x}$", r"$\hat{y}$", r"$\hat{z}$"]


def test_single_joint_chain_draws():
    from kinegami import SE3, KinematicChain, StartTip

    chain = KinematicChain(StartTip(4, 1, Pose=SE3(), length=1.5))
    fig, ax = chain.show(showLinkPoses=True, showPathCircles=True, showSpheres=True)
    fig.canvas.draw()
    assert "joint-bodies" in _gids(ax)


def test_legend_entries(example_1a):
    _, ax = example_1a.show(showJointPoses=False)
    assert _legend_labels(ax) == []
    _, ax = example_1a.show(showJointPoses=False, showGlobalFrame=True)
    assert len(_legend_labels(ax)) == 3
    _, ax = example_1a.show(showLinkPoses=True)
    assert len(_legend_labels(ax)) == 6


def test_axis_grids(example_1a):
    _, ax = example_1a.show(showAxisGrids=True)
    assert _axes_shown(ax)
    _, ax = example_1a.show()
    assert not _axes_shown(ax)


def test_draws_into_given_axes(example_1a):
    fig = plt.figure()
    ax = fig.add_subplot(projection="3d")
    ax.plot([100.0], [0.0], [0.0], "o")
    fig2, ax2 = example_1a.show(ax=ax)
    assert fig2 is fig and ax2 is ax
    assert ax.get_xlim3d()[1] >= 100.0  # the existing data stays in view
    assert "joint-bodies" in _gids(ax)


def test_2d_axes_rejected(example_1a):
    _, ax = plt.subplots()
    with pytest.raises(InvalidTypeError, match="3D"):
        example_1a.show(ax=ax)


def test_headless_never_calls_plt_show(example_1a, monkeypatch):
    def forbidden(*args, **kwargs):
        raise AssertionError("plt.show called under a non-interactive backend")

    monkeypatch.setattr(plt, "show", forbidden)
    example_1a.show(block=True)


@pytest.mark.parametrize(("block", "expected"), [(None, {}), (False, {"block": False})])
def test_interactive_backend_calls_plt_show(example_1a, monkeypatch, block, expected):
    calls = []
    monkeypatch.setattr(_backend, "backend_is_interactive", lambda: True)
    monkeypatch.setattr(plt, "show", lambda **kwargs: calls.append(kwargs))
    example_1a.show(block=block)
    assert calls == [expected]
    # Drawing into the caller's axes leaves showing to the caller.
    ax = plt.figure().add_subplot(projection="3d")
    example_1a.show(ax=ax)
    assert len(calls) == 1


def test_agg_is_not_interactive():
    assert _backend.backend_is_interactive() is False


def test_show_chain_is_the_delegate(example_1a):
    fig, ax = show_chain(example_1a, showLinkPath=False)
    assert "link-path" not in _collection_gids(ax)


def test_fifty_joint_chain_draws_quickly():
    chain = build_long_chain(50)
    assert len(chain) >= 50
    start = time.perf_counter()
    fig, _ = chain.show()
    fig.canvas.draw()
    assert time.perf_counter() - start < 5.0


def test_shading_matches_mplot3d_on_ordinary_faces():
    """Faces are shaded here (Newell normals) the way mplot3d shades them itself."""
    from mpl_toolkits.mplot3d.art3d import Poly3DCollection

    from kinegami.viz.chain_geometry import face_normals
    from kinegami.viz.chain_plot import _shaded, _shading

    rng = np.random.default_rng(3)
    triangles = rng.normal(size=(40, 3, 3))
    colour = to_rgba("tab:blue", 0.4)
    ax = plt.figure().add_subplot(projection="3d")
    collection = Poly3DCollection(list(triangles), shade=True, facecolors=colour)
    ax.add_collection3d(collection)
    ax.figure.canvas.draw()
    theirs = collection.get_facecolor()  # in drawing order: compare sorted by brightness
    ours = _shaded(colour, _shading(face_normals(triangles)))
    plt.close(ax.figure)
    assert_allclose(ours[np.argsort(ours[:, 0])], theirs[np.argsort(theirs[:, 0])], atol=1e-12)


def test_elbow_triangles_are_shaded_by_their_plane(example_1a):
    """An elbow quad whose two vertices coincide is drawn in the shade of its triangle, not of
    the noise in the null vector that three of its vertices give (which changed with the CPU)."""
    from kinegami.viz.chain_geometry import grid_quads, link_elbow_grids
    from kinegami.viz.chain_plot import _shaded, _shading

    fig, ax = example_1a.show()
    fig.canvas.draw()
    drawn = _artist(ax, "link-elbows").get_facecolor()
    plt.close(fig)
    grids = [
        g for link in example_1a.Links if len(g := link_elbow_grids(link, style.linkSurfaceSides))
    ]
    q = grid_quads(np.concatenate(grids))
    gaps = np.stack([np.linalg.norm(q[:, i] - q[:, (i + 1) % 4], axis=1) for i in range(4)], 1)
    pinched = gaps.min(axis=1) < 1e-9 * gaps.max(axis=1)
    assert pinched.sum() > 10  # the case exists in Example 1A
    # each quad's plane from its two diagonals, which a repeated vertex does not spoil
    normals = np.cross(q[:, 2] - q[:, 0], q[:, 3] - q[:, 1])
    expected = _shaded(to_rgba(style.CHAIN_PLOT_DEFAULTS["linkColor"], 1.0), _shading(normals))
    expected[:, 3] = drawn[:, 3]
    assert_allclose(
        drawn[np.lexsort(drawn.T[::-1])], expected[np.lexsort(expected.T[::-1])], atol=1e-9
    )


# --- a tree's junction connectors (showJunctions) ------------------------------------------------


def _three_finger_tree():
    import warnings

    from kinegami import ClearanceWarning, EndTip, KinematicTree, RevoluteJoint, Waypoint

    tree = KinematicTree(Waypoint(4, 1, SE3()))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ClearanceWarning)
        for k in range(3):
            pose = SE3.Rz(2 * np.pi * k / 3) * SE3.Trans(3, 0, 4) * SE3.Ry(np.pi / 2)
            a = tree.addJoint(0, RevoluteJoint(4, 1, np.pi, pose))
            tree.addJoint(a, EndTip(4, 1, SE3.Trans(4, 0, 0) * SE3.Ry(np.pi / 2), 1.5))
    return tree


def _collection_gids(ax) -> set:
    return {artist.get_gid() for artist in ax.collections}


def test_show_junctions_draws_every_connector_of_a_tree():
    pytest.importorskip("manifold3d")
    from kinegami.fabrication.sheets import fabricate, fit_junctions

    tree, _ = fit_junctions(_three_finger_tree())
    fig, ax = show_chain(tree, showJunctions=True)
    try:
        [junctions] = [c for c in ax.collections if c.get_gid() == "junctions"]
        fabrication = fabricate(tree)
        meshes = [fabrication.connector(k) for k in range(len(fabrication.junctions))]
        fig.canvas.draw()  # mplot3d projects its polygons when drawn
        assert len(junctions.get_paths()) == sum(len(m.faces) for m in meshes)
        # the view's limits hold every connector
        lo = np.min([m.bounds[0] for m in meshes], axis=0)
        hi = np.max([m.bounds[1] for m in meshes], axis=0)
        for (a, b), low, high in zip(
            (ax.get_xlim(), ax.get_ylim(), ax.get_zlim()), lo, hi, strict=True
        ):
            assert a <= low + 1e-9 and high <= b + 1e-9
    finally:
        plt.close(fig)
    fig, ax = show_chain(tree)  # off by default
    assert "junctions" not in _collection_gids(ax)
    plt.close(fig)


def test_show_junctions_on_a_chain_draws_nothing_more():
    from kinegami import KinematicChain, RevoluteJoint, StartTip

    chain = KinematicChain(StartTip(4, 1, SE3(), 1.5))
    chain.append(RevoluteJoint(4, 1, np.pi, SE3.Trans(0, 0, 6)))
    fig, ax = show_chain(chain, showJunctions=True)
    assert "junctions" not in _collection_gids(ax)
    plt.close(fig)


def test_a_connector_that_cannot_be_made_is_left_out_with_a_warning():
    import warnings
    from pathlib import Path

    from kinegami import ClearanceWarning
    from kinegami.design import load_design

    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ClearanceWarning)
        # the paper's hand as published: the palm's tube has no room for its socket
        root = Path(__file__).resolve().parents[2]
        hand = load_design(root / "tests" / "design" / "data" / "papers_hand.json")
    with pytest.warns(UserWarning, match="showJunctions: the junctions are not drawn.*joint 1"):
        fig, ax = show_chain(hand, showJunctions=True)
    assert "junctions" not in _collection_gids(ax)
    assert "joint-bodies" in _collection_gids(ax)
    plt.close(fig)


def test_a_fabrication_shows_its_folded_tree_and_only_its_own_connectors():
    """``TreeFabrication.show``: the quadruped with ``junction="auto"`` has a take-off at the
    body and a printed connector at joint 9: the view draws the take-off links and that one
    connector (``showJunctions`` alone would have made both junctions connectors)."""
    pytest.importorskip("manifold3d")
    import warnings
    from pathlib import Path

    from kinegami import ClearanceWarning
    from kinegami.design import load_design
    from kinegami.fabrication.sheets import fabricate, fit_junctions

    design = Path(__file__).resolve().parents[2] / "examples/designs/quadruped.json"
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ClearanceWarning)
        tree, _ = fit_junctions(load_design(design))
        made = fabricate(tree, junction="auto")
    assert made.takeoffs and len(made.junctions) == 1
    fig, ax = made.show()
    try:
        fig.canvas.draw()
        [junctions] = [c for c in ax.collections if c.get_gid() == "junctions"]
        assert len(junctions.get_paths()) == len(made.connector(0).faces)
        # the centrelines drawn are the folded tree's: one more node per take-off cut
        [path] = [line for line in ax.lines if line.get_gid() == "link-path"]
        drawn = np.asarray(path.get_data_3d()).T
        folded = made.folded_tree()
        assert len(folded.Joints) > len(tree.Joints)
        for takeoff in made.takeoffs:  # each take-off link starts on its trunk's face
            start = takeoff.frame[:3, 3]
            assert np.nanmin(np.linalg.norm(drawn - start, axis=1)) < 1e-9
    finally:
        plt.close(fig)
    fig, ax = made.show(showJunctions=False)
    assert "junctions" not in _collection_gids(ax)
    plt.close(fig)
