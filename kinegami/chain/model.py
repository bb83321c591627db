"""KinematicChain: append joints, place them, edit them, set their states.

See docs/theory/chain.md (frames, balls, edits) and docs/placement.md (placement).

The chain holds joints in world coordinates and, for every joint i >= 1, the link ``Links[i]``
from joint i-1's distal Dubins frame to joint i's proximal Dubins frame (``Links[0]`` is the
empty path at the root). Joints and links are values; every operation computes the new lists
and the new bounding ball first and swaps them in only when everything succeeded, so a failed
append, edit or state change leaves the chain bit-identical.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from kinegami.chain.assembly import (
    JointAssembly,
)
from kinegami.chain.joints import Joint
from kinegami.errors import (
    ClearanceWarning,
    PlacementWarning,
)
from kinegami.validation import (
    check_twist_portion,
)

__all__ = ["KinematicChain", "JointAssembly", "PlacementWarning", "ClearanceWarning"]


class KinematicChain(JointAssembly):
    """A serial chain of tubular origami joints joined by CSC links.

    Parameters
    ----------
    startJoint : the root joint (copied; world coordinates).
    maxAnglePerElbow : largest turn of a single elbow fitting, in (0, pi] (default pi/2).

    Examples
    --------
    >>> chain = KinematicChain(StartTip(4, 1, Pose=SE3.Trans(3, 3, 0), length=1.5))
    >>> chain.append(PrismaticJoint(4, 1, 3, 3, np.pi / 4, SE3.Trans(5, 5, 0)))
    2
    """

    @classmethod
    def from_dh(
        cls,
        table,
        numSides: int,
        r: float,
        convention: str = "standard",
        jointTypes=None,
        *,
        placement: str = "compact",
        totalBendingAngle: float = np.pi,
        numSinkLayers: int = 1,
        neutralLength: float | None = None,
        numLayers: int = 3,
        coneAngle: float = np.pi / 4,
        endTip: bool = True,
        tipLength: float | None = None,
        maxAnglePerElbow: float = np.pi / 2,
    ) -> KinematicChain:
        """A chain whose joints move about the axes of a Denavit-Hartenberg table.

        Parameters
        ----------
        table : rows (theta, alpha, a, d), one per joint; radians and the chain's length unit;
            |a| and |d| <= 1e6 r.
        numSides, r : the tube (an even number of sides >= 4, radius > 0).
        convention : ``"standard"`` (joint i moves about z of frame i-1; frame 0 = world) or
            ``"modified"`` (Craig: joint i moves about z of frame i). See :mod:`kinegami.chain.dh`.
        jointTypes : None (all revolute), a string such as ``"RRP"``, or a sequence of
            ``"revolute"``/``"prismatic"``, one per row.
        placement : ``"compact"`` (default; docs/placement.md, DH roll kept) or ``"safe"``
            (docs/placement.md; never fails). Joints only slide along their DH axes.
        totalBendingAngle, numSinkLayers : of every revolute joint (default pi, 1).
        neutralLength, numLayers, coneAngle : of every prismatic joint (default 3r, 3, pi/4).
        endTip : add an EndTip on the tool frame (standard: frame n; modified: frame n
            turned so that the tip points along its x axis), placed like the joints.
        tipLength : the end tip's length (default 1.5 r).
        maxAnglePerElbow : largest turn of one elbow fitting (default pi/2).

        Raises
        ------
        NoPathError
            When compact placement finds no link to a joint (the message suggests 'safe').

        Examples
        --------
        >>> puma = KinematicChain.from_dh(
        ...     [(np.pi/2, -np.pi/2, 0, 0), (0, 0, 431.8, 149.09), (np.pi/2, np.pi/2, -20.32, 0),
        ...      (0, -np.pi/2, 0, 433.07), (0, np.pi/2, 0, 0), (0, 0, 0, 56.25)], 6, 100)
        >>> len(puma.Joints)
        7
        """
        from kinegami.chain.dh import chain_from_dh

        return chain_from_dh(
            cls, table, numSides, r, convention, jointTypes, placement=placement,
            totalBendingAngle=totalBendingAngle, numSinkLayers=numSinkLayers,
            neutralLength=neutralLength, numLayers=numLayers, coneAngle=coneAngle,
            endTip=endTip, tipLength=tipLength, maxAnglePerElbow=maxAnglePerElbow,
        )  # fmt: skip

    @property
    def Parents(self) -> tuple[int, ...]:
        """Parent index of every joint (-1 for the root)."""
        return tuple(self._parent_list())

    def __repr__(self) -> str:
        kinds = ", ".join(type(j).__name__ for j in self._joints)
        return (
            f"KinematicChain({len(self._joints)} joints: {kinds}; "
            f"path length {self.totalPathLength():.6g})"
        )

    # --- building ----------------------------------------------------------------------------
    def append(
        self,
        newJoint: Joint,
        relative: bool = True,
        safe: bool = True,
        fixedPosition: bool = False,
        fixedOrientation: bool = False,
    ) -> int | None:
        """Add ``newJoint`` after the last joint and return its index.

        Parameters
        ----------
        newJoint : the joint; its Pose gives the axis of motion (z). It is copied.
        relative : the Pose is relative to the last joint's Pose (True) or global (False).
        safe : place with the safe algorithm (waypoints; never fails) rather than compact.
        fixedPosition : keep the given position (requires safe=False).
        fixedOrientation : keep the given orientation (requires safe=False).

        Returns the new joint's index, or None (with a PlacementWarning, chain unchanged) when
        no link with turns < pi reaches it.
        """
        return self._place(
            "append", len(self._joints) - 1, newJoint, relative, safe, fixedPosition,
            fixedOrientation,
        )  # fmt: skip

    # --- edits ---------------------------------------------------------------------------------
    def delete(self, jointIndex: int) -> bool:
        """Remove joint ``jointIndex`` and join its neighbours by a new link.

        Deleting the last joint drops it; deleting joint 0 makes joint 1 the root. Returns True,
        or False with a PlacementWarning (chain unchanged) when the new link cannot be built or
        the chain has a single joint.
        """
        j = self._index(jointIndex)
        if len(self._joints) == 1:
            self._reject("delete failed: a chain must keep at least one joint")
            return False

        def build():
            joints = self._joints[:j] + self._joints[j + 1 :]
            links = self._links[:j] + self._links[j + 1 :]
            if j == 0:
                links[0] = self._root_link(joints[0])
            elif j < len(joints):
                links[j] = self._link(joints[j - 1], joints[j])
            return joints, links

        return self._try_edit("delete", build)

    # --- states --------------------------------------------------------------------------------
    def setJointState(self, jointIndex: int, newState: float) -> bool:
        """Set joint ``jointIndex`` to ``newState`` (radians or length); later joints follow.

        Returns False with a PlacementWarning (chain unchanged) if ``newState`` is outside the
        joint's ``stateRange()``. Link shapes never change: downstream links move rigidly.
        """
        j = self._index(jointIndex)
        s = self._state_value(j, newState)
        if s is None:
            return False
        values = [joint.state for joint in self._joints]
        values[j] = s
        joints, links = self._configured(values)  # one motion from home: no drift
        return self._accept("setJointState", joints, links)

    def setJointStates(self, states: Sequence[float]) -> bool:
        """Set every joint's state at once (one value per joint, in index order);
        all-or-nothing (``states``: see :meth:`_state_values`)."""
        values = self._state_values(states)
        if values is None:
            return False
        joints, links = self._configured(values)
        return self._accept("setJointStates", joints, links)

    # --- output --------------------------------------------------------------------------------
    def creasePattern(self, twistPortion: float = 0.2):
        """The chain's tubular crease pattern (docs/fabrication.md) as a TubularPattern."""
        from kinegami.pattern import TubularPattern
        from kinegami.pattern.catalog import build_pieces, check_pattern_size

        twistPortion = check_twist_portion(twistPortion)
        # every link's modules built together (the elbows of the whole chain in one batch)
        pieces = [link.pattern_pieces(self.numSides, twistPortion) for link in self._links[1:]]
        check_pattern_size([p for link in pieces for p in link]
                           + [p for joint in self._joints for p in joint.pattern_pieces()])
        built = iter(build_pieces([piece for link in pieces for piece in link]))
        modules = [self._joints[0].pattern]
        for link, joint in zip(pieces, self._joints[1:], strict=True):
            modules.extend(next(built) for _ in link)
            modules.append(joint.pattern)
        return TubularPattern.concatenate(modules)

    def clearance(self, states=None, margin=None):
        """Self-intersection at the current states or at ``states`` (one per joint), with
        ``margin`` (default: :attr:`margin`): a ClearanceReport (``.ok``, ``.min_clearance``,
        ``.pairs``, ``.verdict()``). See kinegami.clearance."""
        from kinegami.clearance import chain_clearance

        return chain_clearance(self, states, margin=margin)

    def show(self, **options):
        """Draw the chain in 3D with matplotlib; returns (figure, axes). See kinegami.viz."""
        from kinegami.viz.chain_plot import show_chain

        return show_chain(self, **options)
