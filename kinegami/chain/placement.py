"""Joint placement along the axis of motion.

The published rules: docs/theory/placement.md; what kinegami adds: docs/placement.md.

These functions only compute poses; the chain builds and checks the links. All frames are 4x4
world arrays. A joint placed here keeps its axis-of-motion line: it only slides along its z
axis, turns about it (common-normal rule) or reverses its path direction (a half turn that
keeps the line).
"""

from __future__ import annotations

import math

import numpy as np

from kinegami.chain.joints import Joint, Waypoint
from kinegami.errors import NoPathError
from kinegami.geometry.balls import Ball
from kinegami.geometry.frames import angle_between, any_perpendicular, rotation_matrix, unit
from kinegami.geometry.lines import common_normal

#: Plane side tests and line/plane parallelism (docs/theory/chain.md §0).
PLANE_TOLERANCE = 1e-8


def slide_to_plane(
    p: np.ndarray,
    z: np.ndarray,
    target: np.ndarray,
    plane_point: np.ndarray,
    plane_normal: np.ndarray,
) -> float:
    """lambda minimising |target - (p + lambda z)| with (p + lambda z) on or beyond the plane.

    Closed form of docs/theory/placement.md §1 step 5.
    """
    lam_star = float((target - p) @ z)
    a = float(plane_normal @ z)
    b = float(plane_normal @ (p - plane_point))
    if abs(a) < PLANE_TOLERANCE:
        return lam_star
    if a > 0:
        return max(lam_star, -b / a)
    return min(lam_star, -b / a)


def compact_lambda(
    p_parent: np.ndarray, p: np.ndarray, z: np.ndarray, ball: Ball, clearance: float, r: float
) -> float:
    """Slide for compact placement (docs/theory/placement.md §2): nearest to the parent with
    |c - (p + lambda z)| >= clearance, staying on the side of the ball the user chose."""
    lam_star = float((p_parent - p) @ z)
    lam_c = float((ball.c - p) @ z)
    h2 = float((ball.c - p) @ (ball.c - p)) - lam_c * lam_c
    D2 = clearance * clearance
    if D2 <= h2:
        return lam_star
    w = math.sqrt(D2 - max(h2, 0.0))
    if lam_c <= 1e-9 * r:
        return max(lam_star, lam_c + w)
    return min(lam_star, lam_c - w)


def compact_lambda_other_side(
    p: np.ndarray, z: np.ndarray, ball: Ball, clearance: float, r: float
) -> float | None:
    """The clearance boundary point on the other side of the ball from :func:`compact_lambda`.

    Tried when the link to the rule's choice needs a turn >= pi (e.g. the tie case, where the
    joint's axis passes through the ball's centre, sends it to +z). None when the clearance
    bound is inactive (the axis misses the clearance sphere).
    """
    lam_c = float((ball.c - p) @ z)
    h2 = float((ball.c - p) @ (ball.c - p)) - lam_c * lam_c
    D2 = clearance * clearance
    if D2 <= h2:
        return None
    w = math.sqrt(D2 - max(h2, 0.0))
    return lam_c - w if lam_c <= 1e-9 * r else lam_c + w


def orient_by_common_normal(joint: Joint, parent_pose: np.ndarray) -> Joint:
    """x along the common normal from the parent's axis, path pointing away.

    See docs/theory/placement.md §3.
    """
    T = joint.pose_matrix
    tol = 1e-9 * joint.r
    n = common_normal(parent_pose[:3, 3], parent_pose[:3, 2], T[:3, 3], T[:3, 2], tol)
    if n is not None:
        joint = joint.with_xhat_about_zhat(n)
    if float(joint.path_direction() @ (joint.pose_matrix[:3, 3] - parent_pose[:3, 3])) < -tol:
        joint = joint.with_reversed_path_direction()
    return joint


def _waypoint(template: Joint, R: np.ndarray, origin: np.ndarray, path_index: int) -> Waypoint:
    T = np.eye(4)
    T[:3, :3] = R
    T[:3, 3] = origin
    # a computed position, not a user parameter: not held to the +-1e6 r bound of Poses
    return Waypoint(template.numSides, template.r, np.eye(4), pathIndex=path_index).with_pose(T)


def published_safe_placement(
    parent_distal: np.ndarray,
    parent_path_index: int,
    joint: Joint,
    ball: Ball,
    reverse: bool = False,
) -> list[Joint]:
    """The published safe placement (T-RO Algorithm 9, docs/theory/placement.md §1).

    ``parent_distal`` is the parent's distal frame (4x4, not permuted); its column
    ``parent_path_index`` is the direction n1 in which the tube leaves the parent. The joint
    keeps its path direction, or has it reversed when ``reverse`` is True (the caller tries
    both: docs/theory/placement.md §1 step 6). Returns the waypoints and the placed joint, in order.
    """
    r = joint.r
    n1 = parent_distal[:3, parent_path_index]
    A = parent_distal[:3, 3]
    R_parent = parent_distal[:3, :3]
    rho = joint.bounding_radius()
    T = joint.pose_matrix
    p, z = T[:3, 3], T[:3, 2]

    s1 = ball.c + ball.r * n1
    o1 = A + float((s1 - A) @ n1) * n1
    w1 = _waypoint(joint, R_parent, o1, parent_path_index)
    far1 = s1 + (4.0 * r + rho) * n1
    dist_far1 = float((p - far1) @ n1)
    if abs(dist_far1) < PLANE_TOLERANCE:
        dist_far1 = 0.0
    waypoints = [w1]
    if abs(float(n1 @ z)) < PLANE_TOLERANCE and dist_far1 < 0.0:
        n2 = z
        s2 = ball.c + ball.r * n2
        b = o1 + r * n1
        o2 = b + float((s2 - b) @ n2) * n2
        R2 = rotation_matrix(np.cross(n1, n2), math.pi / 2.0) @ R_parent
        waypoints.append(_waypoint(joint, R2, o2, parent_path_index))
        target, plane_point, plane_normal = o2, s2 + (4.0 * r + rho) * n2, n2
    else:
        target, plane_point, plane_normal = o1, far1, n1
    lam = slide_to_plane(p, z, target, plane_point, plane_normal)
    placed = joint.translated_along_z(lam)
    if reverse:
        placed = placed.with_reversed_path_direction()
    return waypoints + [placed]


def _turn(d: np.ndarray, target: np.ndarray) -> tuple[np.ndarray, float]:
    """Unit rotation axis and angle carrying direction d onto target (for opposite directions,
    any axis perpendicular to d)."""
    return any_perpendicular(d, target), angle_between(d, target)


def _arc_displacement(r: float, d: np.ndarray, axis: np.ndarray, angle: float) -> np.ndarray:
    """Displacement along an arc of radius r turning d by ``angle`` about ``axis``."""
    w = np.cross(axis, d)
    return r * math.sin(angle) * d + r * (1.0 - math.cos(angle)) * w


def radial_safe_placement(
    parent_distal: np.ndarray,
    parent_path_index: int,
    joint: Joint,
    ball: Ball,
    *,
    lead: float = 0.0,
    bend_straight: float = 0.5,
    two_arcs_above: float = 2.0 * math.pi / 3.0,
    escape: np.ndarray | None = None,
    hold_past: np.ndarray | None = None,
    outward: float = 0.0,
) -> list[Joint]:
    """Safe placement whose parts stay within a fixed distance of the ball (docs/placement.md).

    With c, R the ball, A and d1 the parent's distal point and direction:

    1. The joint goes to the point x of its axis line at distance R' from c (the one nearest to
       A), with R' = max(R + 4r + rho_N, |A - c| + L_N/2 + 9r); if the line misses that sphere,
       to the point of the line nearest to A. m = unit(x - c) is the outward normal there, and
       the joint's path direction is reversed if it points inwards (a . m < 0).
    2. Waypoint W_b sits 4r straight behind the joint's proximal point B along m, facing m.
       W_b -> joint: the end lies straight ahead at >= 4r and a . m >= 0, so a CSC path with
       turns <= pi/3 and <= 5pi/6 exists (Lemma D of the docs).
    3. Waypoint W_a: from (A, d1) turn onto m: one arc and r straight, or for turns > 2pi/3
       two equal arcs with 0.5 r straight between them (a CSC path either way). W_a -> W_b:
       parallel directions with
       W_b at least 2r ahead, an S-curve with both turns <= pi/2 (Lemma S).

    Every link therefore exists with turns < pi; the joint lies at distance R' from c and every
    part within R' + 2 rho_N + 2r, so the ball grows by a bounded amount per joint.

    Variants (tried by the chain when the default construction passes through the chain):
    ``lead`` (in r) puts a waypoint that far straight ahead of A first, so the turn onto m
    happens away from the parent; turns above ``two_arcs_above`` use two arcs with
    ``bend_straight`` r of straight tube between them, which moves the tube coming back by
    more than 2r away from the parent's axis. ``escape`` (a unit vector perpendicular to the
    parent's path direction) first turns the tube by pi/2 towards it and runs 2r straight (a
    waypoint), the way out when the tube arrived at the parent by a U-turn and anything leaving
    the parent would otherwise run back along it. ``hold_past`` (points, shape (k, 3)) puts
    one more waypoint W_h straight ahead of W_a, 2r past every one of those points along m,
    and starts the S-curve only there (R' grows until W_b is still 2r ahead of W_h): from W_h
    on, the heading never turns back against m, so every later part lies at least 2r beyond
    each capsule whose ends are those points. The chain passes the capsule ends of the tube
    that arrived at the parent: after a U-turn made of one elbow fitting (a large
    maxAnglePerElbow), the fitting's legs and mitre reach far behind the parent, along the
    way the tube comes back (W_a -> W_h is a straight tube: a CSC path with no turns).
    ``outward`` (in r) adds that much to R': the joint sits farther out on its axis (a tree
    uses it when a sibling already sits where the joint would go). Every link still exists
    as above, and the ball grows by at most ``outward`` r more.
    """
    r = joint.r
    c, R = ball.c, ball.r
    A = parent_distal[:3, 3]
    d1 = parent_distal[:3, parent_path_index]
    R_parent = parent_distal[:3, :3]
    lead_waypoints = []
    if escape is not None:
        e = unit(np.asarray(escape, dtype=float) - float(np.asarray(escape) @ d1) * d1)
        R_escape = rotation_matrix(np.cross(d1, e), math.pi / 2.0) @ R_parent
        A = A + r * d1 + 3.0 * r * e
        d1 = e
        R_parent = R_escape
        lead_waypoints.append(_waypoint(joint, R_parent, A, parent_path_index))
    if lead > 0.0:
        A = A + lead * r * d1
        lead_waypoints.append(_waypoint(joint, R_parent, A, parent_path_index))
    rho = joint.bounding_radius()
    L = joint.neutralLength
    T = joint.pose_matrix
    p, z = T[:3, 3], T[:3, 2]
    radius = max(R + 4.0 * r + rho, float(np.linalg.norm(A - c)) + L / 2.0 + 9.0 * r)
    if outward > 0.0:
        radius += outward * r
    past = None if hold_past is None else np.asarray(hold_past, dtype=float).reshape(-1, 3)

    for _ in range(8):
        lam_c = float((c - p) @ z)
        foot = p + lam_c * z
        h2 = float((foot - c) @ (foot - c))
        if h2 >= radius * radius:
            lam = float((A - p) @ z)
        else:
            w = math.sqrt(radius * radius - h2)
            lam = min((lam_c - w, lam_c + w), key=lambda t: float(np.linalg.norm(p + t * z - A)))
        x = p + lam * z
        m = unit(x - c)
        placed = joint.translated_along_z(lam)
        if float(placed.path_direction() @ m) < 0.0:
            placed = placed.with_reversed_path_direction()
        B = placed.proximal_frame()[:3, 3]
        wb = B - 4.0 * r * m

        axis, psi = _turn(d1, m)
        if psi <= two_arcs_above:  # arc, then r straight: a CSC path with theta2 = 0
            wa = A + _arc_displacement(r, d1, axis, psi) + r * m
        else:  # arc, bend_straight r straight, arc: a CSC path
            half = psi / 2.0
            u_mid = rotation_matrix(axis, half) @ d1
            wa = (
                A
                + _arc_displacement(r, d1, axis, half)
                + bend_straight * r * u_mid
                + _arc_displacement(r, u_mid, axis, half)
            )
        held = []  # W_h: straight ahead of W_a until 2r past every point of hold_past along m
        if past is not None:
            hold = float(np.max((past - wa) @ m)) + 2.0 * r
            if hold > 0.0:
                held = [wa + hold * m]
        ahead = float((wb - (held[-1] if held else wa)) @ m)
        if ahead >= 2.0 * r:
            R_turned = rotation_matrix(axis, psi) @ R_parent
            return lead_waypoints + [
                _waypoint(joint, R_turned, point, parent_path_index) for point in [wa, *held, wb]
            ] + [placed]  # fmt: skip
        # a long hold may need more than 4r: the joint (so W_b) moves out about as far as R'
        radius += max(4.0 * r, 2.0 * r - ahead) if held else 4.0 * r
    raise NoPathError("radial safe placement found no waypoint layout (degenerate input)")
