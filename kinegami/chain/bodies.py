"""The solid parts of a folded chain, shared by the clearance engine, meshes and views.

See docs/clearance.md. Two descriptions of the same parts, both in world coordinates (units of
r) at the chain's current configuration:

* **Shapes** (what meshes and pictures are made of): the n-gon of circumradius r in a Dubins
  frame (:func:`regular_polygon`), the point sets whose convex hulls are the joints
  (each joint kind's :meth:`~kinegami.chain.joints.Joint.body_pieces`) and the polygons an elbow
  fitting is swept through (:func:`elbow_rings`).
* **Capsules** (what the clearance engine tests): the tube's centreline as a polyline of
  segments, each the axis of a capsule of radius r that encloses every part along it
  (:class:`CapsuleModel`, built by :func:`capsule_model`).

The centreline of a folded chain is a polyline: an elbow fitting is two straight legs that meet
at its vertex (the intersection of the tangents of its arc), so a link is
``p1 -> vertices of arc 1 -> vertices of arc 2 -> p2`` (the straight part lies on the segment
from the last vertex of arc 1 to the first vertex of arc 2), a revolute joint is
``proximal origin -> centre -> distal origin`` (a kink by its state at the hinge), and
a prismatic joint or a tip is the segment from its proximal to its distal origin. Waypoints add
nothing. Every part lies within r of its segment, except the mitred corners of an elbow, which
reach up to ``r tan(alpha / 2)`` past the vertex on the outside of the turn. They lie in one
more capsule per elbow, the *mitre capsule*: radius r, from the vertex V outwards along
``e = unit(a_in - a_out)`` (in the plane of the turn, away from its centre) for
``r (1 - cos(alpha/2)) / cos(alpha/2)``. Why that suffices: beyond the plane through V normal
to the incoming leg, the leg's solid is the convex hull of the outer half of the disc of radius
r in that plane (within r of V) and the outer half of the mitre ellipse (semi-axes
r / cos(alpha/2) along e and r across); a point x e + y f of that ellipse, 0 <= x, is within r
of the segment [0, x1] e whenever x (1 - cos(alpha/2)) <= x1, so both halves, and therefore
their hull, lie in the capsule (docs/clearance.md has the figure).

Each segment carries the total turning of the centreline up to it (arc angles, plus |state| at
every revolute hinge): the clearance engine tests two segments only when the centreline between
them turns by at least pi.
"""

from __future__ import annotations

import math
import operator
import threading
from dataclasses import dataclass

import numpy as np

from kinegami._memo import weighted_lru_cache
from kinegami.chain.joints import (
    Joint,
)
from kinegami.errors import InvalidParameterError, InvalidTypeError
from kinegami.geometry.screws import FIXED, PRISMATIC, REVOLUTE
from kinegami.geometry.segments import segment_distances
from kinegami.geometry.shapes import (
    regular_polygon,
)
from kinegami.limits import MEMO_CAPSULE_ROWS
from kinegami.validation import shown

__all__ = [
    "BALL_GROUP",
    "near_capsule_pairs",
    "link_capsule_arrays",
    "joint_capsule_arrays",
    "overlap_of_deepest_pair",
    "elbow_rings",
    "CapsuleModel",
    "capsule_model",
    "joint_label",
    "deepest_overlap",
    "worst_overlap",
    "part_label",
    "link_polyline",
    "link_capsule_ends",
    "Overlap",
    "CONTACT_TOLERANCE",
    "clear_limit",
    "check_margin",
    "TURN_TOLERANCE",
    "JOINT_FIXED",
    "JOINT_REVOLUTE",
    "JOINT_PRISMATIC",
]


# --- shapes ----------------------------------------------------------------------------------
def elbow_rings(arc, n: int) -> np.ndarray | None:
    """Polygons an arc's elbows are swept through: the n-gon at each elbow frame and the mitre
    polygon between (2 count + 1, n, 3); None for an arc without elbows.

    ``arc`` is a :class:`~kinegami.chain.links.ElbowArc`. The mitre polygon is the start polygon
    carried along the incoming axis to the plane through the vertex that bisects the turn.
    """
    if arc.count == 0:
        return None
    r = arc.r
    F = np.asarray(arc.frames)
    delta = r * math.tan(arc.elbowAngle / 2.0)
    rings = [regular_polygon(F[0], r, n)]
    for j in range(arc.count):
        a_in, a_out = F[j, :3, 0], F[j + 1, :3, 0]
        start = regular_polygon(F[j], r, n) if j else rings[0]
        vertex = F[j, :3, 3] + delta * a_in
        normal = a_in + a_out
        normal /= np.linalg.norm(normal)
        lam = ((vertex - start) @ normal) / float(a_in @ normal)
        rings.append(start + lam[:, None] * a_in)
        rings.append(regular_polygon(F[j + 1], r, n))
    return np.stack(rings)


# --- capsules --------------------------------------------------------------------------------
#: Overlaps shallower than this many r count as contact, not collision.
CONTACT_TOLERANCE = 1e-9
#: Two capsules are tested when the centreline between them turns by at least pi minus this.
TURN_TOLERANCE = 1e-9

#: Joint motion codes of :class:`CapsuleModel`.
JOINT_FIXED, JOINT_REVOLUTE, JOINT_PRISMATIC = FIXED, REVOLUTE, PRISMATIC

ORDINALS = (
    "first", "second", "third", "fourth", "fifth", "sixth", "seventh", "eighth", "ninth", "tenth",
)  # fmt: skip


def _ordinal(k: int) -> str:
    """'first', 'second', ... for k = 1..10, then '11th', '12th', ..."""
    if 1 <= k <= len(ORDINALS):
        return ORDINALS[k - 1]
    suffix = "th" if 10 <= k % 100 <= 20 else {1: "st", 2: "nd", 3: "rd"}.get(k % 10, "th")
    return f"{k}{suffix}"


def joint_label(chain, index: int, names=None) -> str:
    """``"joint 5, RevoluteJoint 'wrist'"``: a joint in words (``names[index]`` if given)."""
    joint = chain.Joints[index]
    text = f"joint {index}, {type(joint).__name__}"
    if names is not None and index < len(names) and names[index] is not None:
        text += f" '{names[index]}'"
    return text


@dataclass(frozen=True, eq=False)
class CapsuleModel:
    """The chain's centreline as capsules of radius ``r``, and how they move with the joints.

    Everything is at the chain's current configuration, world coordinates, units of r.

    Attributes
    ----------
    r : float
        Capsule radius: the tube's circumradius.
    starts, ends : numpy.ndarray, shape (S, 3)
        End points of every capsule's segment, already extended past elbow vertices.
    start_body, end_body : numpy.ndarray of int, shape (S,)
        Index j of the joint whose distal side each end point moves with (j = -1: the base).
        A link into joint i moves with joint i - 1; the distal half of a revolute joint and
        the distal end of a prismatic joint move with the joint itself.
    turning : numpy.ndarray, shape (S,)
        Total turning of the centreline from the root to the segment (radians), without the
        revolute hinges; at a configuration q, every revolute joint j <= ``start_body`` adds
        |q_j| (its hinge lies before the segment).
    joint_kind : numpy.ndarray of int, shape (J,)
        ``JOINT_FIXED``, ``JOINT_REVOLUTE`` or ``JOINT_PRISMATIC`` of every joint.
    joint_point, joint_axis : numpy.ndarray, shape (J, 3)
        A point of every joint's axis of motion and its unit direction (current configuration).
    states : numpy.ndarray, shape (J,)
        The current states.
    pieces : tuple
        Per segment, ``(breaks, labels)``: the distances along the segment (from its start, in
        units of r, extension included) at which the part changes, and the ``len(breaks) + 1``
        part labels ("link 3, second elbow", "joint 4, RevoluteJoint, distal half", ...).
    element : numpy.ndarray of int, shape (S,)
        Per segment, 2 i for joint i and 2 i - 1 for link i (the order along the tube).
    """

    r: float
    starts: np.ndarray
    ends: np.ndarray
    start_body: np.ndarray
    end_body: np.ndarray
    turning: np.ndarray
    joint_kind: np.ndarray
    joint_point: np.ndarray
    joint_axis: np.ndarray
    states: np.ndarray
    pieces: tuple
    element: np.ndarray

    @property
    def count(self) -> int:
        """Number of capsules."""
        return int(self.starts.shape[0])

    def label(self, segment: int, s: float) -> str:
        """The part at parameter ``s`` in [0, 1] of capsule ``segment``, in words."""
        breaks, labels = self.pieces[segment]
        length = float(np.linalg.norm(self.ends[segment] - self.starts[segment]))
        at = s * length
        for k, b in enumerate(breaks):
            if at < b:
                return labels[k]
        return labels[-1]


class _Builder:
    """Collects the capsules of a chain, segment by segment along the tube."""

    def __init__(self, r: float):
        self.r = r
        self.rows: list[tuple] = []

    def add(self, a, b, body_a, body_b, turning, element, breaks, labels, ext_a=0.0, ext_b=0.0):
        """A segment a -> b extended by ``ext_a`` before a and ``ext_b`` past b; ``breaks`` are
        distances from a at which the label changes (``len(labels) == len(breaks) + 1``)."""
        a = np.asarray(a, dtype=float)
        b = np.asarray(b, dtype=float)
        d = b - a
        length = math.sqrt(float(d.dot(d)))  # np.linalg.norm's arithmetic, without its overhead
        if length > 0.0:
            u = d / length
        else:
            u = np.zeros(3)
            ext_a = ext_b = 0.0
        start = a - ext_a * u
        end = b + ext_b * u
        shifted = tuple(ext_a + x for x in breaks)
        self.rows.append((start, end, body_a, body_b, turning, element, shifted, tuple(labels)))


def _link_events(link, i: int, twistPortion: float) -> list[tuple]:
    """The link's centreline as events in order: ("label", point, text) where a part starts,
    ("vertex", point, (angle, incoming direction, outgoing direction)) at every elbow vertex."""
    r = link.r
    p = link.path
    events: list[tuple] = []
    elbow = 0

    def arc_events(arc):
        nonlocal elbow
        if arc.count == 0:
            return
        delta = r * math.tan(arc.elbowAngle / 2.0)
        F = np.asarray(arc.frames)
        for j in range(arc.count):
            elbow += 1
            events.append(("label", F[j, :3, 3], f"link {i}, {_ordinal(elbow)} elbow"))
            turn = (arc.elbowAngle, F[j, :3, 0], F[j + 1, :3, 0])
            events.append(("vertex", F[j, :3, 3] + delta * F[j, :3, 0], turn))

    arc_events(link.elbows1)
    if p.tMag > 0.0:
        q1 = np.asarray(p.q1, dtype=float)
        if link.hasTwist:
            events.append(("label", q1, f"link {i}, twist"))
            q1 = q1 + twistPortion * p.tMag * np.asarray(p.tUnit, dtype=float)
        events.append(("label", q1, f"link {i}, straight tube"))
    arc_events(link.elbows2)
    return events


def _mitre_extent(r: float, alpha: float) -> float:
    """Length of an elbow's mitre capsule: r (1 - cos(alpha/2)) / cos(alpha/2)."""
    c = math.cos(alpha / 2.0)
    return r * (1.0 - c) / c


def _link_capsules(out: _Builder, link, i: int, turning: float, twistPortion: float) -> float:
    """Add link i (from joint i - 1 to joint i); returns the turning after it.

    The polyline's edges are capsules of radius r; each elbow vertex adds its mitre capsule
    (see :func:`capsule_model`) with the turning half-way through the elbow.
    """
    if link.path.length <= 0.0:
        return turning
    r = out.r
    start = np.asarray(link.start_frame[:3, 3], dtype=float)
    end = np.asarray(link.end_frame[:3, 3], dtype=float)
    events = _link_events(link, i, twistPortion)
    edge_start = start
    breaks: list[float] = []
    labels: list[str] = []
    for kind, point, value in events + [("end", end, None)]:
        if kind == "label":
            along = float(np.linalg.norm(point - edge_start))
            if not labels or along <= 1e-12 * r and not breaks:
                labels[:] = [value]
            else:
                breaks.append(along)
                labels.append(value)
            continue
        if not labels:
            labels = [f"link {i}, straight tube"]
        out.add(edge_start, point, i - 1, i - 1, turning, 2 * i - 1, breaks, labels)
        if kind == "vertex":
            alpha, a_in, a_out = value
            outward = a_in - a_out  # in the plane of the turn, away from its centre
            norm = float(np.linalg.norm(outward))
            if norm > 0.0:
                tip = point + _mitre_extent(r, alpha) * outward / norm
                out.add(point, tip, i - 1, i - 1, turning + alpha / 2.0, 2 * i - 1, [],
                        [labels[-1]])  # fmt: skip
            turning += alpha
        edge_start = point
        breaks, labels = [], [labels[-1]]
    return turning


def _joint_capsules(out: _Builder, joint: Joint, j: int, turning: float, text: str) -> None:
    """Add joint j's centreline segments (:meth:`Joint.capsule_segments`): an end that moves
    with the joint belongs to body j, the other to body j - 1."""
    for segment in joint.capsule_segments():
        out.add(segment.start, segment.end, j if segment.start_moves else j - 1,
                j if segment.end_moves else j - 1, turning, 2 * j, [],
                [text + segment.words])  # fmt: skip


@weighted_lru_cache(16384, MEMO_CAPSULE_ROWS, lambda found: len(found[0]))
def _link_rows(link, i: int, r: float, twistPortion: float) -> tuple[tuple, float]:
    """Capsule rows of link i with turning measured from the link's start, and its turning.

    A link that is a rigid copy of another (``LinkCSC.transformed``, as every state change
    makes of the links after the joint) gets the other's rows moved by the same transform.
    """
    moved = link.__dict__.get("_moved_from")
    if moved is not None:
        rows, turning = _link_rows(moved[0], i, r, twistPortion)
        R, t = moved[1][:3, :3], moved[1][:3, 3]
        return tuple((R @ row[0] + t, R @ row[1] + t) + row[2:] for row in rows), turning
    out = _Builder(r)
    turning = _link_capsules(out, link, i, 0.0, twistPortion)
    return tuple(out.rows), turning


@weighted_lru_cache(16384, MEMO_CAPSULE_ROWS, len)
def _joint_rows(joint, j: int, r: float, text: str) -> tuple:
    """Capsule rows of joint j with turning 0 (the chain adds the turning before it)."""
    out = _Builder(r)
    _joint_capsules(out, joint, j, 0.0, text)
    return tuple(out.rows)


def _joint_row_count(joint, j: int, r: float) -> int:
    """How many capsules joint j has (0 for a waypoint, 2 for a revolute joint, else 1)."""
    return len(_joint_rows(joint, j, r, f"joint {j}, {type(joint).__name__}"))


def _chain_rows(joints, links, r: float, names, twistPortion: float) -> tuple[list, list]:
    """All capsule rows in order along the tube, and the index of every joint's first row."""
    rows: list = []
    first: list[int] = []
    turning = 0.0
    for j, joint in enumerate(joints):
        if j > 0:
            link_rows, turn = _link_rows(links[j], j, r, twistPortion)
            rows += [row[:4] + (row[4] + turning,) + row[5:] for row in link_rows]
            turning += turn
        first.append(len(rows))
        text = f"joint {j}, {type(joint).__name__}"
        if names is not None and j < len(names) and names[j] is not None:
            text += f" '{names[j]}'"
        rows += [row[:4] + (row[4] + turning,) + row[5:] for row in _joint_rows(joint, j, r, text)]
    return rows, first


def _arrays(rows) -> tuple:
    """Segment starts (k, 3), ends (k, 3), bodies (k,) and turnings (k,) of capsule rows."""
    if not rows:
        return np.zeros((0, 3)), np.zeros((0, 3)), np.zeros(0, dtype=np.int64), np.zeros(0)
    return (np.array([row[0] for row in rows]), np.array([row[1] for row in rows]),
            np.array([row[2] for row in rows], dtype=np.int64),
            np.array([row[4] for row in rows], dtype=float))  # fmt: skip


@weighted_lru_cache(16384, MEMO_CAPSULE_ROWS, lambda found: len(found[1]))
def link_capsule_arrays(link, i: int, r: float, twistPortion: float) -> tuple:
    """:func:`_arrays` of link i's rows, the rows whose labels they carry (those of the
    link it is a rigid copy of: labels need only lengths along a segment) and its turning."""
    moved = link.__dict__.get("_moved_from")
    if moved is not None:
        (A, B, body, turn), rows, total = link_capsule_arrays(moved[0], i, r, twistPortion)
        R, t = moved[1][:3, :3], moved[1][:3, 3]
        return (A @ R.T + t, B @ R.T + t, body, turn), rows, total
    rows, total = _link_rows(link, i, r, twistPortion)
    return _arrays(rows), rows, total


@weighted_lru_cache(16384, MEMO_CAPSULE_ROWS, lambda found: len(found[1]))
def joint_capsule_arrays(joint, j: int, r: float) -> tuple:
    """:func:`_arrays` of joint j's rows (labels without names) and the rows (those of the
    joint it is a rigid copy of, when it is one: labels need only lengths along a segment)."""
    moved = joint.__dict__.get("_moved_from")
    if moved is not None:
        (A, B, body, turn), rows = joint_capsule_arrays(moved[0], j, r)
        R, t = moved[1][:3, :3], moved[1][:3, 3]
        return (A @ R.T + t, B @ R.T + t, body, turn), rows
    rows = _joint_rows(joint, j, r, f"joint {j}, {type(joint).__name__}")
    return _arrays(rows), rows


@dataclass(frozen=True)
class _ChainArrays:
    """The capsules of a chain's first ``len(joints)`` joints as arrays (see
    :func:`_chain_arrays`), with what extending them needs: the turning after the last joint."""

    joints: tuple
    links: tuple
    r: float
    starts: np.ndarray
    ends: np.ndarray
    bodies: np.ndarray
    turns: np.ndarray
    elements: np.ndarray
    rows: tuple
    first: tuple
    turning: float
    #: cumulative hinge turning up to body b at index b + 1 (:func:`_kink_prefix`)
    kinks: np.ndarray
    #: total turning of every capsule, hinges included (non-decreasing along the tube)
    tau: np.ndarray
    centre: np.ndarray
    half: np.ndarray
    #: the parts (runs of one element): first capsule, ball centre and radius, turning range
    block_starts: np.ndarray
    block_centre: np.ndarray
    block_radius: np.ndarray
    block_tau_min: np.ndarray
    block_tau_max: np.ndarray


#: The last few chains' arrays, so that a chain extended by a few joints (placement's
#: candidates, a chain built joint by joint) computes only its new parts' capsules.
_ARRAY_MEMO: list[_ChainArrays] = []
_ARRAY_MEMO_SIZE = 8
_ARRAY_MEMO_LOCK = threading.Lock()


def _longest_known_prefix(joints, links, r: float) -> _ChainArrays | None:
    """The memo entry of the longest prefix of (joints, links), the very same objects."""
    best = None
    with _ARRAY_MEMO_LOCK:
        entries = list(_ARRAY_MEMO)
    for entry in entries:
        k = len(entry.joints)
        if entry.r != r or k > len(joints) or (best is not None and k <= len(best.joints)):
            continue
        if all(map(operator.is_, entry.joints, joints[:k])) and all(
            map(operator.is_, entry.links, links[1:k])
        ):
            best = entry
    return best


def _chain_arrays(joints, links, r: float) -> _ChainArrays:
    """The chain's capsules as arrays (starts, ends, bodies, turnings without the hinges, the
    element of every capsule: 2 j for joint j, 2 j - 1 for the link into it), the row of every
    capsule (for its labels) and the index of every joint's first capsule.

    The arrays of a prefix of the chain computed before (the same joint and link objects) are
    reused, so extending a chain by a few joints costs what the new joints cost (plus copying
    arrays), not a pass over the whole chain.
    """
    known = _longest_known_prefix(joints, links, r)
    if known is not None and len(known.joints) == len(joints):
        return known
    k0 = 0 if known is None else len(known.joints)
    starts, ends, bodies, turns, elements = [], [], [], [], []
    rows: list = []
    first: list[int] = []
    turning = 0.0
    count = 0
    if known is not None:
        starts, ends = [known.starts], [known.ends]
        bodies, turns, elements = [known.bodies], [known.turns], [known.elements]
        first = list(known.first)
        turning = known.turning
        count = len(known.rows)
    for j in range(k0, len(joints)):
        joint = joints[j]
        if j > 0:
            (A, B, body, turn), link_rows, total = link_capsule_arrays(links[j], j, r, 0.2)
            if len(link_rows):
                starts.append(A)
                ends.append(B)
                bodies.append(body)
                turns.append(turn + turning)
                elements.append(np.full(len(link_rows), 2 * j - 1, dtype=np.int64))
                rows += link_rows
            turning += total
            count += len(link_rows)
        first.append(count)
        (A, B, body, turn), joint_rows = joint_capsule_arrays(joint, j, r)
        if len(joint_rows):
            starts.append(A)
            ends.append(B)
            bodies.append(body)
            turns.append(turn + turning)
            elements.append(np.full(len(joint_rows), 2 * j, dtype=np.int64))
            rows += joint_rows
            count += len(joint_rows)
    all_rows = tuple(rows) if known is None else known.rows + tuple(rows)
    if not all_rows:
        empty = np.zeros((0, 3))
        arrays = (empty, empty, np.zeros(0, dtype=np.int64), np.zeros(0),
                  np.zeros(0, dtype=np.int64))  # fmt: skip
    else:
        arrays = tuple(np.concatenate(part) for part in (starts, ends, bodies, turns, elements))
    a, b, body, turn, element = arrays
    # what the new rows add (the prefix's values are reused): hinge turnings, totals, balls
    n_old = 0 if known is None else len(known.rows)
    kinks_new = [abs(j.state) if j.motion == REVOLUTE else 0.0 for j in joints[k0:]]
    kinks = np.concatenate([[0.0] if known is None else known.kinks,
                            (0.0 if known is None else known.kinks[-1]) + np.cumsum(kinks_new)])
    a_new, b_new = a[n_old:], b[n_old:]
    tau_new = turn[n_old:] + kinks[body[n_old:] + 1]
    centre_new = 0.5 * (a_new + b_new)
    half_new = 0.5 * np.sqrt(((b_new - a_new) ** 2).sum(axis=1))
    e_new = element[n_old:]
    S_new = e_new.size
    if S_new:
        local = np.flatnonzero(np.r_[True, e_new[1:] != e_new[:-1]])
        sizes = np.diff(np.r_[local, S_new])
        c = np.add.reduceat(centre_new, local, axis=0) / sizes[:, None]
        spread = np.sqrt(((centre_new - np.repeat(c, sizes, axis=0)) ** 2).sum(axis=1))
        rho = np.maximum.reduceat(spread + half_new, local)
        t_min, t_max = tau_new[local], np.maximum.reduceat(tau_new, local)
    else:
        local, c, rho = np.zeros(0, dtype=np.int64), np.zeros((0, 3)), np.zeros(0)
        t_min = t_max = np.zeros(0)
    derived = [kinks, tau_new, centre_new, half_new, local + n_old, c, rho, t_min, t_max]
    if known is not None:
        old = (known.tau, known.centre, known.half, known.block_starts, known.block_centre,
               known.block_radius, known.block_tau_min, known.block_tau_max)  # fmt: skip
        derived[1:] = [np.concatenate([x, y]) for x, y in zip(old, derived[1:], strict=True)]
    for array in (*arrays, *derived):
        array.flags.writeable = False
    result = _ChainArrays(tuple(joints), tuple(links[1:len(joints)]), r, *arrays, all_rows,
                          tuple(first), turning, *derived)  # fmt: skip
    with _ARRAY_MEMO_LOCK:
        _ARRAY_MEMO.insert(0, result)
        del _ARRAY_MEMO[_ARRAY_MEMO_SIZE:]
    return result


def _new_part_pairs(arrays: _ChainArrays, start_new: int, reach: float):
    """The tested capsule pairs (i < j, j >= start_new, turning between them >= pi) whose
    balls come within ``reach``: only what can pair with a new capsule is looked at, first the
    parts by turning, then the parts' balls against each new capsule's ball, then the capsules
    of the parts that are near."""
    tau, starts = arrays.tau, arrays.block_starts
    S = tau.size
    none = np.zeros(0, dtype=np.int64)
    if start_new >= S:
        return none, none
    centre, half = arrays.centre, arrays.half
    # parts that turn by pi before the last new capsule: a prefix of the parts
    limit = float(tau[-1]) - math.pi + TURN_TOLERANCE
    E_old = int(np.searchsorted(arrays.block_tau_min, limit, side="right"))
    if E_old == 0:
        return none, none
    J = np.arange(start_new, S)
    a, b = arrays.starts, arrays.ends
    # one pass over the parts' balls against a ball around all new capsules, then each
    # remaining part's ball against each new capsule's segment (tighter for long segments)
    points = np.concatenate([a[J], b[J]])
    middle = 0.5 * (points.min(axis=0) + points.max(axis=0))
    spread = float(np.sqrt(((points - middle) ** 2).sum(axis=1)).max())
    d = arrays.block_centre[:E_old] - middle
    candidates = np.flatnonzero(
        np.sqrt(np.einsum("ek,ek->e", d, d)) - arrays.block_radius[:E_old] - spread < reach
    )
    if candidates.size == 0:
        return none, none
    c, rho = arrays.block_centre[candidates], arrays.block_radius[candidates]
    near = _point_segment_distance(c[:, None, :], a[None, J], b[None, J]) - rho[:, None] < reach
    near &= arrays.block_tau_min[candidates, None] <= tau[None, J] - math.pi + TURN_TOLERANCE
    e, jj = np.nonzero(near)
    e = candidates[e]
    if e.size == 0:
        return none, none
    ends = np.r_[starts[1:], S]
    sizes = ends[e] - starts[e]
    offset = np.repeat(np.cumsum(sizes) - sizes, sizes)
    i = np.repeat(starts[e], sizes) + np.arange(int(sizes.sum())) - offset
    j = np.repeat(J[jj], sizes)
    ok = (j > i) & (tau[j] >= tau[i] + math.pi - TURN_TOLERANCE)
    i, j = i[ok], j[ok]
    ok = _point_segment_distance(centre[i], a[j], b[j]) - half[i] < reach
    return i[ok], j[ok]


def _point_segment_distance(p: np.ndarray, a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Distance from points ``p`` to segments [a, b] (broadcast over leading axes)."""
    ab = b - a
    length2 = np.einsum("...k,...k->...", ab, ab)
    t = np.einsum("...k,...k->...", p - a, ab) / np.where(length2 > 0.0, length2, 1.0)
    foot = a + np.clip(t, 0.0, 1.0)[..., None] * ab
    d = p - foot
    return np.sqrt(np.einsum("...k,...k->...", d, d))


def _kink_prefix(joints) -> np.ndarray:
    """Turning added by the revolute hinges up to body b (index b + 1; b = -1: 0)."""
    kinks = [abs(j.state) if j.motion == REVOLUTE else 0.0 for j in joints]
    return np.concatenate([[0.0], np.cumsum(kinks)])


@dataclass(frozen=True)
class Overlap:
    """The closest pair of parts of a chain that are closer than the margin: its clearance
    (chain units; < 0 is an overlap, < ``margin`` when a margin is required) and the two parts.

    ``elements`` are the two parts' places along the tube (2 i: joint i, 2 i - 1: link i, the
    link into joint i), in the order of ``first`` and ``second``. ``margin`` is the clearance
    that was required (chain units; 0: parts that touch are clear).
    """

    clearance: float
    first: str
    second: str
    elements: tuple[int, int] = (-1, -1)
    margin: float = 0.0

    def __str__(self) -> str:
        if self.clearance < 0.0:
            return f"{self.first} and {self.second} overlap by {-self.clearance:.4g}"
        return (f"{self.first} and {self.second} are {self.clearance:.4g} apart, closer than "
                f"the margin {self.margin:.4g}")  # fmt: skip


#: Consecutive capsules (or balls) per group where parts are searched by groups (here and in
#: kinegami.clearance.tree_bodies).
BALL_GROUP = 32

#: A pair of parts with more capsule pairs than this is searched by groups of BALL_GROUP
#: consecutive capsules before its capsules are compared (a link of many elbows, or a long one,
#: has a ball that prunes little).
_NEAR_SPLIT = 4096


def near_capsule_pairs(element, tau, first, centre, half, reach: float,
                wanted=None) -> tuple[np.ndarray, np.ndarray]:  # fmt: skip
    """Tested capsule pairs (i < j, j >= first[i]) whose segment balls come within ``reach``
    (with ``wanted``, a bool per capsule constant over each part: only pairs with a wanted
    capsule).

    ``element`` (S,) is each capsule's part (the rows of one part are contiguous). Two
    levels: a ball around each part prunes whole blocks of pairs before the segments' own
    balls are compared; a pair of large parts is pruned by groups of consecutive capsules in
    between. The pairs come by pairs of parts (in order), then rows i, then j.
    """
    S = element.size
    starts = np.flatnonzero(np.r_[True, element[1:] != element[:-1]])
    ends = np.r_[starts[1:], S]
    sizes = ends - starts
    E = starts.size
    c = np.add.reduceat(centre, starts, axis=0) / sizes[:, None]
    owner = np.repeat(np.arange(E), sizes)
    spread = np.sqrt(((centre - c[owner]) ** 2).sum(axis=1)) + half
    rho = np.maximum.reduceat(spread, starts)
    # block pairs (e <= f) that contain a tested pair and whose balls come within reach
    e, f = np.triu_indices(E)
    last_first = np.minimum.reduceat(first, starts)  # smallest first[i] over the block's rows
    tested = last_first[e] < ends[f]
    d = c[e] - c[f]
    near = np.sqrt(np.einsum("ij,ij->i", d, d)) - rho[e] - rho[f] < reach
    keep = tested & near
    if wanted is not None:
        keep &= wanted[starts[e]] | wanted[starts[f]]
    e, f = e[keep], f[keep]
    if e.size == 0:
        return np.zeros(0, dtype=np.int64), np.zeros(0, dtype=np.int64)
    ne, nf = sizes[e], sizes[f]
    # blocks of rows [r1, r1 + n1) against [r2, r2 + n2), each within the part pair `pair`
    r1, n1, r2, n2, pair = starts[e], ne, starts[f], nf, np.arange(e.size)
    split = ne * nf > _NEAR_SPLIT
    if split.any():
        big = np.flatnonzero(split)
        g1, m1, g2, m2, of = _group_blocks(e[big], f[big], starts, ends, first, centre, half,
                                           reach)  # fmt: skip
        small = np.flatnonzero(~split)
        r1, n1 = np.r_[r1[small], g1], np.r_[n1[small], m1]
        r2, n2 = np.r_[r2[small], g2], np.r_[n2[small], m2]
        pair = np.r_[small, big[of]]
    block = n1 * n2
    total = int(block.sum())
    offset = np.repeat(np.cumsum(block) - block, block)
    q = np.arange(total) - offset
    nf_rep = np.repeat(n2, block)
    i = np.repeat(r1, block) + q // nf_rep
    j = np.repeat(r2, block) + q % nf_rep
    ok = j >= first[i]
    i, j = i[ok], j[ok]
    d = centre[i] - centre[j]
    ok2 = np.sqrt(np.einsum("ij,ij->i", d, d)) - half[i] - half[j] < reach
    i, j = i[ok2], j[ok2]
    if split.any():  # the order of whole blocks: each pair's place among all of its blocks'
        which = np.repeat(pair, block)[ok][ok2]
        place = (np.cumsum(ne * nf) - ne * nf)[which] + (i - starts[e[which]]) * nf[which] \
            + (j - starts[f[which]])  # fmt: skip
        order = np.argsort(place, kind="stable")
        i, j = i[order], j[order]
    return i, j


def _group_blocks(e, f, starts, ends, first, centre, half, reach: float):
    """The blocks of groups of at most ``BALL_GROUP`` consecutive rows of parts e and f (for
    each pair of parts e[k], f[k]) that contain a tested pair and whose groups' balls come
    within ``reach``: (first row, rows) of each side and k."""
    G = BALL_GROUP
    parts = np.unique(np.r_[e, f])
    count = -(-(ends[parts] - starts[parts]) // G)  # groups per part
    begin = np.zeros(starts.size, dtype=np.int64)
    begin[parts] = np.cumsum(count) - count  # index of each part's first group
    number = np.zeros(starts.size, dtype=np.int64)
    number[parts] = count
    owner = np.repeat(parts, count)
    g0 = starts[owner] + G * (np.arange(owner.size) - begin[owner])
    g1 = np.minimum(g0 + G, ends[owner])
    size = g1 - g0
    at = np.cumsum(size) - size
    rows = np.repeat(g0 - at, size) + np.arange(int(size.sum()))  # every group's rows
    gc = np.add.reduceat(centre[rows], at, axis=0) / size[:, None]
    spread = np.sqrt(((centre[rows] - np.repeat(gc, size, axis=0)) ** 2).sum(axis=1)) + half[rows]
    gr = np.maximum.reduceat(spread, at)
    gfirst = np.minimum.reduceat(first[rows], at)
    slack = reach + 1e-9 * (1.0 + float(np.abs(gc).max()) + 2.0 * float(gr.max()))
    pairs = number[e] * number[f]
    k = np.repeat(np.arange(e.size), pairs)
    q = np.arange(int(pairs.sum())) - np.repeat(np.cumsum(pairs) - pairs, pairs)
    ge = begin[e][k] + q // number[f][k]
    gf = begin[f][k] + q % number[f][k]
    d = gc[ge] - gc[gf]
    keep = (gfirst[ge] < g1[gf]) & (np.sqrt((d**2).sum(axis=1)) - gr[ge] - gr[gf] < slack)
    ge, gf, k = ge[keep], gf[keep], k[keep]
    return g0[ge], size[ge], g0[gf], size[gf], k


def worst_overlap(
    joints, links, r: float, names=None, since: int = 0, margin: float = 0.0
) -> Overlap | None:
    """The closest tested pair of parts of a chain at its current configuration (the pair rule
    of :mod:`kinegami.clearance`) when it is closer than ``margin`` (chain units; 0: when the
    parts overlap), or None when the chain is clear with that margin.

    A fast test for placement, edits and searches: only pairs whose capsule balls come within
    ``margin`` are measured exactly. With ``since`` = k > 0 only pairs with a part of joint k
    or later (or of the link into it) are measured: placement checks an extension without
    re-checking the chain it extends.
    """
    found = _tested_pairs(joints, links, r, since, margin)
    if found is None:
        return None
    i, j, a, b, rows = found
    dist, s, t = segment_distances(a[i], b[i], a[j], b[j])
    return overlap_of_deepest_pair(i, j, dist, s, t, rows, joints, names, r, margin)


#: Candidate pairs :func:`overlaps` measures at a time (it stops at the first chunk with a
#: pair closer than the margin: a colliding placement candidate has many).
_OVERLAP_CHUNK = 2048


def overlaps(joints, links, r: float, since: int = 0, margin: float = 0.0) -> bool:
    """Whether :func:`worst_overlap` finds a pair (the same pairs and arithmetic, so the same
    answer), measuring the candidate pairs a chunk at a time and stopping at the first pair
    closer than ``margin``: placement's yes/no for a candidate, without the deepest pair a
    colliding candidate would cost (a chain of one-degree elbows spent 21 s of a fuzzed
    case's 23 s measuring every pair of its rejected candidates)."""
    found = _tested_pairs(joints, links, r, since, margin)
    if found is None:
        return False
    i, j, a, b, _ = found
    limit = clear_limit(r, margin)
    for start in range(0, i.size, _OVERLAP_CHUNK):
        ci, cj = i[start : start + _OVERLAP_CHUNK], j[start : start + _OVERLAP_CHUNK]
        dist, _, _ = segment_distances(a[ci], b[ci], a[cj], b[cj])
        if not float(dist.min()) - 2.0 * r >= limit:  # overlap_of_deepest_pair's test
            return True
    return False


def _tested_pairs(joints, links, r: float, since: int, margin: float):
    """The candidate pairs of :func:`worst_overlap` (row indices i, j) with the capsules' end
    points and rows, or None when there is none."""
    arrays = _chain_arrays(joints, links, r)
    a, b, rows, tau = arrays.starts, arrays.ends, arrays.rows, arrays.tau
    S = len(rows)
    if S < 2:
        return None
    if since > 0:
        # the parts from the link into joint `since` on: the rows after joint since - 1's own
        start_new = arrays.first[since - 1] + _joint_row_count(joints[since - 1], since - 1, r)
        i, j = _new_part_pairs(arrays, start_new, 2.0 * r + margin)
    else:
        # turning is non-decreasing along the tube: the pairs (i, j >= first[i]) are tested
        first = np.maximum(
            np.searchsorted(tau, tau + math.pi - TURN_TOLERANCE, side="left"), np.arange(S) + 1
        )
        if int(np.maximum(S - first, 0).sum()) == 0:
            return None
        i, j = near_capsule_pairs(arrays.elements, tau, first, arrays.centre, arrays.half,
                           2.0 * r + margin)
    if i.size == 0:
        return None
    return i, j, a, b, rows


def check_margin(value, name: str = "margin") -> float:
    """A margin (the clearance a design requires, chain units) as a float: a finite number
    >= 0, or an InvalidParameterError / InvalidTypeError naming ``name`` and the value."""
    if isinstance(value, bool) or not isinstance(value, int | float | np.integer | np.floating):
        raise InvalidTypeError(
            f"{name} must be a finite number >= 0 (the clearance required, in the design's "
            f"units), got {shown(value)}"
        )
    number = float(value)
    if not (math.isfinite(number) and number >= 0.0):
        raise InvalidParameterError(
            f"{name} must be a finite number >= 0 (the clearance required, in the design's "
            f"units), got {shown(value)}"
        )
    return number


def clear_limit(r: float, margin: float = 0.0) -> float:
    """The smallest clearance that is clear: ``margin - CONTACT_TOLERANCE * r`` (chain units;
    with margin 0, parts that touch are clear). Every verdict uses it."""
    return margin - CONTACT_TOLERANCE * r


def overlap_of_deepest_pair(i, j, dist, s, t, rows, joints, names, r: float, margin: float = 0.0
             ) -> Overlap | None:  # fmt: skip
    """The Overlap of the closest of the candidate pairs (row indices i, j at distance
    ``dist``, curve parameters s, t), or None when even it is clear (at least ``margin``
    apart, to within CONTACT_TOLERANCE r)."""
    k = int(np.argmin(dist))
    worst = float(dist[k]) - 2.0 * r
    if worst >= clear_limit(r, margin):
        return None
    first_row, second_row = rows[int(i[k])], rows[int(j[k])]
    return Overlap(worst, part_label(first_row, float(s[k]), joints, names),
                   part_label(second_row, float(t[k]), joints, names),
                   (int(first_row[5]), int(second_row[5])), margin)  # fmt: skip


def deepest_overlap(joints, links, r: float) -> float:
    """The clearance of :func:`worst_overlap` (< 0), or +inf when nothing overlaps."""
    found = worst_overlap(joints, links, r)
    return math.inf if found is None else found.clearance


def capsule_model(chain, names=None, twistPortion: float = 0.2) -> CapsuleModel:
    """The :class:`CapsuleModel` of ``chain`` at its current configuration.

    Parameters
    ----------
    chain : KinematicChain
    names : sequence of str or None, optional
        A name for every joint (None where it has none), used in the part labels.
    twistPortion : float, optional
        Fraction of a straight part taken by its twist fitting (labels only); default 0.2.
    """
    joints = chain.Joints
    r = float(chain.r)
    rows, _ = _chain_rows(joints, chain.Links, r, None if names is None else tuple(names),
                          twistPortion)  # fmt: skip
    count = len(joints)
    kinds = np.zeros(count, dtype=np.int64)
    points = np.zeros((count, 3))
    axes = np.zeros((count, 3))
    states = np.zeros(count)
    for j, joint in enumerate(joints):
        T = joint.pose_matrix
        points[j] = T[:3, 3]
        axes[j] = T[:3, 2]
        states[j] = joint.state
        kinds[j] = joint.motion

    def column(k: int, dtype, shape: tuple = ()) -> np.ndarray:
        return np.array([row[k] for row in rows], dtype=dtype).reshape((len(rows), *shape))

    model = CapsuleModel(
        r=r,
        starts=column(0, float, (3,)),
        ends=column(1, float, (3,)),
        start_body=column(2, np.int64),
        end_body=column(3, np.int64),
        turning=column(4, float),
        element=column(5, np.int64),
        pieces=tuple((row[6], row[7]) for row in rows),
        joint_kind=kinds,
        joint_point=points,
        joint_axis=axes,
        states=states,
    )
    for array in vars(model).values():
        if isinstance(array, np.ndarray):
            array.setflags(write=False)
    return model


def link_polyline(link) -> np.ndarray:
    """The link's centreline polyline (units of r, world): its start, every elbow vertex of
    both arcs, its end; shape (k, 3). The tube lies within r of it except at mitred corners."""
    start = np.asarray(link.start_frame[:3, 3], dtype=float)
    end = np.asarray(link.end_frame[:3, 3], dtype=float)
    return np.concatenate([start[None], link.elbows1.vertices(), link.elbows2.vertices(),
                           end[None]])  # fmt: skip


def link_capsule_ends(link) -> np.ndarray:
    """Both ends of every capsule of the link (its polyline's edges and the mitre capsules at
    its elbow vertices), shape (2k, 3), world: the link lies within r of their convex hulls.
    Empty (0, 3) for a link of length 0."""
    (starts, ends, _, _), _, _ = link_capsule_arrays(link, 0, link.r, 0.2)
    return np.concatenate([starts, ends]).reshape(-1, 3)


def part_label(row, param: float, joints, names=None) -> str:
    """The part at parameter ``param`` in [0, 1] of a capsule row, in words (with the joint's
    name from ``names``, if given)."""
    breaks, labels = row[6], row[7]
    at = param * float(np.linalg.norm(row[1] - row[0]))
    text = labels[-1]
    for n, x in enumerate(breaks):
        if at < x:
            text = labels[n]
            break
    return with_joint_name(text, int(row[5]), joints, names)


def with_joint_name(text: str, element: int, joints, names=None) -> str:
    """A part's words ``text`` with its joint's name from ``names`` after "joint j, Type"
    (``element`` 2 j is joint j; links and unnamed joints are left as they are)."""
    if names is not None and element % 2 == 0:
        jj = element // 2
        if jj < len(names) and names[jj] is not None:
            plain = f"joint {jj}, {type(joints[jj]).__name__}"
            text = text.replace(plain, f"{plain} '{names[jj]}'", 1)
    return text
