"""Small contracts of the public API: values do not change under the user, keyword spellings."""

import subprocess
import sys

import numpy as np
import pytest

from kinegami import (
    SE3,
    InvalidParameterError,
    KinematicChain,
    PrismaticJoint,
    RevoluteJoint,
    StartTip,
)


def _chain():
    """A start tip and a prismatic joint straight above it (exact poses)."""
    chain = KinematicChain(StartTip(4, 1, SE3(), 1.5))
    joint = PrismaticJoint(4, 1, 3, 3, np.pi / 4, SE3.Trans(0, 0, 6))
    assert chain.append(joint, safe=False, fixedPosition=True, fixedOrientation=True) == 1
    return chain


def test_changing_a_returned_pose_does_not_change_the_joint():
    chain = _chain()
    joint = chain.Joints[-1]
    before = np.array(joint.pose_matrix)
    pose = joint.Pose
    pose.A[0, 3] = 99.0
    np.testing.assert_array_equal(joint.pose_matrix, before)
    np.testing.assert_array_equal(joint.Pose.A, before)


def test_pose_matrix_is_read_only():
    joint = _chain().Joints[-1]
    with pytest.raises(ValueError):
        joint.pose_matrix[0, 3] = 1.0


@pytest.mark.parametrize(
    "method", ["translateJointAlongAxisOfMotion", "rotateJointAboutAxisOfMotion"]
)
@pytest.mark.parametrize("propogate", [True, False])
def test_both_spellings_of_propagate_at_once_are_rejected(method, propogate):
    chain = _chain()
    with pytest.raises(InvalidParameterError, match="only one"):
        getattr(chain, method)(1, 0.1, propogate=propogate, propagate=not propogate)
    with pytest.raises(InvalidParameterError, match="only one"):
        getattr(chain, method)(1, 0.1, propogate, propagate=propogate)


def test_transform_joint_spellings():
    chain = _chain()
    assert chain.transformJoint(1, SE3.Trans(0, 0, 1), propagate=False)
    assert chain.transformJoint(1, SE3.Trans(0, 0, 1), propogate=False)
    assert chain.transformJoint(1, SE3.Trans(0, 0, 1), False)
    with pytest.raises(InvalidParameterError):
        chain.transformJoint(1, SE3.Trans(0, 0, 1), True, propagate=True)


def test_joints_with_equal_parameters_share_their_pattern():
    a = RevoluteJoint(6, 1, np.pi, SE3())
    b = RevoluteJoint(6, 1, np.pi, SE3.Trans(1, 2, 3))
    assert a.pattern is b.pattern
    assert RevoluteJoint(6, 1, np.pi / 2, SE3()).pattern is not a.pattern


def test_command_without_arguments_prints_help():
    done = subprocess.run(
        [sys.executable, "-m", "kinegami.cli"], capture_output=True, text=True, check=True
    )
    assert "usage: kinegami" in done.stdout
    done = subprocess.run(
        [sys.executable, "-m", "kinegami.cli", "--version"],
        capture_output=True,
        text=True,
        check=True,
    )
    assert done.stdout.startswith("kinegami ")


def _fresh(code: str) -> str:
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    return done.stdout.strip()


def test_export_is_a_function_and_kinegami_export_a_plain_package():
    import inspect

    import kinegami
    from kinegami import export

    assert inspect.isfunction(export) and kinegami.export is export
    package = sys.modules["kinegami.export"]
    assert not callable(package)  # no callable module
    from kinegami.export import (  # the public names of the package stay importable
        EXPORTERS,
        ExportError,
        known_formats,
        register_exporter,
        save_pattern,
        write_atomic,
        write_atomic_bytes,
    )

    assert package.export is export
    assert all((EXPORTERS, ExportError, known_formats, register_exporter, save_pattern,
                write_atomic, write_atomic_bytes))  # fmt: skip


def test_importing_kinegami_imports_no_heavy_library():
    # nor the standard modules that cost milliseconds: shutil (bz2, lzma), dataclasses
    # (inspect), tempfile, secrets; `import kinegami` is about 10 ms (docs/architecture.md)
    heavy = ("numpy", "spatialmath", "scipy", "matplotlib", "ezdxf", "trimesh", "jsonschema",
             "shutil", "dataclasses", "inspect", "tempfile", "secrets")  # fmt: skip
    code = f"import sys, kinegami\nprint([m for m in {heavy!r} if m in sys.modules])"
    assert _fresh(code) == "[]"


def test_star_import_gives_every_name_of_the_paper():
    code = (
        "from kinegami import *\nimport kinegami, spatialmath, numpy\n"
        "missing = [n for n in kinegami.__all__ if n not in globals()]\n"
        "print(missing, SE3 is spatialmath.SE3, np is numpy, callable(export))"
    )
    assert _fresh(code) == "[] True True True"


def test_unknown_attribute_of_the_package_is_an_attribute_error():
    import kinegami

    with pytest.raises(AttributeError, match="no_such_name"):
        kinegami.no_such_name  # noqa: B018
    assert "KinematicChain" in dir(kinegami)
