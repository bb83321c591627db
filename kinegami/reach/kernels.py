"""Compiled damped least squares for one tip, and a redundant arm's moves along its solutions
(numba; docs/reach.md, "Inverse kinematics").

:func:`kinegami.reach.inverse.solve` on a target of one tip spends its time in the fixed cost
of some hundred small numpy calls per iteration, not in arithmetic: a 6-joint arm's forward
kinematics, Jacobian and 6x6 solve are a few hundred floating-point operations. This module
runs one start's whole iteration compiled: the tip's pose by the product of elementary
transforms of :meth:`kinegami.geometry.screws.JointScrews.frame_poses` (the constant step to
each joint's axis frame, then its turn or slide), the geometric Jacobian from the axes, the
damped step with the same damping rule as the numpy path, and the projection onto the ranges.
:func:`escape_step` moves an exact solution of a redundant arm along its solutions, away
from itself: the clearance's analytic gradient (:func:`clearance_gradients`) projected onto
the Jacobian's null space, then :func:`descend` back onto the target.

Compiled once per machine (``cache=True``); :func:`kinegami.reach.inverse.solve` loads this
module on first use and keeps the numpy path where numba cannot run. The first use compiles,
so the kernels are written for a short compilation as well as a fast run: plain loops over
scalars, no matrix products, ``np.linalg``, ``np.dot`` or sorting (numba compiles a BLAS or
LAPACK wrapper for each: ``np.linalg.solve`` alone took about 5 s), no array expressions or
slice assignments (their shape checks compile error messages), no ``min``/``max`` builtins.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit, prange

__all__ = ["clearance_gradients", "descend", "escape_step", "frame_poses", "solve_spd"]

#: Target kinds.
POSITION, AXIS, POSE = 0, 1, 2
#: A start has stalled when its error (position in r plus angle in rad, above the floor) has
#: fallen by less than a tenth over the last window of iterations (looked at every few, from
#: the window and a look on): measured on the 9-joint spherical series, the PUMA and the
#: 7-joint spiral, this stops about half of the iterations of stalled starts and almost never
#: a start that would have converged (1 in about 350).
STALL_EVERY, STALL_WINDOW, STALL_FACTOR, STALL_FLOOR = 10, 20, 0.9, 1e-6
STALL_LOOK = (STALL_WINDOW + STALL_EVERY) // STALL_EVERY  # the first look (in marks)


@njit(cache=True)
def _frames(steps, path, revolute, q, reference, E, axes, T):
    """The tip's pose T (4, 4) and every path joint's axis frame (P, 3, 4) at the path
    joints' states ``q`` (P,) (their turns or slides: ``q - reference``). Plain loops, no
    array expressions: an array expression's shape checks compile their error messages
    (seconds on a fresh install)."""
    S = np.empty((3, 4))  # the running product's top rows
    for i in range(3):
        for j in range(4):
            S[i, j] = 1.0 if i == j else 0.0
    for m in range(path.size):
        step = steps[path[m] - 1]
        for i in range(3):
            for j in range(4):
                axes[m, i, j] = (
                    S[i, 0] * step[0, j]
                    + S[i, 1] * step[1, j]
                    + S[i, 2] * step[2, j]
                    + S[i, 3] * step[3, j]
                )
        d = q[m] - reference[m]
        if revolute[m]:
            c, s = math.cos(d), math.sin(d)
            for i in range(3):
                x, y = axes[m, i, 0], axes[m, i, 1]
                S[i, 0] = c * x + s * y
                S[i, 1] = c * y - s * x
                S[i, 2] = axes[m, i, 2]
                S[i, 3] = axes[m, i, 3]
        else:
            for i in range(3):
                S[i, 0], S[i, 1], S[i, 2] = axes[m, i, 0], axes[m, i, 1], axes[m, i, 2]
                S[i, 3] = axes[m, i, 3] + d * axes[m, i, 2]
    for i in range(3):
        for j in range(4):
            T[i, j] = S[i, 0] * E[0, j] + S[i, 1] * E[1, j] + S[i, 2] * E[2, j] + S[i, 3] * E[3, j]
    T[3, 0], T[3, 1], T[3, 2], T[3, 3] = 0.0, 0.0, 0.0, 1.0


@njit(cache=True)
def _copy(source, out):
    """out[:] = source for vectors (n,), in a plain loop."""
    for i in range(source.size):
        out[i] = source[i]


@njit(cache=True)
def _rotation_vector(R, out):
    """The rotation vector (axis times angle) of R into out (3,), as inverse's numpy one."""
    wx, wy, wz = R[2, 1] - R[1, 2], R[0, 2] - R[2, 0], R[1, 0] - R[0, 1]
    s = 0.5 * math.sqrt(wx * wx + wy * wy + wz * wz)
    c = 0.5 * (R[0, 0] + R[1, 1] + R[2, 2] - 1.0)
    c = -1.0 if -1.0 > c else 1.0 if 1.0 < c else c  # (no min and max: cheaper to compile)
    angle = math.atan2(s, c)
    if s >= 1e-12:
        scale = angle / (2.0 * s)
        out[0], out[1], out[2] = wx * scale, wy * scale, wz * scale
        return
    if c >= 0.0:
        out[0], out[1], out[2] = 0.5 * wx, 0.5 * wy, 0.5 * wz
        return
    # near pi: the axis from the symmetric part's largest diagonal
    k = 0
    for i in range(1, 3):
        if R[i, i] > R[k, k]:
            k = i
    ax, ay, az = 0.5 * R[0, k], 0.5 * R[1, k], 0.5 * R[2, k]
    if k == 0:
        ax += 0.5
    elif k == 1:
        ay += 0.5
    else:
        az += 0.5
    norm = math.sqrt(ax * ax + ay * ay + az * az)
    out[0], out[1], out[2] = ax / norm * math.pi, ay / norm * math.pi, az / norm * math.pi


@njit(cache=True)
def _residual(T, kind, target_p, target_R, target_a, r, e, w):
    """Residual e (3 or 6; units of r, then rad) of pose T; returns (position error in design
    units, angle error in rad)."""
    dx, dy, dz = target_p[0] - T[0, 3], target_p[1] - T[1, 3], target_p[2] - T[2, 3]
    e[0], e[1], e[2] = dx / r, dy / r, dz / r
    pos = math.sqrt(dx * dx + dy * dy + dz * dz)
    if kind == POSE:
        M = np.empty((3, 3))
        for i in range(3):
            for j in range(3):
                M[i, j] = (
                    target_R[i, 0] * T[j, 0] + target_R[i, 1] * T[j, 1] + target_R[i, 2] * T[j, 2]
                )
        _rotation_vector(M, w)
        e[3], e[4], e[5] = w[0], w[1], w[2]
        return pos, math.sqrt(w[0] * w[0] + w[1] * w[1] + w[2] * w[2])
    if kind == AXIS:
        zx, zy, zz = T[0, 2], T[1, 2], T[2, 2]
        ax, ay, az = target_a[0], target_a[1], target_a[2]
        e[3], e[4], e[5] = ax - zx, ay - zy, az - zz
        cx, cy, cz = zy * az - zz * ay, zz * ax - zx * az, zx * ay - zy * ax
        return pos, math.atan2(math.sqrt(cx * cx + cy * cy + cz * cz), zx * ax + zy * ay + zz * az)
    return pos, 0.0


@njit(cache=True)
def solve_spd(A, b):
    """x (n,) with A x = b for a small symmetric positive definite A (n, n): J J^T + lambda I
    (3x3, 6x6) or a null-space step's normal matrix, by Cholesky in plain loops. Where a
    pivot is not positive (A singular to rounding), A + delta I is solved instead, delta
    from 1e-12 of A's largest diagonal entry up by tens until every pivot is positive: a
    little more damping (x = 0 for a matrix that is not finite). No LAPACK or BLAS call: on a
    fresh install those cost seconds of compilation, and a threaded BLAS loaded by another
    library (Robotics Toolbox's import made each solve 2x slower) costs nothing here."""
    n = A.shape[0]
    x = np.empty(n)
    _spd_solve_into(A, b, np.empty((n, n)), x)
    return x


@njit(cache=True)
def _spd_solve_into(A, b, L, x):
    """:func:`solve_spd` into ``x`` (n,), ``L`` (n, n) its work space."""
    n = A.shape[0]
    largest = 0.0
    for i in range(n):
        d = A[i, i] if A[i, i] >= 0.0 else -A[i, i]
        if d > largest:
            largest = d
    shift = 0.0
    for attempt in range(40):
        if attempt:  # a pivot was not positive: a little more damping
            shift = 1e-12 * largest + 1e-300 if attempt == 1 else 10.0 * shift
        positive = True
        for i in range(n):
            for j in range(i + 1):
                total = A[i, j] + shift if i == j else A[i, j]
                for k in range(j):
                    total -= L[i, k] * L[j, k]
                if i == j:
                    if not total > 0.0:
                        positive = False
                        break
                    L[i, i] = math.sqrt(total)
                else:
                    L[i, j] = total / L[j, j]
            if not positive:
                break
        if positive:
            break
    if not positive:  # not finite
        for i in range(n):
            x[i] = 0.0
        return
    for i in range(n):  # L y = b (y in x)
        total = b[i]
        for k in range(i):
            total -= L[i, k] * x[k]
        x[i] = total / L[i, i]
    for i in range(n - 1, -1, -1):  # L^T x = y
        total = x[i]
        for k in range(i + 1, n):
            total -= L[k, i] * x[k]
        x[i] = total / L[i, i]


@njit(cache=True)
def _gram(X, out):
    """out (m, m) = X X^T for X (m, n), in plain loops."""
    m, n = X.shape
    for i in range(m):
        for j in range(i + 1):
            total = 0.0
            for k in range(n):
                total += X[i, k] * X[j, k]
            out[i, j] = total
            out[j, i] = total


@njit(cache=True)
def _transposed_times(X, v, out):
    """out (n,) = X^T v for X (m, n), v (m,), in plain loops."""
    m, n = X.shape
    for j in range(n):
        total = 0.0
        for i in range(m):
            total += X[i, j] * v[i]
        out[j] = total


@njit(cache=True)
def _squared(v):
    """v . v for v (n,)."""
    total = 0.0
    for i in range(v.size):
        total += v[i] * v[i]
    return total


@njit(cache=True)
def _hold(q, step, low, high, held):
    """Mark in ``held`` the joints at a limit of their range that ``step`` pushes beyond it;
    True when it marked one not marked before."""
    more = False
    for m in range(q.size):
        if not held[m] and (
            (step[m] > 0.0 and q[m] >= high[m]) or (step[m] < 0.0 and q[m] <= low[m])
        ):
            held[m] = True
            more = True
    return more


@njit(cache=True)
def descend(steps, path, revolute, reference, E, low, high, kind, target_p, target_R, target_a,
            r, tol_p, tol_a, q, patience, damping, damping_min, damping_max):  # fmt: skip
    """Iterate one start: ``q`` (P,) the path joints' states, changed in place to the last
    iterate. Returns (exact, iterations, position error, angle error, best q, its position and
    angle errors): exact when the tip is within ``tol_p`` r and ``tol_a`` rad; otherwise the
    start stalled (``patience`` iterations, damped to ``damping_max``, or too little progress:
    :data:`STALL_FACTOR`) and best is its nearest iterate (position error, then angle
    error)."""
    P = path.size
    size = 3 if kind == POSITION else 6
    axes = np.empty((P, 3, 4))  # the axis frames and the tip's pose at q
    T = np.empty((4, 4))
    trial_axes = np.empty((P, 3, 4))  # and at the trial step
    trial_T = np.empty((4, 4))
    e = np.empty(size)
    e2 = np.empty(size)
    w = np.empty(3)
    J = np.zeros((size, P))
    A = np.empty((size, size))
    L = np.empty((size, size))
    x = np.empty(size)
    trial = np.empty(P)
    step = np.empty(P)
    best = np.empty(P)
    held = np.zeros(P, dtype=np.bool_)  # joints at a limit that the step pushes beyond
    Jh = np.empty((size, P))  # J without their columns
    _copy(q, best)
    _frames(steps, path, revolute, q, reference, E, axes, T)
    pos, ang = _residual(T, kind, target_p, target_R, target_a, r, e, w)
    best_pos, best_ang = pos, ang
    lam = damping
    moved = True  # q changed: its Jacobian is to be made
    marks = np.empty(patience // STALL_EVERY + 1)  # the error every STALL_EVERY iterations
    for iteration in range(patience):
        if pos <= tol_p * r and ang <= tol_a:
            return True, iteration + 1, pos, ang, q, pos, ang
        if iteration % STALL_EVERY == 0:  # stalled: too little progress over the window
            n = iteration // STALL_EVERY
            marks[n] = error = pos / r + ang
            before = marks[n - STALL_WINDOW // STALL_EVERY] if n >= STALL_LOOK else math.inf
            if error > STALL_FLOOR and error > STALL_FACTOR * before:
                return False, iteration, pos, ang, best, best_pos, best_ang
        if moved:  # the residual's Jacobian at q (kept while steps are refused)
            _residual_jacobian(axes, T, revolute, kind, r, J)
            moved = False
        # the step J^T (J J^T + lambda I)^-1 e, the joints at a limit that it pushes beyond
        # held (their columns left out, the step solved again: the others make up for them)
        for m in range(P):
            held[m] = False
        while True:
            for i in range(size):
                for m in range(P):
                    Jh[i, m] = 0.0 if held[m] else J[i, m]
            _gram(Jh, A)
            for i in range(size):
                A[i, i] += lam
            _spd_solve_into(A, e, L, x)
            _transposed_times(Jh, x, step)
            if not _hold(q, step, low, high, held):
                break
        for m in range(P):
            v = q[m] + step[m]
            v = low[m] if low[m] > v else v
            trial[m] = high[m] if high[m] < v else v
        _frames(steps, path, revolute, trial, reference, E, trial_axes, trial_T)
        pos2, ang2 = _residual(trial_T, kind, target_p, target_R, target_a, r, e2, w)
        if _squared(e2) < _squared(e):
            _copy(trial, q)
            _copy(e2, e)
            axes, trial_axes = trial_axes, axes
            T, trial_T = trial_T, T
            moved = True
            pos, ang = pos2, ang2
            lam = lam * 0.3
            lam = damping_min if damping_min > lam else lam
            if pos < best_pos or (pos == best_pos and ang < best_ang):
                _copy(q, best)
                best_pos, best_ang = pos, ang
        else:
            lam = lam * 8.0
            lam = damping_max if damping_max < lam else lam
            if lam >= damping_max:
                return False, iteration + 1, pos, ang, best, best_pos, best_ang
    if pos <= tol_p * r and ang <= tol_a:
        return True, patience, pos, ang, q, pos, ang
    return False, patience, pos, ang, best, best_pos, best_ang


@njit(cache=True, parallel=True)
def frame_poses(steps, parent, revolute, delta, E, bodies, out):
    """Batched :meth:`kinegami.geometry.screws.JointScrews.frame_poses` (without axes): for
    each configuration k (rows of ``delta`` (K, M), the moving joints' states minus the
    reference ones) and frame l, ``out[k, l]`` (4, 4) = S_bodies[l] E[l], with S_b = S_parent(b)
    steps[b - 1] then body b's turn about (or slide along) its z. The same products as the
    numpy path, in plain loops over configurations split across threads (equal to rounding,
    1e-15 relative)."""
    K, M = delta.shape
    L = bodies.size
    for k in prange(K):
        S = np.empty((M + 1, 3, 4))
        for i in range(3):
            for j in range(4):
                S[0, i, j] = 1.0 if i == j else 0.0
        for b in range(1, M + 1):
            step = steps[b - 1]
            P = S[parent[b]]
            A = S[b]
            for i in range(3):
                for j in range(4):
                    A[i, j] = (
                        P[i, 0] * step[0, j]
                        + P[i, 1] * step[1, j]
                        + P[i, 2] * step[2, j]
                        + P[i, 3] * step[3, j]
                    )
            d = delta[k, b - 1]
            if revolute[b - 1]:
                c, s = math.cos(d), math.sin(d)
                for i in range(3):
                    x, y = A[i, 0], A[i, 1]
                    A[i, 0] = c * x + s * y
                    A[i, 1] = c * y - s * x
            else:
                for i in range(3):
                    A[i, 3] += d * A[i, 2]
        for l in range(L):  # noqa: E741 - frame l
            B = S[bodies[l]]
            F = E[l]
            T = out[k, l]
            for i in range(3):
                for j in range(4):
                    T[i, j] = (
                        B[i, 0] * F[0, j]
                        + B[i, 1] * F[1, j]
                        + B[i, 2] * F[2, j]
                        + B[i, 3] * F[3, j]
                    )
            T[3, 0], T[3, 1], T[3, 2], T[3, 3] = 0.0, 0.0, 0.0, 1.0


@njit(cache=True)
def clearance_gradients(steps, path, revolute, reference, E, q, ends, bodies, s, t, moves):
    """(k, P): the gradient of each pair's clearance with respect to the path joints' states
    ``q`` (P,) (per radian, or per length unit of a slide). The pairs are
    :meth:`kinegami.clearance.engine.ClearanceEngine.closest_pairs`' at ``q``: ``ends`` (k,
    4, 3) world end points, ``bodies`` (k, 4) their bodies, ``s``, ``t`` the closest points'
    parameters; ``moves`` (P, bodies): whether path joint m moves body b.

    The closest points p1 (first capsule) and p2 move with their segments' ends (the
    parameters held: the distance is smallest there, so their change adds nothing to first
    order); joint m moves an end x riding on a body it moves at a_m x (x - o_m) (revolute,
    axis a_m through o_m at ``q``) or a_m (prismatic). The clearance |p1 - p2| - 2r changes
    at n . (dp1 - dp2), n the unit vector from p2 to p1; a pair whose points coincide gets
    a zero row (no direction)."""
    P = path.size
    K = ends.shape[0]
    axes = np.empty((P, 3, 4))
    T = np.empty((4, 4))
    _frames(steps, path, revolute, q, reference, E, axes, T)
    G = np.zeros((K, P))
    weight = np.empty(4)
    for k in range(K):
        dx, dy, dz = 0.0, 0.0, 0.0
        for c in range(3):
            p1 = ends[k, 0, c] + s[k] * (ends[k, 1, c] - ends[k, 0, c])
            p2 = ends[k, 2, c] + t[k] * (ends[k, 3, c] - ends[k, 2, c])
            if c == 0:
                dx = p1 - p2
            elif c == 1:
                dy = p1 - p2
            else:
                dz = p1 - p2
        dist = math.sqrt(dx * dx + dy * dy + dz * dz)
        if not dist > 0.0:
            continue
        nx, ny, nz = dx / dist, dy / dist, dz / dist
        weight[0], weight[1] = 1.0 - s[k], s[k]
        weight[2], weight[3] = t[k] - 1.0, -t[k]
        for e in range(4):
            w = weight[e]
            if w == 0.0:
                continue
            b = bodies[k, e]
            x, y, z = ends[k, e, 0], ends[k, e, 1], ends[k, e, 2]
            for m in range(P):
                if not moves[m, b]:
                    continue
                ax, ay, az = axes[m, 0, 2], axes[m, 1, 2], axes[m, 2, 2]
                if revolute[m]:
                    px, py, pz = x - axes[m, 0, 3], y - axes[m, 1, 3], z - axes[m, 2, 3]
                    vx, vy, vz = ay * pz - az * py, az * px - ax * pz, ax * py - ay * px
                else:
                    vx, vy, vz = ax, ay, az
                G[k, m] += w * (nx * vx + ny * vy + nz * vz)
    return G


@njit(cache=True)
def _residual_jacobian(axes, T, revolute, kind, r, J):
    """The residual's Jacobian J (3 or 6, P) at the tip pose T and axis frames ``axes``, as
    :func:`descend` makes it."""
    for m in range(J.shape[1]):
        dx, dy, dz = axes[m, 0, 2], axes[m, 1, 2], axes[m, 2, 2]
        if revolute[m]:
            px, py, pz = T[0, 3] - axes[m, 0, 3], T[1, 3] - axes[m, 1, 3], T[2, 3] - axes[m, 2, 3]
            vx, vy, vz = dy * pz - dz * py, dz * px - dx * pz, dx * py - dy * px
            wx, wy, wz = dx, dy, dz
        else:
            vx, vy, vz = dx, dy, dz
            wx, wy, wz = 0.0, 0.0, 0.0
        J[0, m], J[1, m], J[2, m] = vx / r, vy / r, vz / r
        if kind == POSE:
            J[3, m], J[4, m], J[5, m] = wx, wy, wz
        elif kind == AXIS:
            zx, zy, zz = T[0, 2], T[1, 2], T[2, 2]
            J[3, m], J[4, m], J[5, m] = wy * zz - wz * zy, wz * zx - wx * zz, wx * zy - wy * zx


@njit(cache=True)
def _null_step(J, G, rise, held, scale):
    """x (P,): the damped least-squares step (in units of ``scale``: rad, or r for a slide)
    that raises each pair's clearance by ``rise`` (K,) to first order (gradients G (K, P))
    while the residual does not change (J x = 0: the step lies in J's null space), the
    ``held`` joints not moving."""
    size, P = J.shape
    K = G.shape[0]
    Js = np.empty((size, P))
    Gs = np.empty((K, P))
    for m in range(P):
        f = 0.0 if held[m] else scale[m]
        for i in range(size):
            Js[i, m] = J[i, m] * f
        for k in range(K):
            Gs[k, m] = G[k, m] * f
    # the null space's projector N = I - Js^T (Js Js^T + eps I)^-1 Js (plain loops)
    A = np.empty((size, size))
    _gram(Js, A)
    trace = 0.0
    for i in range(size):
        trace += A[i, i]
    eps = 1e-12 * (trace + 1.0)
    for i in range(size):
        A[i, i] += eps
    L = np.empty((size, size))
    column = np.empty(size)
    solved = np.empty(size)
    M = np.empty((size, P))  # (Js Js^T + eps I)^-1 Js, a column at a time
    for m in range(P):
        for i in range(size):
            column[i] = Js[i, m]
        _spd_solve_into(A, column, L, solved)
        for i in range(size):
            M[i, m] = solved[i]
    N = np.empty((P, P))
    for a in range(P):
        for c in range(P):
            total = 0.0
            for i in range(size):
                total += Js[i, a] * M[i, c]
            N[a, c] = (1.0 if a == c else 0.0) - total
    GN = np.empty((K, P))
    for k in range(K):
        for c in range(P):
            total = 0.0
            for a in range(P):
                total += Gs[k, a] * N[a, c]
            GN[k, c] = total
    H = np.empty((P, P))  # GN^T GN + mu I
    for a in range(P):
        for c in range(a + 1):
            total = 0.0
            for k in range(K):
                total += GN[k, a] * GN[k, c]
            H[a, c] = total
            H[c, a] = total
    trace = 0.0
    for m in range(P):
        trace += H[m, m]
    mu = 1e-6 * (trace / P) + 1e-300
    for m in range(P):
        H[m, m] += mu
    right = np.empty(P)
    _transposed_times(GN, rise, right)
    return solve_spd(H, right)


@njit(cache=True)
def escape_step(steps, path, revolute, reference, E, low, high, kind, r, q, clearance, ends,
                bodies, s, t, moves, goal, radius):  # fmt: skip
    """One move of a redundant arm along its exact solutions, away from itself, before the
    descent back onto the target (:func:`descend`). ``q`` (P,): the path joints' states at an
    exact solution; ``clearance``, ``ends``, ``bodies``, ``s``, ``t``: the engine's closest
    pairs there, ``moves`` as :func:`clearance_gradients`.

    Every pair closer than ``goal`` asks its clearance to rise to it; the step that does so
    best to first order while the tip stays put (Gauss-Newton on the pairs' gradients,
    projected onto the null space of the residual's Jacobian, damped), at most ``radius``
    long (rad; a slide in units of r), a joint at a limit that it would push beyond held
    there, the others projected onto their ranges. Returns the path joints' new states, or
    ``q`` itself when no step raises a pair."""
    P = path.size
    size = 3 if kind == POSITION else 6
    axes = np.empty((P, 3, 4))
    T = np.empty((4, 4))
    _frames(steps, path, revolute, q, reference, E, axes, T)
    J = np.zeros((size, P))
    _residual_jacobian(axes, T, revolute, kind, r, J)
    G_all = clearance_gradients(steps, path, revolute, reference, E, q, ends, bodies, s, t,
                                moves)  # fmt: skip
    K = 0
    for k in range(clearance.size):
        if clearance[k] < goal:
            K += 1
    G = np.empty((K, P))
    rise = np.empty(K)
    n = 0
    for k in range(clearance.size):
        if clearance[k] < goal:
            for m in range(P):
                G[n, m] = G_all[k, m]
            rise[n] = goal - clearance[k]
            n += 1
    scale = np.empty(P)
    for m in range(P):
        scale[m] = 1.0 if revolute[m] else r
    held = np.zeros(P, dtype=np.bool_)
    x = _null_step(J, G, rise, held, scale)
    again = False
    for m in range(P):
        d = x[m] * scale[m]
        if (q[m] + d > high[m] and q[m] >= high[m] - 1e-12) or \
                (q[m] + d < low[m] and q[m] <= low[m] + 1e-12):  # fmt: skip
            held[m] = True
            again = True
    if again:
        x = _null_step(J, G, rise, held, scale)
    length = math.sqrt(_squared(x))
    trial = np.empty(P)
    _copy(q, trial)
    if not length > 0.0:
        return trial
    f = radius / length
    f = f if f < 1.0 else 1.0
    for m in range(P):
        v = q[m] + f * x[m] * scale[m]
        v = low[m] if low[m] > v else v
        trial[m] = high[m] if high[m] < v else v
    return trial
