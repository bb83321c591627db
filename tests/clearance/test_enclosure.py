"""The capsules of the body model enclose the parts they stand for.

Every vertex of every exported mesh part lies inside the capsules (radius r) of its own chain
element, and every vertex of the folded form lies inside the union of the chain's capsules:
the meshes on the gallery designs and on random chains, at random states too; the folded forms
on the gallery designs (at state 0, the folded form's configuration).

The folded form departs from the kinematic model after a prismatic joint, by design
(kinegami/pattern/folded.py): the joint's pattern folds to d' + L, the REBO bellows at its rigid
folded length d' >= d plus the sleeve L, instead of the kinematic d, and everything after it is
translated by the difference along the joint's axis. So a prismatic module is checked in its own
frame (every vertex within r of its axis, between its two ends), and the modules after it are
checked against the capsules moved by the translations of the prismatic joints before them.
"""

from __future__ import annotations

import numpy as np
import pytest
from export.test_mesh import random_chains  # the mesh tests' random chains
from gallery_designs import CHAIN_DESIGNS
from hypothesis import given, settings
from hypothesis import strategies as st

from kinegami import (
    PrismaticJoint,
)
from kinegami.chain.bodies import capsule_model
from kinegami.clearance.solids import chain_parts
from kinegami.design import load_design
from kinegami.pattern.folded import folded_form

DESIGNS = CHAIN_DESIGNS  # a chain pattern's folded form (trees: one per sheet)
#: Vertices may lie this many r outside their capsules (round-off).
TOLERANCE = 1e-6


def distances_to_segments(points, starts, ends) -> np.ndarray:
    """(P,) distance of every point to the nearest of the segments starts[k] -> ends[k]."""
    p = np.asarray(points, dtype=float)[:, None, :]
    d = ends - starts
    length2 = np.einsum("ij,ij->i", d, d)
    t = np.einsum("pij,ij->pi", p - starts, d) / np.where(length2 > 0.0, length2, 1.0)
    closest = starts + np.clip(t, 0.0, 1.0)[..., None] * d
    return np.linalg.norm(p - closest, axis=2).min(axis=1)


def element(part) -> int:
    """The chain element of a mesh part: 2 i for joint i, 2 i - 1 for link i."""
    return 2 * part.index if part.is_joint else 2 * part.index - 1


def mesh_excess(chain) -> dict[str, float]:
    """Per mesh part, how far (in r) its farthest vertex lies outside its element's capsules."""
    model = capsule_model(chain)
    out = {}
    for part in chain_parts(chain, split_joints=False):
        mine = model.element == element(part)
        assert mine.any(), f"{part.name} has no capsule"
        d = distances_to_segments(part.vertices, model.starts[mine], model.ends[mine])
        out[part.name] = float(d.max() - model.r) / model.r
    return out


def assert_mesh_enclosed(chain) -> None:
    excess = mesh_excess(chain)
    outside = {name: e for name, e in excess.items() if e > TOLERANCE}
    assert not outside, f"mesh vertices outside their capsules (in r): {outside}"


def folded_excess(chain) -> dict[str, float]:
    """Per folded module (``"k: kind"``), how far (in r) its farthest vertex lies outside the
    capsules, at state 0; prismatic modules against their own axis (see the module docstring).
    """
    chain.setJointStates([0.0] * len(chain.Joints))
    model = capsule_model(chain)
    r = model.r
    form = folded_form(chain)
    prismatic = iter(j for j in chain.Joints if isinstance(j, PrismaticJoint))
    shift = np.zeros(3)  # folded minus kinematic position, after the prismatic joints so far
    out = {}
    for k, module in enumerate(form.modules):
        X = form.vertices[module.vertices]
        if module.kind == "prismatic":
            joint = next(prismatic)
            o, R = module.proximal[:3, 3], module.proximal[:3, :3]
            local = (X - o) @ R  # x along the axis of motion
            length = float(np.linalg.norm(module.distal[:3, 3] - o))
            radial = np.hypot(local[:, 1], local[:, 2]).max() - r
            axial = max(-local[:, 0].min(), local[:, 0].max() - length)
            out[f"{k}: prismatic"] = float(max(radial, axial)) / r
            shift = shift + (length - joint.neutralLength) * R[:, 0]
            continue
        d = distances_to_segments(X - shift, model.starts, model.ends)
        out[f"{k}: {module.kind}"] = float(d.max() - r) / r
    assert next(prismatic, None) is None, "a prismatic joint without a folded module"
    return out


def assert_folded_enclosed(chain) -> None:
    excess = folded_excess(chain)
    outside = {name: e for name, e in excess.items() if e > TOLERANCE}
    assert not outside, f"folded vertices outside the capsules (in r): {outside}"


# --- gallery ---------------------------------------------------------------------------------


@pytest.fixture(scope="module", params=DESIGNS, ids=[p.stem for p in DESIGNS])
def design(request):
    return request.param


def test_the_gallery_has_designs():
    assert len(DESIGNS) >= 10


def test_gallery_meshes_lie_in_their_capsules(design):
    assert_mesh_enclosed(load_design(design))


@settings(deadline=None, max_examples=5)
@given(data=st.data())
def test_gallery_meshes_lie_in_their_capsules_at_random_states(design, data):
    chain = load_design(design)
    assert chain.setJointStates([data.draw(st.floats(*j.stateRange())) for j in chain.Joints])
    assert_mesh_enclosed(chain)


def test_gallery_folded_forms_lie_in_the_capsules(design):
    chain = load_design(design)
    excess = folded_excess(chain)
    assert len(excess) >= 2
    outside = {name: e for name, e in excess.items() if e > TOLERANCE}
    assert not outside, f"folded vertices outside the capsules (in r): {outside}"


def test_the_folded_prismatic_joint_is_longer_than_its_capsule():
    """Why prismatic modules need their own check: the folded joint overshoots the kinematic
    one, so its vertices are not inside the chain's capsules where they are."""
    chain = load_design(DESIGNS[[p.stem for p in DESIGNS].index("cylindrical_joint")])
    model = capsule_model(chain)
    form = folded_form(chain)
    (module,) = [m for m in form.modules if m.kind == "prismatic"]
    d = distances_to_segments(form.vertices[module.vertices], model.starts, model.ends)
    assert d.max() > 2.0 * model.r


# --- random chains ---------------------------------------------------------------------------
# random chains from tests/export/test_mesh.py. Folded forms are checked on the gallery only:
# on random safe chains the folded form drifts from the kinematic model by up to ~1e-3 r
# (a 12-joint chain: 7.4e-4 r at its end tip), more than the 1e-6 r of these checks; see the
# folded form's omissions (turns and twists <= 0.01 rad, tubes < 1e-4 b) in pattern/folded.py.

@settings(deadline=None, max_examples=30)
@given(chain=random_chains(), data=st.data())
def test_random_chain_meshes_lie_in_their_capsules_at_random_states(chain, data):
    assert chain.setJointStates([data.draw(st.floats(*j.stateRange())) for j in chain.Joints])
    assert_mesh_enclosed(chain)


def test_the_distance_to_the_capsule_axes_is_exact():
    """The helper the checks rely on: clamped to the segments' ends, nearest segment wins."""
    starts = np.array([[0.0, 0.0, 0.0], [5.0, 0.0, 0.0]])
    ends = np.array([[1.0, 0.0, 0.0], [5.0, 0.0, 0.0]])  # the second one is a point
    points = np.array([[0.5, 1.01, 0.0], [-3.0, 4.0, 0.0], [5.0, 0.0, 2.0], [3.0, 0.0, 0.0]])
    d = distances_to_segments(points, starts, ends)
    np.testing.assert_allclose(d, [1.01, 5.0, 2.0, 2.0], rtol=0, atol=1e-15)
