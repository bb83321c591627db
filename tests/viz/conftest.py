"""Fixtures for the drawing tests: a headless backend, the paper's example 1A, cleanup."""

import matplotlib

matplotlib.use("Agg")

import matplotlib.pyplot as plt  # noqa: E402
import pytest  # noqa: E402

from kinegami import (  # noqa: E402
    SE3,
    EndTip,
    KinematicChain,
    PrismaticJoint,
    RevoluteJoint,
    StartTip,
    np,
)


@pytest.fixture(autouse=True)
def _close_figures():
    yield
    plt.close("all")


def build_example_1a() -> KinematicChain:
    """Example 1A of the paper (chain.md 11.2)."""
    chain = KinematicChain(StartTip(4, 1, Pose=SE3.Trans(3, 3, 0), length=1.5))
    chain.append(
        PrismaticJoint(
            4, 1, neutralLength=3, numLayers=3, coneAngle=np.pi / 4, Pose=SE3.Trans([5, 5, 0])
        )
    )
    chain.append(RevoluteJoint(4, 1, np.pi, SE3.Ry(np.pi / 4)))
    chain.append(EndTip(4, 1, Pose=SE3.Ry(np.pi / 2), length=1.5))
    return chain


def build_long_chain(num_joints: int = 50) -> KinematicChain:
    """A chain of at least ``num_joints`` joints (revolute and prismatic, safe placement)."""
    chain = KinematicChain(StartTip(6, 1, Pose=SE3(), length=1.5))
    i = 0
    while len(chain) < num_joints:
        if i % 2 == 0:
            joint = RevoluteJoint(6, 1, np.pi, SE3.Rz(0.7 * i) * SE3.Ry(np.pi / 3))
        else:
            joint = PrismaticJoint(6, 1, 2, 2, np.pi / 4, SE3.Rx(0.5 * i) * SE3.Trans(2, 0, 0))
        assert chain.append(joint) is not None
        i += 1
    return chain


@pytest.fixture(scope="session")
def example_1a() -> KinematicChain:
    return build_example_1a()


@pytest.fixture
def straight_chain() -> KinematicChain:
    """A StartTip and an EndTip on one axis: every link straight, no elbow anywhere."""
    chain = KinematicChain(StartTip(4, 1, Pose=SE3(), length=1.5))
    chain.append(
        EndTip(4, 1, Pose=SE3.Trans(0, 0, 6), length=1.5),
        safe=False,
        fixedPosition=True,
        fixedOrientation=True,
    )
    return chain
