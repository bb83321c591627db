"""Reproducible files (kinegami/export/_reproducible.py): with SOURCE_DATE_EPOCH set, the DXF
and 3MF files record that time and take their identifiers from their content, so building a
design twice gives the same bytes in every format; without it, every DXF gets new GUIDs and the
time of writing, as ezdxf writes them."""

from __future__ import annotations

import datetime
import io
import re
import subprocess
import sys
import zipfile
from pathlib import Path

import ezdxf
import numpy as np
import pytest
from ezdxf.tools import juliandate

from kinegami.errors import InvalidParameterError
from kinegami.export._reproducible import content_uuid, reproducible_3mf, source_date_epoch
from kinegami.export.dxf import dxf_data
from kinegami.pattern import TubeFittingPattern

ROOT = Path(__file__).resolve().parents[2]
DESIGNS = ROOT / "examples" / "designs"
GUID = re.compile(r"\{[0-9A-F]{8}-[0-9A-F]{4}-8[0-9A-F]{3}-[89AB][0-9A-F]{3}-[0-9A-F]{12}\}")
EPOCH = 1_700_000_000  # 2023-11-14T22:13:20 UTC


def _header(text: str) -> dict:
    """The header variables that differ between writes, as written (ezdxf.read would set the
    times to the time of reading); the file must also read back."""
    ezdxf.read(io.StringIO(text))
    lines = text.splitlines()
    found = {}
    for name, kind in (("$TDCREATE", float), ("$TDUPDATE", float), ("$FINGERPRINTGUID", str),
                       ("$VERSIONGUID", str)):  # fmt: skip
        found[name] = kind(lines[lines.index(name) + 2].strip())
    return found


def test_with_source_date_epoch_equal_sheets_give_equal_dxf_files(monkeypatch):
    monkeypatch.setenv("SOURCE_DATE_EPOCH", str(EPOCH))
    tube = TubeFittingPattern(6, 10.0, 30.0)
    text = dxf_data(tube)
    assert dxf_data(TubeFittingPattern(6, 10.0, 30.0)) == text
    header = _header(text)
    # what ezdxf (and AutoCAD) write: the Julian day number plus the fraction since midnight
    julian = juliandate(datetime.datetime(2023, 11, 14, 22, 13, 20))
    assert julian == pytest.approx(2460263 + (22 + 13 / 60 + 20 / 3600) / 24, abs=1e-9)
    assert header["$TDCREATE"] == pytest.approx(julian, abs=1e-9)
    assert header["$TDUPDATE"] == pytest.approx(julian, abs=1e-9)
    assert "2023-11-14T22:13:20+00:00" in text  # ezdxf's metadata of when it was written
    fingerprint, version = header["$FINGERPRINTGUID"], header["$VERSIONGUID"]
    assert GUID.fullmatch(fingerprint) and GUID.fullmatch(version) and fingerprint != version
    # another sheet, or the same sheet with a label, is another drawing
    other = _header(dxf_data(TubeFittingPattern(6, 10.0, 31.0)))["$FINGERPRINTGUID"]
    labelled = _header(dxf_data(tube, label="sheet 1"))["$FINGERPRINTGUID"]
    assert len({fingerprint, other, labelled}) == 3
    # the lines are the ones written without the variable
    monkeypatch.delenv("SOURCE_DATE_EPOCH")

    def entities(dxf: str) -> str:
        start = dxf.index("\nENTITIES\n")
        return dxf[start : dxf.index("\nENDSEC\n", start)]

    assert entities(dxf_data(tube)) == entities(text) and "\nLINE\n" in entities(text)


@pytest.mark.parametrize("value", [None, "", "  "])
def test_without_source_date_epoch_every_dxf_gets_new_guids_and_the_time_now(monkeypatch, value):
    import time

    if value is None:
        monkeypatch.delenv("SOURCE_DATE_EPOCH", raising=False)
    else:
        monkeypatch.setenv("SOURCE_DATE_EPOCH", value)
    assert source_date_epoch() is None
    tube = TubeFittingPattern(4, 10.0, 30.0)
    first, second = _header(dxf_data(tube)), _header(dxf_data(tube))
    assert first["$FINGERPRINTGUID"] != second["$FINGERPRINTGUID"]
    assert first["$VERSIONGUID"] != second["$VERSIONGUID"]
    now = 2440588.0 + time.time() / 86400.0  # 2440588: the day number of 1970-01-01
    assert abs(first["$TDCREATE"] - now) < 60.0 / 86400.0


@pytest.mark.parametrize("epoch", [None, EPOCH])
def test_utc_times_are_the_times_written(monkeypatch, tmp_path, epoch):
    """$TDUCREATE and $TDUUPDATE (UTC) are the time of writing, as $TDCREATE and $TDUPDATE: the
    times written are UTC (time.time() or SOURCE_DATE_EPOCH), not the template's 2019 values."""
    import time

    from kinegami.export import save_pattern

    if epoch is None:
        monkeypatch.delenv("SOURCE_DATE_EPOCH", raising=False)
    else:
        monkeypatch.setenv("SOURCE_DATE_EPOCH", str(epoch))
    path = save_pattern(TubeFittingPattern(4, 10.0, 30.0), tmp_path / "tube.dxf")
    header = ezdxf.readfile(path).header
    # ezdxf.readfile sets $TDCREATE to the time of reading: that one as written in the file
    lines = path.read_text(encoding="utf-8").splitlines()
    written = {name: float(lines[lines.index(name) + 2]) for name in ("$TDCREATE", "$TDUPDATE")}
    assert header["$TDUCREATE"] == written["$TDCREATE"]
    assert header["$TDUUPDATE"] == written["$TDUPDATE"] == header["$TDUPDATE"]
    if epoch is None:
        now = 2440588.0 + time.time() / 86400.0
        assert abs(header["$TDUCREATE"] - now) < 60.0 / 86400.0
    else:
        utc = datetime.datetime.fromtimestamp(epoch, datetime.UTC).replace(tzinfo=None)
        assert header["$TDUCREATE"] == pytest.approx(juliandate(utc), abs=1e-9)
        assert header["$TDUUPDATE"] == pytest.approx(juliandate(utc), abs=1e-9)


@pytest.mark.parametrize("value", ["abc", "-1", "1.5", "1e9", "\u0661\u0662", "9" * 13, "0x10"])
def test_a_bad_source_date_epoch_is_named(monkeypatch, value):
    monkeypatch.setenv("SOURCE_DATE_EPOCH", value)
    with pytest.raises(InvalidParameterError, match="SOURCE_DATE_EPOCH must be a whole number"):
        dxf_data(TubeFittingPattern(4, 10.0, 30.0))
    with pytest.raises(ValueError, match=re.escape(repr(value.strip()))):
        source_date_epoch()


def test_content_uuids_depend_on_content_and_tag():
    a = content_uuid(b"sheet", "a")
    assert a == content_uuid(b"sheet", "a")
    assert len({a, content_uuid(b"sheet", "b"), content_uuid(b"sheets", "a")}) == 3
    assert re.fullmatch(r"[0-9a-f]{8}-[0-9a-f]{4}-8[0-9a-f]{3}-[89ab][0-9a-f]{3}-[0-9a-f]{12}", a)


def test_3mf_files_get_uuids_from_their_content(monkeypatch):
    trimesh = pytest.importorskip("trimesh")
    pytest.importorskip("lxml")
    pytest.importorskip("networkx")
    box = trimesh.creation.box((1.0, 2.0, 3.0))
    monkeypatch.delenv("SOURCE_DATE_EPOCH", raising=False)
    raw = box.export(file_type="3mf")
    assert reproducible_3mf(raw) is raw  # unchanged without the variable
    monkeypatch.setenv("SOURCE_DATE_EPOCH", str(EPOCH))
    first = reproducible_3mf(box.export(file_type="3mf"))
    assert first == reproducible_3mf(box.export(file_type="3mf"))
    assert first != reproducible_3mf(trimesh.creation.box((1.0, 2.0, 4.0)).export(file_type="3mf"))
    with zipfile.ZipFile(io.BytesIO(first)) as archive:
        assert {i.date_time for i in archive.infolist()} == {(2023, 11, 14, 22, 13, 20)}
        model = archive.read("3D/3dmodel.model").decode()
    uuids = re.findall(r'UUID="([^"]+)"', model)
    assert len(uuids) >= 3 and len(set(uuids)) == len(uuids)  # every identifier its own
    loaded = trimesh.load(io.BytesIO(first), file_type="3mf", force="mesh")
    assert np.allclose(sorted(loaded.extents), [1.0, 2.0, 3.0])
    assert loaded.is_watertight and loaded.volume == pytest.approx(6.0)
    monkeypatch.setenv("SOURCE_DATE_EPOCH", "0")  # before 1980: the first date a zip can hold
    with zipfile.ZipFile(io.BytesIO(reproducible_3mf(raw))) as archive:
        assert {i.date_time for i in archive.infolist()} == {(1980, 1, 1, 0, 0, 0)}


def _build(out: Path, *arguments: str, env: dict) -> None:
    command = [sys.executable, "-m", "kinegami", "build", *arguments, "-o", str(out)]
    subprocess.run(command, check=True, capture_output=True, env=env, cwd=ROOT)


def _files(folder: Path) -> dict[str, bytes]:
    return {str(p.relative_to(folder)): p.read_bytes() for p in folder.rglob("*") if p.is_file()}


def test_building_a_design_twice_gives_the_same_bytes_in_every_format(tmp_path):
    import os

    env = {**os.environ, "SOURCE_DATE_EPOCH": str(EPOCH), "MPLBACKEND": "Agg"}
    for run in ("first", "second"):
        _build(tmp_path / run, str(DESIGNS / "example1.json"), "--formats", "all", env=env)
        _build(tmp_path / run / "hand", str(DESIGNS / "hand.json"), "--formats", "dxf,junctions",
               env=env)  # fmt: skip
    first, second = _files(tmp_path / "first"), _files(tmp_path / "second")
    suffixes = {Path(name).suffix for name in first}
    assert {".dxf", ".svg", ".fold", ".pdf", ".stl", ".obj", ".urdf", ".png", ".3mf"} <= suffixes
    assert sorted(first) == sorted(second)
    assert [name for name in first if first[name] != second[name]] == []
    # a bad value is one line and writes nothing, whichever format comes first (numpy's f2py,
    # which scipy imports, would fail on it with a traceback of its own)
    for arguments in ([str(DESIGNS / "example1.json")],
                      [str(DESIGNS / "hand.json"), "--formats", "junctions"]):  # fmt: skip
        for value in ("yesterday", "-5"):
            env["SOURCE_DATE_EPOCH"] = value
            command = [sys.executable, "-m", "kinegami", "build", *arguments, "-o",
                       str(tmp_path / "bad")]  # fmt: skip
            done = subprocess.run(command, capture_output=True, text=True, env=env, cwd=ROOT)
            assert done.returncode == 1 and not (tmp_path / "bad").exists()
            assert done.stderr.count("\n") == 1, done.stderr
            assert "SOURCE_DATE_EPOCH must be a whole number" in done.stderr
            assert repr(value) in done.stderr and "internal error" not in done.stderr
    # an empty one is unset
    env["SOURCE_DATE_EPOCH"] = ""
    _build(tmp_path / "empty", str(DESIGNS / "hand.json"), "--formats", "junctions", env=env)
    assert (tmp_path / "empty" / "hand_junction_0.3mf").stat().st_size > 0
