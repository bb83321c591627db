"""Fixtures of the sheet, export and pattern-plot tests: a headless backend, sample patterns."""

import matplotlib

matplotlib.use("Agg")

import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import pytest  # noqa: E402

from kinegami import pattern as catalog  # noqa: E402
from kinegami.pattern import TubularPattern  # noqa: E402

from .reference_values import COMPOSITE_MODULES  # noqa: E402


@pytest.fixture(autouse=True)
def _close_figures():
    yield
    plt.close("all")


def build(spec: tuple) -> TubularPattern:
    """A catalog pattern from ``(function name, args)``."""
    name, args = spec
    return getattr(catalog, name)(*args)


def build_composite(n: int) -> TubularPattern:
    """Tube(1) + Twist(0.5, 0.5) + Elbow(pi/2, pi/3) + Revolute(pi) + Tube(1), r = 1 (spec 7.4)."""
    return TubularPattern.concatenate(build((name, (n, *args))) for name, args in COMPOSITE_MODULES)


def build_long_pattern(joints: int = 32, n: int = 6) -> TubularPattern:
    """A chain-like pattern of 5 modules per joint plus two tips (~9000 drawn lines for 32)."""
    rng = np.random.default_rng(1)
    mods = [catalog.StartTipPattern(n, 1.0, 1.5)]
    for j in range(joints):
        mods += [
            catalog.TubeFittingPattern(n, 1.0, rng.uniform(0.5, 2.0)),
            catalog.TwistFittingPattern(n, 1.0, rng.uniform(-3.0, 3.0), 0.5),
            catalog.ElbowFittingPattern(n, 1.0, rng.uniform(0.3, 1.5), rng.uniform(0.0, 6.0)),
            catalog.ElbowFittingPattern(n, 1.0, rng.uniform(0.3, 1.5), rng.uniform(0.0, 6.0)),
        ]
        if j % 2 == 0:
            mods.append(catalog.RevoluteJointPattern(n, 1.0, np.pi, 1))
        else:
            mods.append(catalog.PrismaticJointPattern(n, 1.0, 2.0, 2, np.pi / 4))
    mods.append(catalog.EndTipPattern(n, 1.0, 1.5))
    return TubularPattern.concatenate(mods)


@pytest.fixture(scope="session")
def composite6() -> TubularPattern:
    return build_composite(6)


@pytest.fixture(scope="session")
def revolute6() -> TubularPattern:
    return catalog.RevoluteJointPattern(6, 1.0, np.pi, 1)


@pytest.fixture(scope="session")
def long_pattern() -> TubularPattern:
    return build_long_pattern()
