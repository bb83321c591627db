"""The limits of kinegami.limits (docs/limits.md), enforced where input enters: each value
beyond a limit is a one-line InvalidParameterError (a ValueError) naming the value, the limit and
why, raised before any work is done, and a chain that refuses it is left bit-identical."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from spatialmath import SE3

from kinegami import (
    InvalidParameterError,
    KinegamiError,
    KinematicChain,
    KinematicTree,
    LinkCSC,
    PrismaticJoint,
    RevoluteJoint,
    StartTip,
    Waypoint,
    limits,
)
from kinegami.design import limits as design_limits
from kinegami.optimize import compact
from kinegami.pattern.prismatic import PrismaticJointPattern
from kinegami.pattern.revolute import RevoluteJointPattern
from kinegami.validation import check_samples

DOCS = Path(__file__).resolve().parents[1] / "docs" / "limits.md"


def _one_line(excinfo, *words) -> str:
    error = excinfo.value
    assert isinstance(error, KinegamiError) and isinstance(error, ValueError)
    text = str(error)
    assert "\n" not in text and len(text) < 400, text
    for word in words:
        assert word in text, (word, text)
    return text


# --- one table --------------------------------------------------------------------------------
def test_docs_limits_lists_every_limit_with_its_value():
    text = DOCS.read_text(encoding="utf-8")
    for name in limits.__all__:
        row = [line for line in text.splitlines() if f"`{name}`" in line and line.startswith("|")]
        assert row, f"{name} is not in docs/limits.md's table"
        value = getattr(limits, name)
        shown = {f"{value:,}", f"{value:g}", str(value), f"{value:_}"} if not isinstance(
            value, float) or value.is_integer() else {f"{value:g}", "pi/180", "π/180"}  # fmt: skip
        assert any(s in row[0] for s in shown), (name, value, row[0])


def test_the_design_files_and_the_api_share_the_numbers():
    for name in ("R_MIN", "R_MAX", "LENGTH_FACTOR", "NUM_SINK_LAYERS_MAX", "NUM_LAYERS_MAX",
                 "MIN_ANGLE_PER_ELBOW", "MAX_JOINTS", "MAX_FILE_BYTES", "MAX_DEPTH"):  # fmt: skip
        assert getattr(design_limits, name) is getattr(limits, name)
    assert design_limits.NUM_SIDES_MAX == limits.FILE_NUM_SIDES_MAX


# --- elbows -----------------------------------------------------------------------------------
@pytest.mark.parametrize("angle", [1e-9, 1e-4, math.pi / 181, 0.0, -1.0, math.pi * 1.01])
def test_max_angle_per_elbow_below_one_degree_is_refused(angle):
    """1e-9 rad asked numpy for 167 GiB (1.4e9 elbows in one arc)."""
    start = StartTip(4, 1, SE3(), 1)
    with pytest.raises(InvalidParameterError) as info:
        KinematicChain(start, maxAnglePerElbow=angle)
    _one_line(info, "maxAnglePerElbow", "[pi/180, pi]", "MIN_ANGLE_PER_ELBOW", repr(float(angle)))
    with pytest.raises(InvalidParameterError):
        KinematicTree(Waypoint(4, 1, SE3()), maxAnglePerElbow=angle)
    with pytest.raises(InvalidParameterError):
        LinkCSC(1, SE3(), SE3.Trans(10, 3, 0), angle)


def test_one_degree_per_elbow_builds():
    chain = KinematicChain(StartTip(4, 1, SE3(), 1), maxAnglePerElbow=limits.MIN_ANGLE_PER_ELBOW)
    k = chain.append(RevoluteJoint(4, 1, math.pi, SE3.Trans(5, 5, 0) * SE3.Ry(1)))
    assert k is not None
    counts = [link.elbows1.count + link.elbows2.count for link in chain.Links]
    assert 0 < max(counts) <= 2 * 360
    assert chain.creasePattern().numVertices > 0


# --- layers -----------------------------------------------------------------------------------
@pytest.mark.parametrize("layers", [limits.NUM_SINK_LAYERS_MAX + 1, 10**7, 10**400])
def test_sink_layers_beyond_the_limit(layers):
    """10**7 layers ran past a minute and 2 GB before any answer."""
    with pytest.raises(InvalidParameterError) as info:
        RevoluteJoint(4, 1, math.pi, SE3(), numSinkLayers=layers)
    _one_line(info, "numSinkLayers", "[1, 32]", "NUM_SINK_LAYERS_MAX", "got ")
    with pytest.raises(InvalidParameterError):
        RevoluteJointPattern(4, 1.0, math.pi, numSinkLayers=layers)


@pytest.mark.parametrize("layers", [limits.NUM_LAYERS_MAX + 1, 10**7])
def test_rebo_layers_beyond_the_limit(layers):
    with pytest.raises(InvalidParameterError) as info:
        PrismaticJoint(4, 1, 3, layers, math.pi / 4, SE3())
    _one_line(info, "numLayers", "[1, 200]", "NUM_LAYERS_MAX", str(layers))
    with pytest.raises(InvalidParameterError):
        PrismaticJointPattern(4, 1.0, 3.0, layers, math.pi / 4)


def test_layers_at_the_limit_build():
    assert RevoluteJoint(4, 1, math.pi, SE3(), numSinkLayers=32).numSinkLayers == 32
    assert PrismaticJoint(4, 1, 30, 200, math.pi / 4, SE3()).numLayers == 200


def test_a_refused_joint_leaves_the_chain_identical(example_1a, snapshot):
    before = snapshot(example_1a)
    with pytest.raises(InvalidParameterError):
        example_1a.append(RevoluteJoint(4, 1, math.pi, SE3.Trans(9, 0, 0), numSinkLayers=33))
    assert snapshot(example_1a) == before


# --- samples and starts -----------------------------------------------------------------------
def test_samples_beyond_the_limits():
    assert check_samples("samples", limits.MAX_SAMPLES, 10) == limits.MAX_SAMPLES
    with pytest.raises(InvalidParameterError) as info:
        check_samples("samples", limits.MAX_SAMPLES + 1, 1)
    _one_line(info, "samples", "[1, 100000]", "MAX_SAMPLES", "100001")
    with pytest.raises(InvalidParameterError) as info:
        check_samples("samples", 100_000, 101)
    _one_line(info, "10100000 sampled states", "MAX_SAMPLED_STATES", "at most 99009")


def test_compact_refuses_samples_and_starts_beyond_the_limits(example_1a, snapshot):
    before = snapshot(example_1a)
    with pytest.raises(InvalidParameterError) as info:
        compact(example_1a, samples=10**9, motion=True)
    _one_line(info, "samples", "MAX_SAMPLES")
    with pytest.raises(InvalidParameterError) as info:
        compact(example_1a, starts=limits.MAX_STARTS + 1)
    _one_line(info, "starts", "MAX_STARTS", str(limits.MAX_STARTS + 1))
    assert snapshot(example_1a) == before


def test_the_limits_are_numbers_that_keep_allocations_small():
    # the sampled states of one motion check: 80 MB at most
    assert limits.MAX_SAMPLED_STATES * 8 <= 100 * 2**20
    # a link has at most 2 arcs of at most 2 pi, so at most 720 elbows
    assert 2 * math.ceil(2 * math.pi / limits.MIN_ANGLE_PER_ELBOW) == 720
    assert np.isclose(limits.MIN_ANGLE_PER_ELBOW, math.radians(1))


# --- one line -----------------------------------------------------------------------------------
def test_a_kinegami_error_is_one_line_whatever_its_message_holds():
    """Messages that held the repr of a numpy array printed several lines (a non-rigid Pose
    printed five)."""
    from kinegami.errors import DesignError, ExportError, InvalidTypeError

    text = f"got {np.eye(3)!r}\r\n\u2028end"
    for error in (KinegamiError(text), InvalidParameterError(text), InvalidTypeError(text),
                  ExportError(text)):  # fmt: skip
        assert str(error) == "got array([[1., 0., 0.], [0., 1., 0.], [0., 0., 1.]]) end"
    assert str(InvalidParameterError("keeps  its  spaces")) == "keeps  its  spaces"
    assert "\n" not in str(DesignError("a\nb", field="r", value="x\ny", file="d\n.json"))


def test_a_pose_that_is_not_rigid_is_named_in_one_line():
    with pytest.raises(InvalidParameterError) as info:
        RevoluteJoint(4, 1, math.pi, np.diag([1.0, 2.0, 3.0, 1.0]))
    _one_line(info, "Pose", "proper rigid transform", "[[1.0, 0.0, 0.0, 0.0], [0.0, 2.0")
    from kinegami.pattern.folded import folded_vertices

    chain = KinematicChain(StartTip(4, 1, SE3(), 1))
    with pytest.raises(InvalidParameterError) as info:
        folded_vertices(chain, frame=np.diag([1.0, 1.0, 2.0, 1.0]))
    _one_line(info, "frame", "rigid")


# --- positions a design file can hold --------------------------------------------------------
def _far_design(step: float) -> dict:
    joint = {"type": "Waypoint", "safe": False, "pose": [{"Trans": [step, 0, 0]}]}
    return {"format": "kinegami-design", "version": 1, "numSides": 4, "r": 1,
            "joints": [{"type": "StartTip", "length": 1.5}, joint, joint,
                       {"type": "EndTip", "length": 1.5, "safe": False,
                        "pose": [{"Trans": [3, 0, 0]}]}]}  # fmt: skip


def test_a_design_whose_steps_add_up_beyond_1e6_r_is_refused():
    """Each step within 1e6 r, two of them 1.8e6 r from the origin: such a chain could not be
    written back (the writer holds every joint's position to 1e6 r)."""
    from kinegami.design import DesignError, chain_from_dict, design_to_dict, dumps_design

    chain = chain_from_dict(_far_design(4.5e5))  # 9e5 r: loads, and can be saved
    dumps_design(design_to_dict(chain))
    with pytest.raises(DesignError) as info:
        chain_from_dict(_far_design(9e5), "far.json")
    error = info.value
    assert error.field == "joints[2]"
    _one_line(info, "far.json: joints[2]: out of range: joint 2", "x = 1.8e+06", "LENGTH_FACTOR")


def test_the_editor_refuses_a_command_that_puts_a_joint_beyond_1e6_r():
    from kinegami.design import chain_from_dict
    from kinegami.editor import EditorModel
    from kinegami.editor.document import Document

    model = EditorModel(Document.from_chain(chain_from_dict(_far_design(4e5))))
    before = model.to_design_text()
    far = np.eye(4)
    far[0, 3] = 5e5  # the last joint, at x = 8e5 + 3 r, would go to 1.3e6 r
    result = model.transform_all(far)
    assert not result.ok and "beyond +-1e6 r" in result.reason and "\n" not in result.reason
    assert model.to_design_text() == before
    far[0, 3] = 1e5
    assert model.transform_all(far).ok  # within the bound: done
