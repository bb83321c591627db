"""STL and OBJ of a KinematicTree (the same parts as a chain's, for every node), and what the
registry does with a tree: the chain formats take it, the sheet formats say to export each
sheet."""

from __future__ import annotations

import copy
import io
import os
import sys
import warnings
from pathlib import Path

import numpy as np
import pytest
import trimesh

from kinegami import KinematicChain, KinematicTree
from kinegami.clearance.solids import chain_parts
from kinegami.design import load_design
from kinegami.errors import ExporterUnavailableError, InvalidTypeError
from kinegami.export.mesh import chain_mesh, obj_data, stl_data
from kinegami.export.registry import export

try:  # tests/ is not a package: reachable as tests.tree from the checkout, else as tree
    from tests.tree.helpers import hand_tree
except ImportError:  # pragma: no cover
    from tree.helpers import hand_tree

EXACT = {"relative": False, "safe": False, "fixedPosition": True, "fixedOrientation": True}
DESIGNS = Path(__file__).resolve().parents[2] / "examples" / "designs"


@pytest.fixture(scope="module")
def hand() -> KinematicTree:
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # the paper's hand touches its palm (tests/tree)
        return hand_tree()


def gallery_chains() -> list[str]:
    names = []
    for path in sorted(DESIGNS.glob("*.json")):
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            if isinstance(load_design(path), KinematicChain):
                names.append(path.stem)
    return names


def as_chain_and_tree(chain: KinematicChain) -> tuple[KinematicChain, KinematicTree]:
    """The chain's joints added with exact poses to a chain and to a tree (parents i - 1)."""
    twin_chain = KinematicChain(chain.Joints[0])
    tree = KinematicTree(chain.Joints[0])
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        for k, joint in enumerate(chain.Joints[1:], start=1):
            twin_chain.append(joint, **EXACT)
            tree.addJoint(k - 1, joint, **EXACT)
    return twin_chain, tree


# --- parts -----------------------------------------------------------------------------------


def test_hand_has_the_parts_of_every_node(hand):
    parts = chain_parts(hand)
    names = [p.name for p in parts]
    assert len(names) == len(set(names))
    # every joint except the root waypoint; every link (each from its parent)
    assert sorted({p.index for p in parts if p.is_joint}) == [1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11]
    assert sorted({p.index for p in parts if not p.is_joint}) == list(range(1, 12))
    # in index order, each joint after the link into it
    order = [(p.index, p.is_joint) for p in parts]
    assert order == sorted(order)
    for part in parts:
        mesh = part.to_trimesh()
        assert mesh.is_watertight and mesh.is_winding_consistent and mesh.volume > 0, part.name


def test_each_link_starts_at_its_parent(hand):
    """A link's first ring is the n-gon of its parent's distal Dubins frame."""
    from kinegami.geometry.shapes import regular_polygon

    parts = chain_parts(hand)
    for k in range(1, len(hand.Joints)):
        first = next(p for p in parts if p.index == k and not p.is_joint)
        parent = hand.Joints[hand.Parents[k]]
        expected = regular_polygon(parent.distal_dubins_frame(), hand.r, hand.numSides)
        np.testing.assert_allclose(first.rings[0], expected, atol=1e-12)


def test_state_change_moves_the_parts_of_the_subtree(hand):
    """setJointState(8, q): the parts beyond joint 8 (the third finger) move rigidly, every
    other part stays, bit for bit."""
    tree = copy.deepcopy(hand)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        assert tree.setJointState(8, 0.7)
    inside = set(tree.subtree(8))
    before = {p.name: p for p in chain_parts(hand)}
    after = {p.name: p for p in chain_parts(tree)}
    assert before.keys() == after.keys()
    G = hand.Joints[8].state_transform(0.7)
    for name, part in after.items():
        old = before[name]
        if part.index == 8:  # the link into joint 8 and its proximal half stay
            moves = part.side == "distal"
        else:
            moves = part.index in inside
        if moves:
            moved = old.vertices @ G[:3, :3].T + G[:3, 3]
            d = np.linalg.norm(part.vertices[:, None] - moved[None], axis=2)
            assert d.min(axis=1).max() < 1e-12 and d.min(axis=0).max() < 1e-12, name
            assert np.abs(part.vertices.mean(axis=0) - old.vertices.mean(axis=0)).max() > 1e-3
        else:
            assert np.array_equal(part.vertices, old.vertices), name


# --- files -----------------------------------------------------------------------------------


def test_hand_stl_round_trip(tmp_path, hand):
    path = export(hand, tmp_path / "hand.stl")
    parts = chain_parts(hand)
    data = path.read_bytes()
    assert data[:80].rstrip() == b"kinegami tree mesh, millimetres"
    mesh = trimesh.load(path, file_type="stl")
    assert len(mesh.faces) == sum(len(p.faces) for p in parts)
    assert len(mesh.split(only_watertight=False)) >= len(parts)  # closed shells, not merged
    np.testing.assert_allclose(mesh.bounds, chain_mesh(hand).bounds, atol=1e-5)
    assert data == stl_data(hand)


def test_hand_obj_has_one_object_per_part(tmp_path, hand):
    path = export(hand, tmp_path / "hand.obj", units="cm")
    parts = chain_parts(hand)
    text = path.read_text()
    assert text.startswith("# kinegami tree mesh:")
    scene = trimesh.load(path, split_objects=True, group_material=False)
    assert sorted(scene.geometry) == sorted(p.name for p in parts)
    for part in parts:
        geometry = scene.geometry[part.name]
        assert len(geometry.faces) == len(part.faces)
        np.testing.assert_allclose(geometry.bounds, 10.0 * part.to_trimesh().bounds, atol=1e-9)
    stream = io.StringIO(obj_data(hand, units="cm"))
    assert stream.getvalue() == text


@pytest.mark.parametrize("name", gallery_chains())
def test_a_tree_that_is_a_chain_gives_the_chain_files(name):
    """Every gallery chain as a tree whose parents are i - 1: STL and OBJ byte for byte."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        chain, tree = as_chain_and_tree(load_design(DESIGNS / f"{name}.json"))
    assert stl_data(tree) == stl_data(chain)
    assert obj_data(tree, units="cm", twistPortion=0.3) == obj_data(
        chain, units="cm", twistPortion=0.3
    )


# --- the registry ----------------------------------------------------------------------------


@pytest.mark.parametrize("suffix", [".stl", ".obj", ".urdf"])
def test_chain_formats_take_a_tree(tmp_path, hand, suffix):
    path = export(hand, tmp_path / f"hand{suffix}")
    assert path.is_file() and path.stat().st_size > 0


@pytest.mark.parametrize("suffix", [".dxf", ".svg", ".pdf", ".fold"])
def test_sheet_formats_say_to_export_each_sheet(tmp_path, hand, suffix):
    with pytest.raises(InvalidTypeError) as info:
        export(hand, tmp_path / f"hand{suffix}")
    message = str(info.value)
    assert "\n" not in message
    assert message.startswith(f"{suffix} files hold one crease pattern")
    assert "3 sheets (one per leaf)" in message and "export each sheet" in message
    assert os.listdir(tmp_path) == []


def test_a_missing_mesh_library_is_still_named(tmp_path, hand, monkeypatch):
    monkeypatch.setitem(sys.modules, "trimesh", None)  # as if trimesh were not installed
    monkeypatch.delitem(sys.modules, "trimesh.convex", raising=False)
    with pytest.raises(ExporterUnavailableError, match=r"kinegami\[mesh\]"):
        export(hand, tmp_path / "hand.stl")
    assert os.listdir(tmp_path) == []


def test_other_objects_are_still_refused(tmp_path, hand):
    with pytest.raises(InvalidTypeError, match="KinematicChain or a KinematicTree"):
        export(hand.Joints[1], tmp_path / "joint.stl")
    with pytest.raises(InvalidTypeError, match="KinematicChain or a KinematicTree"):
        stl_data(hand.Links[1])
