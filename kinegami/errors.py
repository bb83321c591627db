"""The kinegami exception hierarchy.

Every error raised on purpose by kinegami is a :class:`KinegamiError`. The subclasses also
inherit the matching builtin, so ``except ValueError`` keeps working (as ezdxf does with
``DXFValueError``).
"""

from __future__ import annotations


class KinegamiError(Exception):
    """Base class of every error kinegami raises on purpose."""


class InvalidParameterError(KinegamiError, ValueError):
    """A parameter has a value outside its valid range (the message names both)."""


class InvalidTypeError(KinegamiError, TypeError):
    """A parameter has the wrong type."""


class JointIndexError(KinegamiError, IndexError):
    """A joint index does not name a joint of the chain."""


class NoPathError(KinegamiError, ValueError):
    """No acceptable CSC link (all turns < pi) joins two frames."""


class IncompatibleJointError(KinegamiError, ValueError):
    """A joint's ``numSides`` or ``r`` differs from the chain's."""


class ClearanceWarning(UserWarning):
    """An operation left the chain passing through itself (it was applied; the message names
    the two parts). ``clearance`` is the overlap (negative, chain units); ``first`` and
    ``second`` name the parts."""

    def __init__(self, message: str, clearance: float = float("nan"), first: str = "",
                 second: str = ""):  # fmt: skip
        super().__init__(message)
        self.clearance = clearance
        self.first = first
        self.second = second
