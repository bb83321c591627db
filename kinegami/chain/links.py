"""Links: CSC Dubins paths turned into elbow, twist and tube fittings (docs/theory/chain.md §3).

A link joins a start Dubins frame (the parent joint's distal Dubins frame) to an end Dubins
frame (the child's proximal Dubins frame). Frames are 4x4 arrays in world coordinates whose x
axis is the path tangent. Each arc of the path is realised by ``ceil(theta / maxAnglePerElbow)``
equal elbows; the straight part by a tube, preceded by a twist when the roll of the frame
carried along the path differs from the end frame's roll.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import cached_property
from typing import TYPE_CHECKING

import numpy as np

from kinegami.chain.joints import as_se3, pose_array
from kinegami.errors import InvalidParameterError, InvalidTypeError, NoPathError
from kinegami.geometry.balls import Ball, merge_balls
from kinegami.geometry.csc import CSCPath, solve_csc
from kinegami.geometry.frames import rotation_matrix, signed_angle
from kinegami.validation import (
    ReadOnlyAttributes,
    check_max_angle_per_elbow,
    check_num_sides,
    check_radius,
    check_twist_portion,
)

if TYPE_CHECKING:
    from spatialmath import SE3

__all__ = ["LinkCSC", "ElbowArc", "ELBOW_MIN_ANGLE", "TWIST_MIN_ANGLE"]

#: Arcs turning more than this get elbows (docs/theory/chain.md §3: no skipped small turns).
ELBOW_MIN_ANGLE = 1e-9
#: A straight part gets a twist fitting when |twist| exceeds this (docs/theory/chain.md §3).
TWIST_MIN_ANGLE = 0.01
#: Arcs and twists up to this angle are left out of the crease pattern (docs/theory/patterns.md §3).
PATTERN_MIN_ANGLE = 0.01


@dataclass(frozen=True, eq=False)
class ElbowArc:
    """One arc of a link realised as ``count`` equal elbows.

    Attributes
    ----------
    angle : total turn of the arc (radians); ``count`` elbows of ``angle / count`` each.
    rotationalAxisAngle : phi, the angle of the rotation axis from the start frame's y axis
        about its x axis (radians).
    frames : (count + 1, 4, 4) read-only array, the start frame and the frame after each elbow.
    """

    angle: float
    count: int
    rotationalAxisAngle: float
    frames: np.ndarray
    r: float

    def __post_init__(self) -> None:
        self.frames.setflags(write=False)  # the arc is a value: its frames too

    @property
    def elbowAngle(self) -> float:
        """Turn of one elbow (radians)."""
        return self.angle / self.count if self.count else 0.0

    def vertices(self) -> np.ndarray:
        """(count, 3) array: the vertex (tangent-line intersection) of each elbow."""
        if self.count == 0:
            return np.zeros((0, 3))
        delta = self.r * math.tan(self.elbowAngle / 2.0)
        return self.frames[:-1, :3, 3] + delta * self.frames[:-1, :3, 0]

    def bounding_ball(self) -> Ball | None:
        """Fold-merge of the elbow balls, or None if the arc has no elbow.

        See docs/theory/chain.md §2.
        """
        if self.count == 0:
            return None
        radius = self.r * math.hypot(math.tan(self.elbowAngle / 2.0), 1.0)
        verts = self.vertices()
        ball = Ball(verts[0], radius)
        for v in verts[1:]:
            ball = merge_balls(ball, Ball(v, radius))
        return ball

    def transformed(self, T: np.ndarray) -> ElbowArc:
        """The arc moved rigidly by T."""
        return ElbowArc(self.angle, self.count, self.rotationalAxisAngle, T @ self.frames, self.r)


def _elbow_arc(
    start: np.ndarray, theta: float, axis: np.ndarray, max_angle: float, r: float
) -> ElbowArc:
    """Split a turn of ``theta`` about world ``axis`` starting at frame ``start`` into elbows."""
    if theta <= ELBOW_MIN_ANGLE:
        return ElbowArc(0.0 if theta <= 0 else theta, 0, 0.0, start[None].copy(), r)
    phi = signed_angle(start[:3, 1], axis, start[:3, 0])
    count = max(1, math.ceil(theta / max_angle - 1e-12))
    alpha = theta / count
    delta = r * math.tan(alpha / 2.0)
    local_axis = (0.0, math.cos(phi), math.sin(phi))
    step = np.eye(4)
    step[:3, :3] = rotation_matrix(local_axis, alpha)
    # Trans(delta x) Rot Trans(delta x)
    step[:3, 3] = np.array([delta, 0.0, 0.0]) + step[:3, :3] @ np.array([delta, 0.0, 0.0])
    frames = np.empty((count + 1, 4, 4))
    frames[0] = start
    for j in range(count):
        frames[j + 1] = frames[j] @ step
    return ElbowArc(theta, count, phi, frames, r)


def _readonly(F: np.ndarray) -> np.ndarray:
    F.setflags(write=False)
    return F


def _solved_path(r: float, start: np.ndarray, end: np.ndarray) -> CSCPath:
    path = solve_csc(start[:3, 3], start[:3, 0], end[:3, 3], end[:3, 0], r)
    if path is None:
        raise NoPathError(
            "no CSC path with both turns < pi joins the start frame at "
            f"{np.round(start[:3, 3], 6).tolist()} (direction "
            f"{np.round(start[:3, 0], 6).tolist()}) to the end frame at "
            f"{np.round(end[:3, 3], 6).tolist()} (direction {np.round(end[:3, 0], 6).tolist()})"
        )
    return path


class LinkCSC(ReadOnlyAttributes):
    """A link: the CSC Dubins path from ``StartDubinsPose`` to ``EndDubinsPose``.

    Links are values: assigning or deleting a public attribute (``link.r = 5``) raises
    :class:`~kinegami.errors.ReadOnlyError` (docs/errors.md).

    Parameters
    ----------
    r : tube radius = turning radius, in [1e-6, 1e6].
    StartDubinsPose, EndDubinsPose : SE3 (or 4x4 arrays), x axis = path tangent; their
        translations lie within +-1e6 r.
    maxAnglePerElbow : largest turn of one elbow, in (0, pi] (default pi/2).

    Raises NoPathError (a ValueError) when no path with both turns < pi exists.

    Examples
    --------
    >>> link = LinkCSC(1, SE3(), SE3.Trans(10, 4, 0))
    >>> round(link.path.length, 6)
    10.789582
    """

    r: float
    maxAnglePerElbow: float
    path: CSCPath

    _READ_ONLY_ADVICE = (
        "links are values; build a new LinkCSC(r, StartDubinsPose, EndDubinsPose, "
        "maxAnglePerElbow), or edit the chain's joints (translateJointAlongAxisOfMotion, "
        "transformJoint, setJointState, ...) and it builds new links"
    )

    def __init__(self, r, StartDubinsPose, EndDubinsPose, maxAnglePerElbow=np.pi / 2):
        r = check_radius(r)
        max_angle = check_max_angle_per_elbow(maxAnglePerElbow)
        start = pose_array(StartDubinsPose, "StartDubinsPose", r=r)
        end = pose_array(EndDubinsPose, "EndDubinsPose", r=r)
        self._init(r, max_angle, start, end, _solved_path(r, start, end))

    @classmethod
    def _between(cls, r, max_angle, start: np.ndarray, end: np.ndarray) -> LinkCSC:
        """The link between two frames the chain computed (already checked: rigid, finite;
        not held to the +-1e6 r bound of user poses). Raises NoPathError."""
        start = np.array(start, dtype=float)
        end = np.array(end, dtype=float)
        start.setflags(write=False)
        end.setflags(write=False)
        return cls._from_parts(r, max_angle, start, end, _solved_path(r, start, end))

    @classmethod
    def from_path(
        cls, r, StartDubinsPose, EndDubinsPose, path: CSCPath, maxAnglePerElbow=np.pi / 2
    ) -> LinkCSC:
        """The link along a given CSC path (e.g. one of ``solve_csc_all``'s), without re-solving.

        The path must join the two frames: start at the start frame's origin along its x axis and
        end at the end frame's origin along its x axis (within 1e-9 r and 1e-9), with turning
        radius ``r``; InvalidParameterError otherwise.

        Examples
        --------
        >>> from kinegami.geometry.csc import solve_csc_all
        >>> end = SE3.Trans(10, 4, 0)
        >>> paths = solve_csc_all((0, 0, 0), (1, 0, 0), (10, 4, 0), (1, 0, 0), 1.0)
        >>> round(LinkCSC.from_path(1, SE3(), end, paths[0]).length, 6)
        10.789582
        """
        r = check_radius(r)
        max_angle = check_max_angle_per_elbow(maxAnglePerElbow)
        start = pose_array(StartDubinsPose, "StartDubinsPose")
        end = pose_array(EndDubinsPose, "EndDubinsPose")
        if not isinstance(path, CSCPath):
            raise InvalidTypeError(f"path must be a CSCPath, got {type(path).__name__}")
        if abs(path.r - r) > 1e-12 * r:
            raise InvalidParameterError(f"path has turning radius {path.r}, the link r = {r}")
        scale = max(1.0, float(np.max(np.abs(end[:3, 3] - start[:3, 3]))) / r)
        for name, frame, point, tangent in (
            ("start", start, path.p1, path.d1),
            ("end", end, path.p2, path.d2),
        ):
            if (
                float(np.max(np.abs(point - frame[:3, 3]))) > 1e-9 * r * scale
                or float(np.max(np.abs(tangent - frame[:3, 0]))) > 1e-9
            ):
                raise InvalidParameterError(
                    f"path does not meet the {name} frame: it passes "
                    f"{np.round(point, 6).tolist()} along {np.round(tangent, 6).tolist()}, "
                    f"the frame is at {np.round(frame[:3, 3], 6).tolist()} with x axis "
                    f"{np.round(frame[:3, 0], 6).tolist()}"
                )
        return cls._from_parts(r, max_angle, start, end, path)

    def _init(self, r, max_angle, start, end, path):
        self._set_attribute("r", r)
        self._set_attribute("maxAnglePerElbow", max_angle)
        self._start = start
        self._end = end
        self._set_attribute("path", path)

    @classmethod
    def _from_parts(cls, r, max_angle, start, end, path) -> LinkCSC:
        link = object.__new__(cls)
        link._init(r, max_angle, start, end, path)
        return link

    # --- published frames ------------------------------------------------------------------
    @property
    def StartDubinsPose(self) -> SE3:
        """The start frame (x = tangent) as an SE3."""
        return as_se3(np.array(self._start))

    @property
    def EndDubinsPose(self) -> SE3:
        """The end frame (x = tangent) as an SE3."""
        return as_se3(np.array(self._end))

    @property
    def start_frame(self) -> np.ndarray:
        """The start Dubins frame as a read-only 4x4 array."""
        return self._start

    @property
    def end_frame(self) -> np.ndarray:
        """The end Dubins frame as a read-only 4x4 array."""
        return self._end

    @property
    def length(self) -> float:
        """Centreline length of the link."""
        return self.path.length

    # --- fittings --------------------------------------------------------------------------
    @cached_property
    def arc1_end_frame(self) -> np.ndarray:
        """F1: the start frame carried exactly along arc 1 (origin q1, x = u); read-only."""
        F = np.array(self._start)
        F[:3, :3] = rotation_matrix(self.path.k1, self.path.theta1) @ F[:3, :3]
        F[:3, 3] = self.path.q1
        return _readonly(F)

    @cached_property
    def arc2_start_frame(self) -> np.ndarray:
        """F2: the end frame carried back along arc 2 (origin q2, x = u); read-only."""
        F = np.array(self._end)
        F[:3, :3] = rotation_matrix(self.path.k2, -self.path.theta2) @ F[:3, :3]
        F[:3, 3] = self.path.q2
        return _readonly(F)

    @cached_property
    def elbows1(self) -> ElbowArc:
        """Arc 1 as elbows."""
        return _elbow_arc(
            self._start, self.path.theta1, self.path.k1, self.maxAnglePerElbow, self.r
        )

    @cached_property
    def elbows2(self) -> ElbowArc:
        """Arc 2 as elbows (starting at ``arc2_start_frame``)."""
        return _elbow_arc(
            self.arc2_start_frame, self.path.theta2, self.path.k2, self.maxAnglePerElbow, self.r
        )

    @cached_property
    def twistAngle(self) -> float:
        """Roll tau (radians) that the straight part must add: y of F1 to y of F2 about u."""
        return signed_angle(
            self.arc1_end_frame[:3, 1], self.arc2_start_frame[:3, 1], self.path.tUnit
        )

    @property
    def hasTwist(self) -> bool:
        """True if the straight part carries a twist fitting (|twistAngle| > 0.01)."""
        return abs(self.twistAngle) > TWIST_MIN_ANGLE

    @cached_property
    def arc1Ball(self) -> Ball:
        """Ball of arc 1 (its elbows, or (start origin, r) without elbows)."""
        ball = self.elbows1.bounding_ball()
        return ball if ball is not None else Ball(self._start[:3, 3], self.r)

    @cached_property
    def arc2Ball(self) -> Ball:
        """Ball of arc 2 (its elbows, or (end origin, r) without elbows)."""
        ball = self.elbows2.bounding_ball()
        return ball if ball is not None else Ball(self._end[:3, 3], self.r)

    def branchingParameters(self) -> list[float]:
        """[phi_w1, theta1, r, tMag, phi_y2, theta2, r] in degrees/lengths.

        See docs/theory/chain.md §3.
        """
        p = self.path
        a_s, b_s = self._start[:3, 0], self._start[:3, 1]
        first = math.degrees(signed_angle(b_s, p.w1, a_s))
        y1 = b_s if p.theta1 <= TWIST_MIN_ANGLE else (p.c1 - p.q1) / self.r
        y2 = (p.c2 - p.q2) / self.r
        second = math.degrees(signed_angle(y1, y2, p.tUnit))
        return [
            first,
            math.degrees(p.theta1),
            self.r,
            p.tMag,
            second,
            math.degrees(p.theta2),
            self.r,
        ]

    # --- rigid motion ------------------------------------------------------------------------
    def transformed(self, T: np.ndarray) -> LinkCSC:
        """The link moved rigidly by the world transform T (no re-solve).

        See docs/theory/chain.md §3.
        """
        start = T @ self._start
        end = T @ self._end
        start.setflags(write=False)
        end.setflags(write=False)
        link = LinkCSC._from_parts(
            self.r, self.maxAnglePerElbow, start, end, self.path.transformed(T)
        )
        cache = self.__dict__
        for name in ("elbows1", "elbows2"):
            if name in cache:
                link.__dict__[name] = cache[name].transformed(T)
        for name in ("arc1Ball", "arc2Ball"):
            if name in cache:
                link.__dict__[name] = cache[name].transformed(T)
        for name in ("arc1_end_frame", "arc2_start_frame"):
            if name in cache:
                link.__dict__[name] = _readonly(T @ cache[name])
        if "twistAngle" in cache:
            link.__dict__["twistAngle"] = cache["twistAngle"]
        # the link this one is a rigid copy of, and the transform from it (kinegami.chain.bodies
        # moves that link's cached capsules instead of rebuilding them)
        origin, moved = cache.get("_moved_from", (self, None))
        link.__dict__["_moved_from"] = (origin, T if moved is None else T @ moved)
        return link

    # --- pattern -----------------------------------------------------------------------------
    def creasePattern(self, numSides: int, twistPortion: float = 0.2):
        """The link's crease pattern (docs/theory/patterns.md §3): elbows, twist, tube, elbows.

        Arcs turning more than 0.01 rad get ``count`` elbow modules; the straight part gets a
        twist of height ``twistPortion * tMag`` when |twistAngle| > 0.01, and a tube for the
        rest. Smaller turns are exact in the chain's frames but below what the pattern
        resolves, and are left out of the pattern as in the reference (docs/theory/patterns.md §3).
        """
        from kinegami.pattern import TubularPattern, WaypointPattern

        numSides = check_num_sides(numSides)
        twistPortion = check_twist_portion(twistPortion)
        modules = [WaypointPattern(numSides, self.r)]
        modules += self.pattern_modules(numSides, twistPortion)
        return TubularPattern.concatenate(modules)

    def pattern_modules(self, numSides: int, twistPortion: float) -> list:
        """The catalog modules of the link's pattern, in order (arguments already checked)."""
        from kinegami.pattern.catalog import build_pieces

        return build_pieces(self.pattern_pieces(numSides, twistPortion))

    def pattern_pieces(self, numSides: int, twistPortion: float) -> list[tuple[str, tuple]]:
        """What :meth:`pattern_modules` builds: a (catalog kind, build arguments) pair per
        module, in order (arguments already checked). A chain builds the pieces of all its links
        together (kinegami.pattern.catalog.build_pieces), its elbows in one batch."""
        pieces = []

        def elbows(arc: ElbowArc) -> list:
            if arc.angle <= PATTERN_MIN_ANGLE:
                return []
            return [("elbow", (numSides, self.r, arc.elbowAngle, arc.rotationalAxisAngle))] * (
                arc.count
            )

        pieces += elbows(self.elbows1)
        tube = self.path.tMag
        if self.hasTwist:
            twist_height = twistPortion * tube
            pieces.append(("twist", (numSides, self.r, self.twistAngle, twist_height)))
            tube -= twist_height
        pieces.append(("tube", (numSides, self.r, tube)))
        pieces += elbows(self.elbows2)
        return pieces

    def __repr__(self) -> str:
        p = self.path
        return (
            f"LinkCSC(theta1={p.theta1:.6g}, tMag={p.tMag:.6g}, theta2={p.theta2:.6g}, "
            f"length={p.length:.6g}, elbows={self.elbows1.count}+{self.elbows2.count}, "
            f"twist={self.twistAngle:.6g})"
        )
