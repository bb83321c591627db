"""Kinematic trees: joints with several children (hands, legged bodies), the tree
construction, and how a tree is fabricated from sheets and junctions (docs/trees.md).

``KinematicTree`` (published name) is the model; a ``KinematicChain`` is the tree in which each
joint's parent is the joint before it.
"""

from kinegami.tree.model import KinematicTree

__all__ = ["KinematicTree"]
