"""save_pattern: suffix dispatch, file-name checks, folders, atomic writes."""

import errno
import os
from pathlib import Path

import pytest

from kinegami.errors import InvalidParameterError, InvalidTypeError, KinegamiError
from kinegami.export import ExportError, register_exporter, registry, save_pattern


def _files(folder: Path) -> list[str]:
    return sorted(p.name for p in folder.iterdir())


@pytest.mark.parametrize("name", ["p.dxf", "p.svg", "P.DXF", "p.Svg"])
def test_dispatch_on_suffix(tmp_path, revolute6, name):
    path = save_pattern(revolute6, tmp_path / name)
    assert path == tmp_path / name
    text = path.read_text(encoding="utf-8")
    if name.lower().endswith(".dxf"):
        assert "SECTION" in text and "AcDbLine" in text
    else:
        assert text.startswith("<?xml") and "<svg" in text
    assert _files(tmp_path) == [name]


def test_accepts_str_paths(tmp_path, revolute6):
    assert save_pattern(revolute6, str(tmp_path / "p.dxf")).exists()


@pytest.mark.parametrize("name", ["p.step", "p", "p.dxf.bak"])
def test_unknown_suffix_names_the_known_ones(tmp_path, revolute6, name):
    with pytest.raises(InvalidParameterError) as info:
        save_pattern(revolute6, tmp_path / name)
    assert ".dxf" in str(info.value) and ".svg" in str(info.value)
    assert _files(tmp_path) == []


@pytest.mark.parametrize("name", [None, "", "   ", ".dxf"])
def test_missing_or_empty_name(tmp_path, revolute6, name, monkeypatch):
    monkeypatch.chdir(tmp_path)
    with pytest.raises(InvalidParameterError):
        save_pattern(revolute6, name)
    assert _files(tmp_path) == []


def test_name_of_wrong_type(revolute6):
    with pytest.raises(InvalidTypeError):
        save_pattern(revolute6, 42)


def test_directory_is_rejected(tmp_path, revolute6):
    (tmp_path / "folder.dxf").mkdir()
    with pytest.raises(InvalidParameterError, match="directory"):
        save_pattern(revolute6, tmp_path / "folder.dxf")
    with pytest.raises(InvalidParameterError, match="directory"):
        save_pattern(revolute6, str(tmp_path / "new") + os.sep)


def test_pattern_type_checked(tmp_path):
    with pytest.raises(InvalidTypeError):
        save_pattern("pattern", tmp_path / "p.dxf")


def test_missing_parent_folders_are_created(tmp_path, revolute6):
    path = save_pattern(revolute6, tmp_path / "a" / "b" / "c" / "p.dxf")
    assert path.is_file()


def test_file_gets_usual_permissions(tmp_path, revolute6):
    umask = os.umask(0o022)
    try:
        path = save_pattern(revolute6, tmp_path / "p.dxf")
    finally:
        os.umask(umask)
    assert path.stat().st_mode & 0o777 == 0o644


def test_existing_file_replaced(tmp_path, revolute6):
    path = tmp_path / "p.svg"
    path.write_text("old")
    save_pattern(revolute6, path)
    assert path.read_text().startswith("<?xml")
    assert _files(tmp_path) == ["p.svg"]


def test_parent_is_a_file(tmp_path, revolute6):
    (tmp_path / "file").write_text("x")
    with pytest.raises(ExportError) as info:
        save_pattern(revolute6, tmp_path / "file" / "p.dxf")
    assert isinstance(info.value, OSError) and isinstance(info.value, KinegamiError)
    assert _files(tmp_path) == ["file"]


@pytest.mark.skipif(
    not hasattr(os, "geteuid") or os.geteuid() == 0, reason="root ignores file permissions"
)
def test_read_only_folder(tmp_path, revolute6):
    folder = tmp_path / "ro"
    folder.mkdir()
    folder.chmod(0o500)
    try:
        with pytest.raises(ExportError) as info:
            save_pattern(revolute6, folder / "p.dxf")
        assert info.value.errno == errno.EACCES
        assert _files(folder) == []
    finally:
        folder.chmod(0o700)


def test_exporter_failing_mid_write_leaves_nothing(tmp_path, revolute6, monkeypatch):
    def broken(pattern, stream, **options):
        stream.write("0\nSECTION\n")
        raise KinegamiError("exporter broke half way")

    monkeypatch.setattr(registry, "FORMATS", dict(registry.FORMATS))
    register_exporter(".dxf", broken)
    path = tmp_path / "p.dxf"
    path.write_text("previous")
    with pytest.raises(KinegamiError, match="half way"):
        save_pattern(revolute6, path)
    assert _files(tmp_path) == ["p.dxf"] and path.read_text() == "previous"


def test_disk_write_failure_leaves_no_file_or_temp(tmp_path, revolute6, monkeypatch):
    real_fdopen = os.fdopen

    class Full:
        def __init__(self, stream):
            self.stream = stream

        def __enter__(self):
            return self

        def __exit__(self, *exc):
            self.stream.close()

        def write(self, text):
            self.stream.write(text[: len(text) // 2])
            raise OSError(errno.ENOSPC, "No space left on device")

    monkeypatch.setattr(os, "fdopen", lambda *a, **k: Full(real_fdopen(*a, **k)))
    with pytest.raises(ExportError) as info:
        save_pattern(revolute6, tmp_path / "p.dxf")
    assert info.value.errno == errno.ENOSPC
    assert "No space" in str(info.value)
    assert _files(tmp_path) == []


def test_replace_failure_leaves_no_temp(tmp_path, revolute6, monkeypatch):
    def refuse(src, dst):
        raise PermissionError(errno.EACCES, "Permission denied")

    monkeypatch.setattr(os, "replace", refuse)
    with pytest.raises(ExportError):
        save_pattern(revolute6, tmp_path / "p.svg")
    assert _files(tmp_path) == []


def test_folder_creation_failure(tmp_path, revolute6, monkeypatch):
    def refuse(self, *args, **kwargs):
        raise PermissionError(errno.EACCES, "Permission denied")

    monkeypatch.setattr(Path, "mkdir", refuse)
    with pytest.raises(ExportError, match="folder"):
        save_pattern(revolute6, tmp_path / "new" / "p.dxf")


def test_interrupt_is_reraised_and_cleaned_up(tmp_path, revolute6, monkeypatch):
    def interrupt(src, dst):
        raise KeyboardInterrupt

    monkeypatch.setattr(os, "replace", interrupt)
    with pytest.raises(KeyboardInterrupt):
        save_pattern(revolute6, tmp_path / "p.dxf")
    assert _files(tmp_path) == []


def test_register_exporter(tmp_path, revolute6, monkeypatch):
    monkeypatch.setattr(registry, "FORMATS", dict(registry.FORMATS))

    def write_count(pattern, stream, **options):
        stream.write(f"{pattern.numEdges} {options}\n")

    register_exporter(".TXT", write_count)
    path = save_pattern(revolute6, tmp_path / "p.txt", flag=1)
    assert path.read_text() == f"{revolute6.numEdges} {{'flag': 1}}\n"
    with pytest.raises(InvalidParameterError):
        register_exporter("txt", write_count)
    with pytest.raises(InvalidTypeError):
        register_exporter(".x", "not callable")
