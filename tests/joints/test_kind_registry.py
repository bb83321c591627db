"""A new joint kind is one class plus one registration (docs/architecture.md, "Joint kinds as
data"): a kind defined here, in this file only, is appended, drawn, meshed, tested for
clearance, posed by the forward kinematics, exported to URDF and saved and loaded through design
files, with no other change to the package."""

from __future__ import annotations

import math
import warnings

import numpy as np
import pytest
from spatialmath import SE3

from kinegami import EndTip, KinematicChain, RevoluteJoint, StartTip
from kinegami.chain.joints import JOINT_KINDS, Joint, register_joint_kind
from kinegami.clearance.solids import chain_parts
from kinegami.design import design_to_dict, dumps_design, loads_design
from kinegami.errors import InvalidTypeError
from kinegami.export.urdf import chain_bodies
from kinegami.validation import check_length
from kinegami.viz.chain_geometry import joint_body_faces


class StraightTube(Joint):
    """A straight piece of tube that does not move (a new kind, for this test): its solid is
    the default hull of its two cross sections, its centreline the default segment."""

    def __init__(self, numSides, r, length, Pose):
        self._set_attribute("length", check_length("length", length, r))
        super().__init__(numSides, r, self.length, Pose)

    def pattern_recipe(self) -> tuple:
        return (("tube", (self.numSides, self.r, self.length)),)

    def design_fields(self) -> dict:
        return {"length": float(self.length)}

    @classmethod
    def design_defaults(cls, r: float) -> dict:
        return {"length": 2.0 * r}

    @classmethod
    def from_design(cls, numSides: int, r: float, pose, fields: dict):
        return cls(numSides, r, fields["length"], pose)


@pytest.fixture
def registered(monkeypatch):
    """StraightTube registered for one test (the registry as it was afterwards)."""
    monkeypatch.setitem(JOINT_KINDS, "StraightTube", None)  # undone after the test
    assert register_joint_kind(StraightTube) is StraightTube
    return StraightTube


def chain_with_a_tube() -> KinematicChain:
    chain = KinematicChain(StartTip(4, 1, SE3(), 1.5))
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        chain.append(StraightTube(4, 1, 3.0, SE3.Trans(0, 0, 6)))
        chain.append(RevoluteJoint(4, 1, math.pi, SE3.Trans(0, 0, 14) * SE3.Ry(math.pi / 2)))
        chain.append(EndTip(4, 1, SE3.Trans(0, 0, 24), 1.5))
    return chain


def test_a_new_kind_is_built_drawn_meshed_and_moved(registered):
    chain = chain_with_a_tube()
    k = next(i for i, joint in enumerate(chain.Joints) if isinstance(joint, StraightTube))
    tube = chain.Joints[k]
    # its pattern, from the catalog modules it names
    pattern = chain.creasePattern()
    assert pattern.numVertices > chain.Joints[0].pattern.numVertices + tube.pattern.numVertices
    # its solid: the hull of both cross sections, drawn and meshed
    assert len(joint_body_faces(tube)) == 6  # a square prism: 4 sides and 2 caps
    part = next(p for p in chain_parts(chain) if p.name == f"joint_{k}")
    assert np.ptp(part.vertices @ tube.pose_matrix[:3, 2]) == pytest.approx(3.0)
    # its centreline in the clearance engine, and the forward kinematics moving it
    assert chain.clearance().ok
    before = tube.pose_matrix.copy()
    j = next(i for i, joint in enumerate(chain.Joints) if isinstance(joint, RevoluteJoint))
    states = [0.0] * len(chain.Joints)
    states[j] = 0.5
    assert chain.setJointStates(states)
    np.testing.assert_array_equal(chain.Joints[k].pose_matrix, before)  # before the joint


def test_a_new_kind_is_saved_and_loaded_and_exported(registered, tmp_path):
    chain = chain_with_a_tube()
    text = dumps_design(design_to_dict(chain, name="tube"))
    assert '"type": "StraightTube"' in text and '"length": 3.0' in text
    loaded = loads_design(text)
    for a, b in zip(loaded.Joints, chain.Joints, strict=True):
        assert type(a) is type(b)
        np.testing.assert_allclose(a.pose_matrix, b.pose_matrix, atol=1e-12)
    # the URDF splits bodies at moving joints only: the tube is fixed in the first body
    revolute = [i for i, joint in enumerate(loaded.Joints) if isinstance(joint, RevoluteJoint)]
    assert chain_bodies(loaded).movable == tuple(revolute)


def test_an_unregistered_kind_is_not_saved_and_bad_kinds_are_refused():
    chain = KinematicChain(StartTip(4, 1, SE3(), 1.5))
    chain.append(StraightTube(4, 1, 3.0, SE3.Trans(0, 0, 6)))
    with pytest.raises(InvalidTypeError, match="cannot save a joint of type StraightTube"):
        design_to_dict(chain)
    with pytest.raises(InvalidTypeError, match="must be a Joint subclass"):
        register_joint_kind(dict)
