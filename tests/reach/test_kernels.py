"""The compiled kernels' own linear algebra (kinegami.reach.kernels): the small symmetric
positive definite solve in plain loops agrees with numpy's LAPACK on random, ill-conditioned
and singular-to-rounding matrices, and the kernels call no BLAS or LAPACK routine (numba
compiles a wrapper for each, seconds on a fresh install: docs/reach.md, "Inverse
kinematics")."""

from __future__ import annotations

import ast
from pathlib import Path

import numpy as np
import pytest

from kinegami.reach.kernels import solve_spd

KERNELS = Path(__file__).resolve().parents[2] / "kinegami" / "reach" / "kernels.py"


@pytest.mark.parametrize("n", [3, 6, 9])
def test_the_spd_solve_is_numpys_on_random_matrices(n):
    rng = np.random.default_rng(n)
    for _ in range(50):
        J = rng.normal(size=(n, n + 2))
        A = J @ J.T + 1e-3 * np.eye(n)  # the descent's J J^T + lambda I
        b = rng.normal(size=n)
        np.testing.assert_allclose(solve_spd(A, b), np.linalg.solve(A, b), rtol=1e-9,
                                   atol=1e-12)  # fmt: skip


def test_the_spd_solve_is_numpys_near_singular():
    """J J^T + lambda I of a Jacobian that loses rank (a wrist at a singularity), lambda down
    to the descent's smallest damping: the answer solves the system as well as LAPACK's."""
    rng = np.random.default_rng(7)
    for lam in (1e-6, 1e-9, 1e-12):
        for _ in range(20):
            J = rng.normal(size=(6, 7))
            J[5] = J[4] + 1e-9 * rng.normal(size=7)  # two rows all but equal
            A = J @ J.T + lam * np.eye(6)
            b = rng.normal(size=6)
            x, expected = solve_spd(A, b), np.linalg.solve(A, b)
            assert np.all(np.isfinite(x))
            scale = np.linalg.norm(A) * np.linalg.norm(expected)
            assert np.linalg.norm(A @ x - b) <= 1e-9 * scale
            assert np.linalg.norm(A @ expected - b) <= 1e-9 * scale  # (LAPACK does as well)
            # the same answer, within what the condition number allows
            error = np.linalg.norm(x - expected) / np.linalg.norm(expected)
            assert error <= 1e-14 * np.linalg.cond(A)


def test_a_pivot_that_is_not_positive_gets_a_little_more_damping():
    """A singular matrix (rank one; exact zero pivots) is solved with a small shift: a finite
    answer whose part in A's range solves the system; a matrix that is not finite gives 0."""
    v = np.array([1.0, 2.0, -1.0, 0.5, 3.0, -2.0])
    A = np.outer(v, v)
    b = 2.5 * v  # in A's range: A x = b for x = 2.5 v / |v|^2
    x = solve_spd(A, b)
    assert np.all(np.isfinite(x))
    np.testing.assert_allclose(A @ x, b, rtol=1e-6)
    # (its other parts: b's rounding divided by the shift's few 1e-11)
    np.testing.assert_allclose(x, 2.5 * v / (v @ v), rtol=1e-2)
    bad = np.eye(3)
    bad[1, 1] = np.nan
    assert np.array_equal(solve_spd(bad, np.ones(3)), np.zeros(3))


def test_the_kernels_call_no_blas_or_lapack():
    """No matrix product (@), np.dot, np.linalg, np.trace or np.argsort in the kernels: each
    makes numba compile a BLAS or LAPACK wrapper (np.linalg.solve alone took about 5 s, a
    product about 0.8 s on a fresh install)."""
    tree = ast.parse(KERNELS.read_text(encoding="utf-8"))
    found = []
    for node in ast.walk(tree):
        if isinstance(node, ast.BinOp) and isinstance(node.op, ast.MatMult):
            found.append(f"@ at line {node.lineno}")
        if isinstance(node, ast.Attribute) and node.attr in {
            "dot",
            "linalg",
            "trace",
            "argsort",
            "matmul",
            "inner",
            "outer",
        }:
            found.append(f"{node.attr} at line {node.lineno}")
    assert not found, found
