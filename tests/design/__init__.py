"""Tests of kinegami.design (design files). Shared helpers: chain comparison, random chains."""

from __future__ import annotations

import math
import warnings
from pathlib import Path

import numpy as np
from hypothesis import strategies as st
from spatialmath import SE3

from kinegami import (
    EndTip,
    ExtendedRevoluteJoint,
    KinematicChain,
    PlacementWarning,
    PrismaticJoint,
    RevoluteJoint,
    StartTip,
    Waypoint,
)

DATA = Path(__file__).parent / "data"
PI = math.pi


def located(error) -> str:
    """The ``<field>: `` part of a DesignError's message (left out for the whole document)."""
    return "" if error.field == "$" else f"{error.field}: "


def pose_error(a: KinematicChain, b: KinematicChain) -> float:
    """Largest joint pose difference, relative to max(1, |coordinate|) (0 for equal chains)."""
    worst = 0.0
    for ja, jb in zip(a.Joints, b.Joints, strict=True):
        A, B = ja.pose_matrix, jb.pose_matrix
        scale = np.maximum(1.0, np.maximum(np.abs(A), np.abs(B)))
        worst = max(worst, float(np.max(np.abs(A - B) / scale)))
    return worst


def joint_parameters(joint) -> tuple:
    """Type, constructor parameters and state of a joint (what a design file stores)."""
    params = {
        RevoluteJoint: ("totalBendingAngle", "numSinkLayers"),
        ExtendedRevoluteJoint: ("totalBendingAngle", "numSinkLayers", "tubeLength"),
        PrismaticJoint: ("neutralLength", "numLayers", "coneAngle"),
        StartTip: ("length",),
        EndTip: ("length",),
        Waypoint: (),
    }[type(joint)]
    values = tuple(getattr(joint, name) for name in params)
    return (type(joint).__name__, values, joint.pathIndex(), joint.numSides, joint.r, joint.state)


def assert_same_chain(a: KinematicChain, b: KinematicChain, pose_tol: float = 1e-12) -> float:
    """Same joints (types, parameters, states), poses within ``pose_tol``, same links (1e-9).

    Returns the pose error measured.
    """
    assert len(a.Joints) == len(b.Joints), (a, b)
    assert [joint_parameters(j) for j in a.Joints] == [joint_parameters(j) for j in b.Joints]
    assert a.numSides == b.numSides and a.r == b.r
    assert a.maxAnglePerElbow == b.maxAnglePerElbow
    error = pose_error(a, b)
    assert error <= pose_tol, f"pose error {error:.3g} > {pose_tol:.3g}"
    for la, lb in zip(a.Links, b.Links, strict=True):
        pa, pb = la.path, lb.path
        scale = max(1.0, pa.length)
        assert abs(pa.theta1 - pb.theta1) <= 1e-9, (pa.theta1, pb.theta1)
        assert abs(pa.theta2 - pb.theta2) <= 1e-9, (pa.theta2, pb.theta2)
        assert abs(pa.tMag - pb.tMag) <= 1e-9 * scale, (pa.tMag, pb.tMag)
    return error


# --- random chains -----------------------------------------------------------------------------
def _pose(draw, r: float, reach: float = 8.0) -> SE3:
    angle = st.floats(-PI, PI, allow_nan=False)
    t = [draw(st.floats(-reach, reach, allow_nan=False)) * r for _ in range(3)]
    return SE3.Trans(*t) * SE3.Rz(draw(angle)) * SE3.Ry(draw(angle)) * SE3.Rx(draw(angle))


def _joint(draw, kind: str, n: int, r: float, pose: SE3):
    if kind == "RevoluteJoint":
        bend = draw(st.floats(0.2, 2 * PI - 0.2))
        return RevoluteJoint(n, r, bend, pose, numSinkLayers=draw(st.integers(1, 3)))
    if kind == "ExtendedRevoluteJoint":
        bend = draw(st.floats(0.2, 2 * PI - 0.2))
        tube = draw(st.floats(0.1, 3.0)) * r
        return ExtendedRevoluteJoint(n, r, bend, tube, pose, draw(st.integers(1, 3)))
    if kind == "PrismaticJoint":
        length = draw(st.floats(0.5, 5.0)) * r
        cone = draw(st.floats(PI / 6, PI / 2 - 0.05))
        return PrismaticJoint(n, r, length, draw(st.integers(1, 5)), cone, pose)
    if kind == "Waypoint":
        return Waypoint(n, r, pose, draw(st.sampled_from([0, 1, 2])))
    cls = StartTip if kind == "StartTip" else EndTip
    return cls(n, r, Pose=pose, length=draw(st.floats(0.2, 3.0)) * r)


_MIDDLE = ["RevoluteJoint", "ExtendedRevoluteJoint", "PrismaticJoint", "Waypoint"]


def _quietly(method, *args, **kwargs):
    """Call a chain method, ignoring a rejection (PlacementWarning)."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", PlacementWarning)
        return method(*args, **kwargs)


@st.composite
def random_chains(draw, max_joints: int = 5, states: bool = True) -> KinematicChain:
    """Chains of random joints placed in every mode, with a few edits and random states."""
    n = draw(st.sampled_from([4, 6, 8]))
    r = draw(st.floats(0.5, 3.0))
    root_kind = draw(st.sampled_from(["StartTip", *_MIDDLE]))
    chain = KinematicChain(
        _joint(draw, root_kind, n, r, _pose(draw, r)),
        maxAnglePerElbow=draw(st.sampled_from([PI / 2, PI / 3, PI])),
    )
    count = draw(st.integers(1, max_joints))
    for k in range(count):
        last = k == count - 1 and draw(st.booleans())
        kind = "EndTip" if last else draw(st.sampled_from(_MIDDLE))
        joint = _joint(draw, kind, n, r, _pose(draw, r))
        safe = draw(st.booleans())
        fixed = (False, False) if safe else (draw(st.booleans()), draw(st.booleans()))
        options = dict(
            relative=draw(st.booleans()),
            safe=safe,
            fixedPosition=fixed[0],
            fixedOrientation=fixed[1],
        )
        _quietly(chain.append, joint, **options)
    for _ in range(draw(st.integers(0, 3))):
        size = len(chain.Joints)
        index = draw(st.integers(0, size - 1))
        op = draw(st.sampled_from(["translate", "rotate", "transform", "all", "delete"]))
        prop = draw(st.booleans())
        if op == "translate":
            d = draw(st.floats(-3, 3)) * r
            _quietly(chain.translateJointAlongAxisOfMotion, index, d, propagate=prop)
        elif op == "rotate":
            a = draw(st.floats(-PI, PI))
            _quietly(chain.rotateJointAboutAxisOfMotion, index, a, propagate=prop)
        elif op == "transform":
            T = _pose(draw, r, reach=1.0)
            _quietly(chain.transformJoint, index, T, propagate=prop)
        elif op == "all":
            chain.transformAll(_pose(draw, r))
        elif size > 1:
            _quietly(chain.delete, index)
    if states:
        values = []
        for joint in chain.Joints:
            lo, hi = joint.stateRange()
            f = draw(st.sampled_from([None, 0.0, 1.0, 0.5, 0.9, 0.1]))
            values.append(0.0 if f is None else min(hi, max(lo, lo + f * (hi - lo))))
        assert chain.setJointStates(values)
    return chain
