"""kinegami build draws a large chain's pictures in a second process (BackgroundPictures):
the same files as drawn in this process, its errors as one line, nothing left running."""

from __future__ import annotations

from pathlib import Path

import pytest

from kinegami import cli
from tests.cli.helpers import main_in_process

EXAMPLE = Path(__file__).resolve().parents[2] / "examples" / "designs" / "example1.json"


def _build(tmp_path: Path, name: str, capsys) -> dict[str, bytes]:
    out = tmp_path / name
    assert main_in_process("build", EXAMPLE, "-o", out) == 0, capsys.readouterr().err
    return {p.name: p.read_bytes() for p in sorted(out.iterdir())}


def test_the_background_pictures_are_the_ones_drawn_here(tmp_path, monkeypatch, capsys):
    started = []
    real = cli.BackgroundPictures.__init__

    def counting(self, job):
        started.append(len(job.chain.Joints))
        real(self, job)

    monkeypatch.setattr(cli.BackgroundPictures, "__init__", counting)
    here = _build(tmp_path, "here", capsys)
    assert started == []  # 7 joints: below the threshold
    monkeypatch.setattr(cli, "BACKGROUND_PICTURES_JOINTS", 1)
    monkeypatch.setattr(cli.os, "cpu_count", lambda: 2)
    there = _build(tmp_path, "there", capsys)
    assert started == [7]
    assert sorted(there) == sorted(here)
    assert there["example1_3d.png"] == here["example1_3d.png"]
    assert there["example1_pattern.png"] == here["example1_pattern.png"]


def test_an_error_drawing_in_the_background_is_one_line(tmp_path, monkeypatch, capsys):
    from kinegami.errors import InvalidParameterError

    def failing(job):
        raise InvalidParameterError("pictures: a test failure")

    monkeypatch.setattr(cli, "BACKGROUND_PICTURES_JOINTS", 1)
    monkeypatch.setattr(cli.os, "cpu_count", lambda: 2)
    monkeypatch.setattr(cli, "_png_data", failing)  # inherited by the forked child
    out = tmp_path / "out"
    assert main_in_process("build", EXAMPLE, "-o", out) == 1
    err = capsys.readouterr().err.strip().splitlines()
    assert err == [f"kinegami build: error: {EXAMPLE}: png export: pictures: a test failure"]
    assert not out.exists() or not any(out.iterdir())  # nothing published


@pytest.mark.parametrize("count, cores, wanted", [(200, 2, True), (199, 2, False),
                                                  (500, 1, False)])  # fmt: skip
def test_only_large_chains_on_several_cores(monkeypatch, count, cores, wanted):
    class Chain:
        Joints = [None] * count

    job = cli.BuildJob(Chain(), None)
    formats = cli._parse_formats("dxf,png")
    monkeypatch.setattr(cli.os, "cpu_count", lambda: cores)
    assert cli.BackgroundPictures.wanted(job, formats) is wanted
    assert cli.BackgroundPictures.wanted(job, cli._parse_formats("png")) is False
