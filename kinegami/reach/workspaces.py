"""What a design can reach at all: its workspace, sampled (docs/reach.md).

:func:`workspace` draws configurations from the joints' ranges (uniform, or scrambled Sobol
points of :mod:`scipy.stats.qmc`), keeps those in which the design does not pass through itself
(the design's own clearance engine, in batches), and reports the tip positions they reach: the
occupied voxels of edge ``voxel`` and their volume, with the number of samples it rests on and
how much it changed from half of them (a sampled volume is low until it converges), and the
share of the volume lost to self-collision, both volumes from as many drawn configurations.
Where asked, it also maps the voxels: Yoshikawa's manipulability of the best clear sample in
each, and the reachability index of Zacharias et al. (the share of approach directions for which
:func:`~kinegami.reach.solve` finds a clear, exact answer).
"""

from __future__ import annotations

import io
import math
from dataclasses import dataclass

import numpy as np

from kinegami._atomic import write_atomic
from kinegami.errors import InvalidParameterError, InvalidTypeError
from kinegami.limits import MAX_REACHABILITY_DIRECTIONS, MAX_WORKSPACE_SAMPLES
from kinegami.reach.forward import kinematics

__all__ = ["Workspace", "approach_directions", "workspace"]

#: Configurations per batch (tip positions and clearance, one task on an executor).
CHUNK = 20_000
#: Targets per call of solve_many in the reachability index (progress between them).
REACHABILITY_CHUNK = 4096


@dataclass(frozen=True, eq=False)
class Workspace:
    """A sampled workspace.

    Attributes
    ----------
    points : (k, 3) array
        Tip positions of the clear sampled configurations (design units, world frame).
    configurations : (k, n) array
        The configurations that reach them (one state per joint of ``design.Joints``).
    lost : (j, 3) array
        Tip positions of the sampled configurations that pass through themselves.
    samples : int
        Configurations drawn.
    voxel : float
        Edge of the voxels (design units).
    voxels : (v, 3) int array
        The occupied voxels (integer coordinates: the voxel [i, i + 1) x ... times ``voxel``).
    volume : float
        ``len(voxels) * voxel**3``, resting on the clear samples.
    half_volume : float
        The volume from the first half of the clear samples: ``convergence`` compares them.
    lost_share : float
        1 - V(clear) / V(all), V(all) from as many drawn configurations as there are clear
        ones (in drawing order).
    manipulability : (v, 2) array or None
        Per voxel (in the order of ``voxels``), the largest Yoshikawa manipulability of the
        clear samples in it: column 0 translational (the product of the singular values of the
        Jacobian's three rows v, design units per joint unit), column 1 full (the six rows, v in
        units of r). Each is sqrt(det(J J^T)) when the tip has at least as many joints as rows,
        else sqrt(det(J^T J)) (the product of the min(rows, joints) singular values). None
        unless asked.
    reachability : (v,) array or None
        Per voxel, the reachability index: the share of ``directions`` approach axes (spread
        evenly over the sphere) for which :func:`~kinegami.reach.solve` reaches the voxel's
        representative point (its clear sample nearest the voxel's centre) with the tip's z
        axis along the direction, exactly and clear. None unless asked.
    directions : (d, 3) array or None
        The approach axes of ``reachability`` (unit vectors, world frame).
    """

    points: np.ndarray
    configurations: np.ndarray
    lost: np.ndarray
    samples: int
    voxel: float
    voxels: np.ndarray
    volume: float
    half_volume: float
    lost_share: float
    manipulability: np.ndarray | None = None
    reachability: np.ndarray | None = None
    directions: np.ndarray | None = None

    @property
    def convergence(self) -> float:
        """|V(N) - V(N/2)| / V(N) (0 for an empty workspace): how much the volume still moved
        between half of the samples and all of them."""
        if self.volume <= 0.0:
            return 0.0
        return abs(self.volume - self.half_volume) / self.volume

    def summary(self, units: str | None = None) -> str:
        """One line: samples, clear share, volume with its convergence, the lost share."""
        unit = f" {units}" if units else ""
        clear = self.points.shape[0]
        return (f"{self.samples} samples, {clear} clear ({clear / max(1, self.samples):.1%}); "
                f"volume {self.volume:.6g}{unit}^3 at voxel {self.voxel:g}{unit} "
                f"({self.voxels.shape[0]} voxels; from half the samples "
                f"{self.convergence:.1%} less); lost to self-collision "
                f"{self.lost_share:.1%}")  # fmt: skip

    def save(self, path) -> str:
        """Write ``path``: ``.npz`` (every array and figure) or ``.ply`` (the clear points, a
        point cloud MeshLab and Open3D open), atomically. Returns the path."""
        import os

        path = os.fspath(path)
        suffix = os.path.splitext(path)[1].lower()
        if suffix not in (".npz", ".ply"):
            raise InvalidParameterError(f"path must end in .npz or .ply, got {path!r}")
        if suffix == ".npz":
            buffer = io.BytesIO()
            maps = {name: getattr(self, name) for name in
                    ("manipulability", "reachability", "directions")
                    if getattr(self, name) is not None}  # fmt: skip
            np.savez_compressed(
                buffer, points=self.points, configurations=self.configurations,
                lost=self.lost, voxels=self.voxels, samples=self.samples, voxel=self.voxel,
                volume=self.volume, half_volume=self.half_volume, lost_share=self.lost_share,
                **maps,
            )  # fmt: skip
            data = buffer.getvalue()
        else:
            header = ("ply\nformat binary_little_endian 1.0\n"
                      f"element vertex {self.points.shape[0]}\n"
                      "property double x\nproperty double y\nproperty double z\n"
                      "end_header\n")  # fmt: skip
            data = header.encode("ascii") + np.ascontiguousarray(self.points, "<f8").tobytes()
        write_atomic(path, data)
        return path

    def show(self, design=None, units: str | None = None, lost: bool = True):
        """Three orthographic views of the clear tip positions (and the lost ones in another
        colour), with the design drawn in when given; returns the matplotlib figure."""
        import matplotlib.pyplot as plt

        fig, axes = plt.subplots(1, 3, figsize=(15, 5))
        unit = f" ({units})" if units else ""
        views = (("x", "y", 0, 1), ("x", "z", 0, 2), ("y", "z", 1, 2))
        frames = None
        if design is not None:
            frames = np.array([joint.distal_dubins_frame()[:3, 3] for joint in design.Joints])
        for ax, (a, b, i, j) in zip(axes, views, strict=True):
            if lost and self.lost.shape[0]:
                ax.scatter(self.lost[:, i], self.lost[:, j], s=1, c="#d62728", alpha=0.15,
                           label="passes through itself", rasterized=True)  # fmt: skip
            ax.scatter(self.points[:, i], self.points[:, j], s=1, c="#1f77b4", alpha=0.3,
                       label="clear", rasterized=True)  # fmt: skip
            if frames is not None:
                ax.plot(frames[:, i], frames[:, j], "-o", c="k", ms=3, lw=1, label="design")
            ax.set_xlabel(a + unit)
            ax.set_ylabel(b + unit)
            ax.set_aspect("equal", adjustable="datalim")
        axes[0].legend(loc="upper right", markerscale=3, fontsize=8)
        fig.suptitle(self.summary(units), fontsize=9)
        fig.tight_layout()
        return fig


def workspace(design, samples: int = 20_000, *, seed: int = 0, voxel: float | None = None,
              tip=None, margin=None, sampler: str = "uniform", manipulability: bool = False,
              reachability: int = 0, executor=None, progress=None) -> Workspace:  # fmt: skip
    """The sampled workspace of ``design``'s tip.

    Parameters
    ----------
    samples : int
        Configurations to draw (1 to MAX_WORKSPACE_SAMPLES).
    seed : int
        The draw's seed (the same seed, the same workspace).
    voxel : float, optional
        Voxel edge in design units (default 2r).
    tip : int, optional
        The tip joint (default: a chain's last joint; a tree needs one).
    margin : float, optional
        The clearance required (default: the design's margin).
    sampler : "uniform" or "sobol"
        Uniform over the joints' ranges, or scrambled Sobol points (lower variance).
    manipulability : bool
        Also map each voxel's best Yoshikawa manipulability (``Workspace.manipulability``).
    reachability : int
        Approach directions per voxel for the reachability index (0: none; up to
        MAX_REACHABILITY_DIRECTIONS). It costs one inverse kinematics per voxel and direction,
        on ``executor`` when given.
    executor : concurrent.futures.Executor, optional
        Runs the batches (threads, processes, a Dask cluster's).
    progress : bool or callable, optional
        As everywhere (docs/progress.md): configurations done of the total.
    """
    from kinegami.chain.bodies import check_margin
    from kinegami.progress import Progress
    from kinegami.validation import check_int

    if isinstance(samples, bool) or not isinstance(samples, (int, np.integer)):
        raise InvalidTypeError(f"samples must be an integer, got {samples!r}")
    if not 1 <= samples <= MAX_WORKSPACE_SAMPLES:
        raise InvalidParameterError(
            f"samples must be an integer in [1, {MAX_WORKSPACE_SAMPLES:,}] (every sample's "
            f"configuration and tip are kept), got {samples}"
        )
    seed = check_int("seed", seed, minimum=0, floats=False)
    if not isinstance(manipulability, bool):
        raise InvalidTypeError(f"manipulability must be True or False, got {manipulability!r}")
    reachability = check_int("reachability", reachability, minimum=0, floats=False)
    if reachability > MAX_REACHABILITY_DIRECTIONS:
        raise InvalidParameterError(
            f"reachability must be an integer in [0, {MAX_REACHABILITY_DIRECTIONS}] (approach "
            f"directions per voxel; MAX_REACHABILITY_DIRECTIONS), got {reachability}"
        )
    if sampler not in ("uniform", "sobol"):
        raise InvalidParameterError(f"sampler must be 'uniform' or 'sobol', got {sampler!r}")
    r = float(design.r)
    h = 2.0 * r if voxel is None else float(voxel)
    if not (math.isfinite(h) and h > 0.0):
        raise InvalidParameterError(f"voxel must be a positive length, got {voxel!r}")
    margin = float(getattr(design, "margin", 0.0)) if margin is None else check_margin(margin)
    if tip is None and len(kinematics(design).tips) != 1:
        raise InvalidParameterError("the design has several tips: give tip=J")
    compiled = kinematics(design, tip)
    low, high = compiled.ranges[:, 0], compiled.ranges[:, 1]
    Q = _draw(low, high, int(samples), seed, sampler)
    pieces = [Q[a : a + CHUNK] for a in range(0, Q.shape[0], CHUNK)]
    parts = []
    with Progress(progress, Q.shape[0], desc="workspace", unit="configuration") as bar:
        if executor is None:
            for piece in pieces:
                parts.append(_chunk(design, compiled, piece, margin))
                bar.update(piece.shape[0])
        else:
            futures = [executor.submit(_chunk, design, compiled, piece, margin)
                       for piece in pieces]  # fmt: skip
            for piece, future in zip(pieces, futures, strict=True):
                parts.append(future.result())
                bar.update(piece.shape[0])
    tips = np.concatenate([p[0] for p in parts]) if parts else np.zeros((0, 3))
    clear = np.concatenate([p[1] for p in parts]) if parts else np.zeros(0, dtype=bool)
    points = tips[clear]
    keys = _voxel_keys(points, h)
    half = _voxel_keys(points[: points.shape[0] // 2], h)
    everything = _voxel_keys(tips[: points.shape[0]], h)  # as many drawn as there are clear
    volume = keys.shape[0] * h**3
    all_volume = everything.shape[0] * h**3
    configurations = Q[clear]
    which = _voxel_of(points, keys, h)
    maps = {}
    if manipulability:
        maps["manipulability"] = _manipulability(compiled, configurations, which, keys.shape[0],
                                                 r)  # fmt: skip
    if reachability:
        directions = approach_directions(reachability)
        maps["directions"] = directions
        maps["reachability"] = _reachability(
            design,
            compiled.tips[0],
            points,
            which,
            keys,
            h,
            directions,
            margin,
            seed,
            executor,
            progress,
        )
    return Workspace(
        points=points, configurations=configurations, lost=tips[~clear], samples=int(samples),
        voxel=h, voxels=keys, volume=volume, half_volume=half.shape[0] * h**3,
        lost_share=0.0 if all_volume == 0 else 1.0 - volume / all_volume, **maps,
    )  # fmt: skip


def approach_directions(count: int) -> np.ndarray:
    """``count`` unit vectors spread evenly over the sphere (a Fibonacci lattice), (count, 3);
    the first is +z."""
    k = np.arange(count, dtype=float)
    z = 1.0 - 2.0 * k / max(1, count - 1) if count > 1 else np.ones(1)
    ring = np.sqrt(np.clip(1.0 - z * z, 0.0, None))
    angle = k * math.pi * (3.0 - math.sqrt(5.0))
    return np.column_stack([ring * np.cos(angle), ring * np.sin(angle), z])


def _voxel_of(points: np.ndarray, keys: np.ndarray, h: float) -> np.ndarray:
    """The index into ``keys`` (sorted, distinct) of each point's voxel, (k,)."""
    if points.shape[0] == 0:
        return np.zeros(0, dtype=np.int64)
    _, inverse = np.unique(np.floor(points / h).astype(np.int64), axis=0, return_inverse=True)
    return inverse.reshape(-1)


def _manipulability(compiled, Q: np.ndarray, which: np.ndarray, voxels: int,
                    r: float) -> np.ndarray:  # fmt: skip
    """Per voxel, the largest translational and full manipulability of its samples, (v, 2)."""
    out = np.zeros((voxels, 2))
    columns = compiled.screws.moving[compiled.path(compiled.tips[0]) - 1]
    if columns.size == 0 or Q.shape[0] == 0:
        return out
    scale = np.array([1.0 / r] * 3 + [1.0] * 3)
    for a in range(0, Q.shape[0], CHUNK):
        J = compiled.jacobians(Q[a : a + CHUNK])[0][:, 0][:, :, columns]  # (m, 6, k)
        values = np.empty((J.shape[0], 2))
        values[:, 0] = np.prod(np.linalg.svd(J[:, :3], compute_uv=False), axis=1)
        values[:, 1] = np.prod(np.linalg.svd(J * scale[:, None], compute_uv=False), axis=1)
        np.maximum.at(out, which[a : a + CHUNK], values)
    return out


def _reachability(design, tip: int, points, which, keys, h, directions, margin, seed, executor,
                  progress) -> np.ndarray:  # fmt: skip
    """Per voxel, the share of ``directions`` reached at its representative point."""
    from kinegami.progress import Progress
    from kinegami.reach.inverse import Target, solve_many

    v = keys.shape[0]
    if v == 0:
        return np.zeros(0)
    # each voxel's clear sample nearest its centre
    gap = np.linalg.norm(points - (keys[which] + 0.5) * h, axis=1)
    order = np.lexsort((gap, which))
    first = order[np.r_[True, which[order][1:] != which[order][:-1]]]
    d = directions.shape[0]
    total = v * d
    reached = np.zeros(total, dtype=bool)
    with Progress(progress, total, desc="reachability", unit="target") as bar:
        for a in range(0, total, REACHABILITY_CHUNK):
            ks = range(a, min(a + REACHABILITY_CHUNK, total))
            targets = [Target(points[first[k // d]], axis=directions[k % d]) for k in ks]
            answers = solve_many(design, targets, tip=tip, seed=seed, margin=margin,
                                 executor=executor)  # fmt: skip
            reached[a : a + len(answers)] = [answer.ok for answer in answers]
            bar.update(len(answers))
    return reached.reshape(v, d).mean(axis=1)


def _draw(low: np.ndarray, high: np.ndarray, m: int, seed: int, sampler: str) -> np.ndarray:
    """``m`` configurations in the box [low, high] (fixed joints at their single state)."""
    if sampler == "sobol":
        from scipy.stats import qmc

        unit = qmc.Sobol(d=low.size, scramble=True, seed=seed).random(m)
    else:
        unit = np.random.default_rng(seed).random((m, low.size))
    return low + (high - low) * unit


def _chunk(design, compiled, Q: np.ndarray, margin: float) -> tuple[np.ndarray, np.ndarray]:
    """Tip positions (m, 3) and whether each configuration is clear (m,): one batch."""
    from kinegami.chain.model import KinematicChain
    from kinegami.clearance.engine import TreeMotion, engine_for

    tips = compiled.tip_poses(Q)[:, 0, :3, 3]
    if isinstance(design, KinematicChain):
        colliding = engine_for(design).colliding(Q, margin)
    else:
        colliding = TreeMotion(design, None, margin).colliding(Q)
    return tips, ~colliding


def _voxel_keys(points: np.ndarray, h: float) -> np.ndarray:
    """The distinct voxels (integer coordinates, (v, 3)) that hold ``points``."""
    if points.shape[0] == 0:
        return np.zeros((0, 3), dtype=np.int64)
    return np.unique(np.floor(points / h).astype(np.int64), axis=0)
