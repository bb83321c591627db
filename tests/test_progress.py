"""Progress and cancellation of long work (kinegami.progress, docs/progress.md)."""

from __future__ import annotations

import concurrent.futures
import copy
import time

import numpy as np
import pytest

from kinegami import KinematicChain
from kinegami.clearance import sweep
from kinegami.errors import Cancelled, InvalidTypeError, KinegamiError
from kinegami.optimize import compact
from kinegami.progress import Progress


def _chain() -> KinematicChain:
    return KinematicChain.from_dh(
        [(0, np.pi / 2, 0, 0), (0, 0, 4, 0), (0, -np.pi / 2, 3, 1)], 4, 1
    )


def test_cancelled_is_a_kinegami_error():
    assert issubclass(Cancelled, KinegamiError)


def test_a_callback_sees_every_step_from_zero_to_total():
    calls = []
    with Progress(lambda done, total: calls.append((done, total)), 3) as bar:
        for _ in range(3):
            bar.update()
    assert calls == [(0, 3), (1, 3), (2, 3), (3, 3)]


def test_false_stops_the_work_but_none_goes_on():
    with Progress(lambda done, total: None, 2) as bar:
        bar.update(2)
    with pytest.raises(Cancelled, match="1 of 2"):
        with Progress(lambda done, total: done < 1, 2) as bar:
            bar.update()


@pytest.mark.parametrize("bad", [3, "yes", [1]])
def test_progress_of_the_wrong_type_is_named(bad):
    with pytest.raises(InvalidTypeError, match="progress must be"):
        Progress(bad, 1)
    with pytest.raises(InvalidTypeError, match="progress must be"):
        compact(_chain(), progress=bad)


def test_sweep_reports_its_configurations_and_can_be_cancelled():
    chain = _chain()
    calls = []
    report = sweep(chain, samples=5000, progress=lambda d, t: calls.append((d, t)))
    assert calls[0] == (0, 5000) and calls[-1] == (5000, 5000)
    assert [d for d, _ in calls] == sorted(d for d, _ in calls)
    assert report.samples == 5000
    # the same report as without progress
    assert sweep(chain, samples=5000).colliding == report.colliding
    with pytest.raises(Cancelled):
        sweep(chain, samples=5000, progress=lambda d, t: d == 0)


def test_compact_reports_each_start_and_returns_the_same_design():
    chain = _chain()
    executor = concurrent.futures.ThreadPoolExecutor(1)
    calls = []
    with_progress = compact(chain, executor=executor, starts=2,
                            progress=lambda d, t: calls.append((d, t)))  # fmt: skip
    assert calls[0] == (0, 2) and calls[-1] == (2, 2)
    plain = compact(chain, executor=executor, starts=2, progress=False)
    assert [j.Pose.A.tolist() for j in with_progress.Joints] == [
        j.Pose.A.tolist() for j in plain.Joints
    ]


def test_cancelling_compact_changes_nothing_and_stops_its_workers_promptly():
    chain = _chain()
    before = copy.deepcopy([j.Pose.A for j in chain.Joints])
    begun = time.monotonic()
    with pytest.raises(Cancelled):
        compact(chain, starts=2, progress=lambda d, t: False)
    # generous liveness bound: the local pool's workers are stopped, not waited for
    assert time.monotonic() - begun < 60
    for pose, joint in zip(before, chain.Joints, strict=True):
        np.testing.assert_array_equal(pose, joint.Pose.A)
