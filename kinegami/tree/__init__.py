"""Kinematic trees: joints with several children (hands, legged bodies), the tree
construction, and how a tree is fabricated from sheets and junctions (docs/trees.md)."""
