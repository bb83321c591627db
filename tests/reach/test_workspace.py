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
from kinegami.reach import kinematics, workspace

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
])  # fmt: skip
def test_bad_input_is_one_line(puma, options, error, words):
    arguments = {"samples": 10, **options}
    with pytest.raises(error, match=words) as raised:
        workspace(puma, **arguments)
    assert "\n" not in str(raised.value)
