"""Sampled workspaces (kinegami.reach.workspace, docs/reach.md): every point is its
configuration's tip and every configuration is clear by the design's own clearance; the volume,
its half-sample figure and the share lost to self-collision are what they say; the same seed
gives the same workspace on any executor; .npz and .ply files open in numpy and trimesh."""

from __future__ import annotations

from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import numpy as np
import pytest

from kinegami.design import load_design
from kinegami.errors import InvalidParameterError, InvalidTypeError
from kinegami.reach import Target, kinematics, solve, workspace
from kinegami.reach.workspaces import approach_directions

DESIGNS = Path(__file__).resolve().parents[2] / "examples" / "designs"


@pytest.fixture(scope="module")
def puma():
    return load_design(DESIGNS / "puma.json")


@pytest.fixture(scope="module")
def sampled(puma):
    return workspace(puma, 3000, seed=4)


def test_points_are_the_clear_configurations_tips(puma, sampled):
    compiled = kinematics(puma)
    assert sampled.samples == 3000
    assert sampled.points.shape[0] == sampled.configurations.shape[0] > 0
    assert sampled.points.shape[0] + sampled.lost.shape[0] == 3000
    assert np.allclose(compiled.fkine(sampled.configurations)[:, :3, 3], sampled.points,
                       rtol=0, atol=1e-12 * puma.r)  # fmt: skip
    for q in sampled.configurations[:25]:
        assert puma.clearance(q.tolist()).ok
    low, high = compiled.ranges[:, 0], compiled.ranges[:, 1]
    assert np.all(sampled.configurations >= low) and np.all(sampled.configurations <= high)
    # the PUMA passes through itself in about half of its configurations (spec: 49%)
    assert 0.3 < sampled.lost.shape[0] / 3000 < 0.7


def test_volumes_are_what_they_say(puma, sampled):
    h = sampled.voxel
    assert h == 2 * puma.r
    keys = {tuple(k) for k in np.floor(sampled.points / h).astype(int)}
    assert len(keys) == sampled.voxels.shape[0]
    assert sampled.volume == pytest.approx(len(keys) * h**3)
    half = {tuple(k) for k in np.floor(sampled.points[: sampled.points.shape[0] // 2] / h)
            .astype(int)}  # fmt: skip
    assert sampled.half_volume == pytest.approx(len(half) * h**3)
    assert 0 <= sampled.convergence < 1
    # lost share at equal sample counts: the first k drawn configurations, clear or not
    again = workspace(puma, 3000, seed=4)
    k = sampled.points.shape[0]
    tips = np.concatenate([sampled.points, sampled.lost])  # not in drawing order: recompute
    compiled = kinematics(puma)
    low, high = compiled.ranges[:, 0], compiled.ranges[:, 1]
    Q = low + (high - low) * np.random.default_rng(4).random((3000, low.size))
    drawn = {tuple(v) for v in np.floor(compiled.fkine(Q[:k])[:, :3, 3] / h).astype(int)}
    assert sampled.lost_share == pytest.approx(1 - len(keys) / len(drawn))
    assert tips.shape[0] == 3000 and np.array_equal(again.points, sampled.points)


def test_the_same_seed_on_any_executor_and_a_sobol_draw(puma, sampled):
    with ThreadPoolExecutor(2) as pool:
        spread = workspace(puma, 3000, seed=4, executor=pool)
    assert np.array_equal(spread.points, sampled.points)
    assert spread.volume == sampled.volume and spread.lost_share == sampled.lost_share
    sobol = workspace(puma, 1024, seed=1, sampler="sobol", voxel=100.0)
    assert sobol.samples == 1024 and sobol.voxel == 100.0 and sobol.points.shape[0] > 0
    assert not np.array_equal(workspace(puma, 1024, seed=2).points[:5], sobol.points[:5])


def test_files_open_in_numpy_and_trimesh(sampled, tmp_path):
    trimesh = pytest.importorskip("trimesh")
    npz = sampled.save(tmp_path / "w.npz")
    with np.load(npz) as data:
        assert np.array_equal(data["points"], sampled.points)
        assert float(data["volume"]) == sampled.volume
    cloud = trimesh.load(sampled.save(tmp_path / "w.ply"))
    assert np.allclose(np.asarray(cloud.vertices), sampled.points)
    with pytest.raises(InvalidParameterError, match=r"\.npz or \.ply"):
        sampled.save(tmp_path / "w.txt")


def test_a_picture(puma, sampled, tmp_path):
    import matplotlib

    matplotlib.use("Agg")
    fig = sampled.show(puma, units="mm")
    fig.savefig(tmp_path / "w.png")
    assert (tmp_path / "w.png").stat().st_size > 10_000
    assert "samples" in fig._suptitle.get_text()


def test_a_tree_names_its_tip():
    hand = load_design(DESIGNS / "hand.json")
    with pytest.raises(InvalidParameterError, match="several tips"):
        workspace(hand, 100)
    finger = workspace(hand, 300, tip=4, seed=1)
    compiled = kinematics(hand, 4)
    assert np.allclose(compiled.fkine(finger.configurations)[:, :3, 3], finger.points)


@pytest.mark.parametrize("options, error, words", [
    ({"samples": 0}, InvalidParameterError, "samples must be an integer in"),
    ({"samples": 10**9}, InvalidParameterError, "2,000,000"),
    ({"samples": True}, InvalidTypeError, "samples"),
    ({"voxel": -1.0}, InvalidParameterError, "voxel"),
    ({"sampler": "grid"}, InvalidParameterError, "sampler"),
    ({"seed": -1}, InvalidParameterError, "seed"),
    ({"reachability": -1}, InvalidParameterError, "reachability"),
    ({"reachability": 257}, InvalidParameterError, "MAX_REACHABILITY_DIRECTIONS"),
    ({"reachability": 2.5}, InvalidTypeError, "reachability"),
    ({"manipulability": "yes"}, InvalidTypeError, "manipulability"),
])  # fmt: skip
def test_bad_input_is_one_line(puma, options, error, words):
    arguments = {"samples": 10, **options}
    with pytest.raises(error, match=words) as raised:
        workspace(puma, **arguments)
    assert "\n" not in str(raised.value)


def test_manipulability_per_voxel_is_the_best_of_its_samples(puma):
    mapped = workspace(puma, 1500, seed=7, manipulability=True)
    assert mapped.manipulability.shape == (mapped.voxels.shape[0], 2)
    compiled = kinematics(puma)
    J = compiled.jacob0(mapped.configurations)[:, :, compiled.movable]  # (k, 6, 6)
    translational = np.sqrt(np.linalg.det(J[:, :3] @ J[:, :3].transpose(0, 2, 1)))
    scaled = J.copy()
    scaled[:, :3] /= puma.r
    full = np.abs(np.linalg.det(scaled))  # square: sqrt(det(J J^T)) = |det J|
    voxel = {tuple(k): i for i, k in enumerate(mapped.voxels)}
    best = np.zeros((mapped.voxels.shape[0], 2))
    for point, t, f in zip(mapped.points, translational, full, strict=True):
        i = voxel[tuple(np.floor(point / mapped.voxel).astype(int))]
        best[i] = np.maximum(best[i], (t, f))
    assert np.allclose(mapped.manipulability, best, rtol=1e-9, atol=0)
    assert (mapped.manipulability > 0).all()
    assert mapped.reachability is None and mapped.directions is None


def test_approach_directions_cover_the_sphere():
    d = approach_directions(64)
    assert d.shape == (64, 3) and np.allclose(np.linalg.norm(d, axis=1), 1.0)
    assert np.allclose(d[0], (0, 0, 1)) and np.allclose(d[-1], (0, 0, -1))
    assert np.linalg.norm(d.mean(axis=0)) < 0.05  # evenly spread: no side favoured
    assert np.allclose(approach_directions(1), [[0, 0, 1]])


def test_reachability_index_counts_the_clear_answers(puma, tmp_path):
    mapped = workspace(puma, 200, seed=3, voxel=10 * puma.r, reachability=4)
    v = mapped.voxels.shape[0]
    assert mapped.reachability.shape == (v,) and mapped.directions.shape == (4, 3)
    assert np.all((mapped.reachability * 4) % 1 == 0)
    assert 0 < mapped.reachability.mean() < 1
    # one voxel again, by hand: its clear sample nearest the centre, each direction solved
    i = int(np.argmax(mapped.reachability))
    inside = np.flatnonzero((np.floor(mapped.points / mapped.voxel) == mapped.voxels[i]).all(1))
    centre = (mapped.voxels[i] + 0.5) * mapped.voxel
    point = mapped.points[inside[np.argmin(np.linalg.norm(mapped.points[inside] - centre,
                                                          axis=1))]]  # fmt: skip
    ok = [solve(puma, Target(point, axis=d), seed=0).ok for d in mapped.directions]
    assert np.mean(ok) == mapped.reachability[i]
    with np.load(mapped.save(tmp_path / "mapped.npz")) as data:
        assert np.array_equal(data["reachability"], mapped.reachability)
        assert data["directions"].shape == (4, 3)
