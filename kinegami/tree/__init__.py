"""Kinematic trees: joints with several children (hands, legged bodies) and the tree
construction (docs/trees.md). How a tree is made from sheets and junctions is
:mod:`kinegami.fabrication`.

``KinematicTree`` (published name) is the model; a ``KinematicChain`` is the tree in which each
joint's parent is the joint before it. ``from_specification`` builds a tree from a joint
specification (``JointSpecificationTree``, published name, or a file read by
``load_joint_specification``).
"""

from kinegami.tree.construction import (
    JointSpecification,
    JointSpecificationTree,
    TreeConstruction,
    from_specification,
    load_joint_specification,
)
from kinegami.tree.model import KinematicTree

__all__ = [
    "KinematicTree",
    "JointSpecification",
    "JointSpecificationTree",
    "TreeConstruction",
    "from_specification",
    "load_joint_specification",
]
