"""kinegami: tubular origami kinematic chains and their crease patterns."""

from kinegami.errors import (
    IncompatibleJointError,
    InvalidParameterError,
    InvalidTypeError,
    JointIndexError,
    KinegamiError,
    NoPathError,
)

__version__ = "0.1.0"

__all__ = [
    "KinegamiError",
    "InvalidParameterError",
    "InvalidTypeError",
    "JointIndexError",
    "NoPathError",
    "IncompatibleJointError",
]
