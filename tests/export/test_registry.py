"""export(): dispatch on the suffix, chains and patterns, lazy exporters, atomic writes."""

from __future__ import annotations

import io
import os
import sys
import types

import pytest

from kinegami.errors import InvalidParameterError, InvalidTypeError, KinegamiError
from kinegami.export import ExportError, register_exporter, registry, save_pattern
from kinegami.export.registry import (
    FORMATS,
    ExporterUnavailableError,
    export,
    known_formats,
    register,
    write_atomic_bytes,
    write_atomic_files,
)

BUILT_IN = (".dxf", ".svg", ".fold", ".pdf", ".stl", ".obj", ".urdf")
CHAIN_ONLY = (".stl", ".obj", ".urdf")


def listing(folder) -> list[str]:
    out = []
    for root, dirs, files in os.walk(folder):
        for name in dirs + files:
            out.append(os.path.relpath(os.path.join(root, name), folder))
    return sorted(out)


@pytest.fixture
def formats(monkeypatch):
    """The registry (FORMATS) restored after the test."""
    monkeypatch.setattr(registry, "FORMATS", dict(FORMATS))
    return registry.FORMATS


# --- formats -------------------------------------------------------------------------------


def test_known_formats_describe_every_suffix():
    known = known_formats()
    assert set(BUILT_IN) <= set(known)
    assert list(known) == sorted(known)
    assert all(isinstance(text, str) and text for text in known.values())
    assert "URDF" in known[".urdf"] and "STL" in known[".stl"] and "PDF" in known[".pdf"]


@pytest.mark.parametrize("suffix", [s for s in BUILT_IN if s != ".fold"])
def test_every_format_from_a_chain(tmp_path, example_1a, suffix):
    path = export(example_1a, tmp_path / f"chain{suffix.upper()}")
    assert path == tmp_path / f"chain{suffix.upper()}"
    data = path.read_bytes()
    assert data
    start = {".dxf": b"  0\nSECTION", ".svg": b"<?xml", ".pdf": b"%PDF", ".obj": b"# kinegami",
             ".urdf": b"<?xml"}.get(suffix)  # fmt: skip
    if start is not None:
        assert data.startswith(start)
    expected = [path.name] + (["chain_meshes"] if suffix == ".urdf" else [])
    assert [p for p in listing(tmp_path) if "/" not in p] == sorted(expected)


def test_fold_is_registered_lazily(tmp_path, example_1a, monkeypatch):
    """.fold is imported on first use; without kinegami/export/fold.py only .fold (and the
    Origami Simulator SVG, drawn from the FOLD export's graph) fails."""
    assert FORMATS[".fold"].func == "kinegami.export.fold:fold_data"
    monkeypatch.setitem(sys.modules, "kinegami.export.fold", None)  # as if the file were missing
    with pytest.raises(ExporterUnavailableError, match="kinegami.export.fold"):
        export(example_1a, tmp_path / "chain.fold")
    assert listing(tmp_path) == []
    export(example_1a, tmp_path / "chain.svg", flavour="laser")
    assert listing(tmp_path) == ["chain.svg"]


def test_fold_gets_the_chain_and_its_options(tmp_path, example_1a, monkeypatch):
    """fold_data takes a pattern or a chain: the chain and all options are passed on."""
    calls = []

    def fold_data(obj, **options):
        calls.append((obj, options))
        return '{"file_spec": 1.1}\n'

    module = types.ModuleType("kinegami.export.fold")
    module.fold_data = fold_data
    monkeypatch.setitem(sys.modules, "kinegami.export.fold", module)
    path = export(example_1a, tmp_path / "chain.fold", twistPortion=0.3, units="cm")
    assert path.read_text() == '{"file_spec": 1.1}\n'
    assert calls == [(example_1a, {"twistPortion": 0.3, "units": "cm"})]


def test_missing_exporter_module_fails_only_when_used(tmp_path, example_1a, formats):
    register(".xyz", "kinegami.export.no_such_module:write", "chain", description="test")
    assert "kinegami.export.no_such_module" not in sys.modules
    assert known_formats()[".xyz"] == "test"
    export(example_1a, tmp_path / "ok.obj")  # other formats still work
    with pytest.raises(ExporterUnavailableError, match="no_such_module") as info:
        export(example_1a, tmp_path / "bad.xyz")
    assert isinstance(info.value, ImportError) and isinstance(info.value, KinegamiError)
    register(".xyz", "kinegami.export.mesh:no_such_function", "chain")
    with pytest.raises(ExporterUnavailableError, match="no_such_function"):
        export(example_1a, tmp_path / "bad.xyz")
    assert listing(tmp_path) == ["ok.obj"]


def test_chain_for_a_pattern_format_is_its_crease_pattern(tmp_path, example_1a):
    for twist in (None, 0.5):
        options = {} if twist is None else {"twistPortion": twist}
        exported = export(example_1a, tmp_path / f"chain{twist}.svg", **options)
        pattern = example_1a.creasePattern(0.2 if twist is None else twist)
        saved = save_pattern(pattern, tmp_path / f"pattern{twist}.svg")
        assert exported.read_bytes() == saved.read_bytes()
    differs = tmp_path / "chainNone.svg", tmp_path / "chain0.5.svg"
    assert differs[0].read_bytes() != differs[1].read_bytes()


def test_pattern_formats_take_patterns(tmp_path, example_1a):
    pattern = example_1a.creasePattern()
    export(pattern, tmp_path / "p.svg", units="cm")
    save_pattern(pattern, tmp_path / "q.svg", units="cm")
    assert (tmp_path / "p.svg").read_bytes() == (tmp_path / "q.svg").read_bytes()
    assert export(pattern, tmp_path / "p.dxf").read_text().count("AcDbLine") > 100
    with pytest.raises(InvalidTypeError, match="twistPortion"):
        export(pattern, tmp_path / "p.svg", twistPortion=0.3)  # only chains have one


def test_exporters_registered_with_register_exporter_are_used(tmp_path, example_1a, formats):
    def write_count(pattern, stream, **options):
        stream.write(f"{pattern.numEdges}\n")

    register_exporter(".count", write_count)
    assert ".count" in known_formats()
    path = export(example_1a, tmp_path / "p.count")
    assert path.read_text() == f"{example_1a.creasePattern().numEdges}\n"
    # replacing the DXF writer through register_exporter changes what export() writes
    register_exporter(".dxf", write_count)
    assert export(example_1a, tmp_path / "p.dxf").read_text() == path.read_text()


def test_register_a_binary_chain_format(tmp_path, example_1a, formats):
    def joints_data(chain, **options):
        return bytes([len(chain.Joints)]) * options.get("repeat", 1)

    register(".jnt", joints_data, accepts="chain", binary=True, description="joint count")
    assert formats[".jnt"].binary
    assert export(example_1a, tmp_path / "c.jnt", repeat=3).read_bytes() == b"\x07\x07\x07"
    with pytest.raises(InvalidTypeError, match="KinematicChain"):
        export(example_1a.creasePattern(), tmp_path / "p.jnt")


@pytest.mark.parametrize(
    ("args", "kwargs", "error"),
    [
        (("stl", print), {}, InvalidParameterError),
        ((".a.b", print), {}, InvalidParameterError),
        ((".x", 42), {}, InvalidTypeError),
        ((".x", "no colon"), {}, InvalidTypeError),
        ((".x", print), {"accepts": "tree"}, InvalidParameterError),
        ((".x", print), {"binary": True, "files": True}, InvalidParameterError),
        ((".x", print), {"binary": "yes"}, InvalidTypeError),
    ],
)
def test_register_checks_its_arguments(formats, args, kwargs, error):
    with pytest.raises(error):
        register(*args, **kwargs)
    assert ".x" not in formats


# --- bad input -----------------------------------------------------------------------------


@pytest.mark.parametrize("name", ["robot.step", "robot", "robot.stl.bak", ".stl"])
def test_unknown_suffix_names_the_known_ones(tmp_path, example_1a, name):
    with pytest.raises(InvalidParameterError) as info:
        export(example_1a, tmp_path / name)
    for suffix in BUILT_IN:
        assert suffix in str(info.value)
    assert listing(tmp_path) == []


@pytest.mark.parametrize("name", [None, "", "  "])
def test_missing_file_name(example_1a, name):
    with pytest.raises(InvalidParameterError):
        export(example_1a, name)


def test_file_name_of_wrong_type(example_1a):
    with pytest.raises(InvalidTypeError):
        export(example_1a, 3)
    with pytest.raises(InvalidTypeError):
        export(example_1a, b"robot.stl")


def test_directory_is_not_a_file_name(tmp_path, example_1a):
    (tmp_path / "robot.stl").mkdir()
    with pytest.raises(InvalidParameterError, match="directory"):
        export(example_1a, tmp_path / "robot.stl")


@pytest.mark.parametrize("suffix", CHAIN_ONLY)
def test_chain_formats_reject_other_objects(tmp_path, example_1a, suffix):
    for obj in (example_1a.creasePattern(), example_1a.Joints[0], "chain"):
        with pytest.raises(InvalidTypeError, match="KinematicChain"):
            export(obj, tmp_path / f"x{suffix}")
    assert listing(tmp_path) == []


@pytest.mark.parametrize("suffix", [".dxf", ".svg", ".pdf"])
def test_pattern_formats_reject_other_objects(tmp_path, suffix):
    with pytest.raises(InvalidTypeError, match="TubularPattern or a KinematicChain"):
        export({"edges": []}, tmp_path / f"x{suffix}")
    assert listing(tmp_path) == []


@pytest.mark.parametrize("suffix", [".obj", ".stl", ".urdf", ".pdf", ".svg"])
def test_folder_that_cannot_be_written(tmp_path, example_1a, suffix):
    """The parent is a regular file (the tests run as root, so permissions cannot be used)."""
    blocker = tmp_path / "blocker"
    blocker.write_text("not a folder")
    for target in (blocker / f"x{suffix}", blocker / "deeper" / f"x{suffix}"):
        with pytest.raises(ExportError) as info:
            export(example_1a, target)
        assert isinstance(info.value, OSError)
    assert listing(tmp_path) == ["blocker"]
    assert blocker.read_text() == "not a folder"


def test_bad_option_writes_nothing(tmp_path, example_1a):
    for suffix, options in ((".stl", {"units": "furlong"}), (".pdf", {"paper": "A0"}),
                            (".obj", {"bogus": 1}), (".dxf", {"scale": -1})):  # fmt: skip
        with pytest.raises((InvalidParameterError, InvalidTypeError)):
            export(example_1a, tmp_path / f"x{suffix}", **options)
    assert listing(tmp_path) == []


def test_exporter_failing_midway_leaves_nothing(tmp_path, example_1a, formats):
    def half_then_fail(chain, **options):
        raise OSError(5, "Input/output error")

    register(".half", half_then_fail, "chain", binary=True)
    with pytest.raises(ExportError, match="Input/output error"):
        export(example_1a, tmp_path / "x.half")
    assert listing(tmp_path) == []


def test_existing_file_replaced_and_kept_on_failure(tmp_path, example_1a, monkeypatch):
    path = export(example_1a, tmp_path / "robot.stl")
    original = path.read_bytes()
    example_1a.setJointStates([0, 0, 1.0, 0, 0.5, 0, 0])
    real_replace = os.replace

    def failing(src, dst):
        raise OSError(28, "No space left on device")

    monkeypatch.setattr(os, "replace", failing)
    with pytest.raises(ExportError, match="No space left"):
        export(example_1a, path)
    assert listing(tmp_path) == ["robot.stl"] and path.read_bytes() == original
    monkeypatch.setattr(os, "replace", real_replace)
    export(example_1a, path)
    assert path.read_bytes() != original


# --- atomic writers ------------------------------------------------------------------------


def test_write_atomic_bytes(tmp_path):
    path = tmp_path / "a" / "b.bin"
    write_atomic_bytes(path, b"\x00\x01\xff")
    assert path.read_bytes() == b"\x00\x01\xff"
    assert listing(tmp_path) == ["a", "a/b.bin"]


def test_write_atomic_files_writes_a_set(tmp_path):
    main = tmp_path / "m.txt"
    write_atomic_files(main, {"m.txt": b"main", "parts/a.bin": b"a", "parts/sub/b.bin": b"b"})
    assert listing(tmp_path) == ["m.txt", "parts", "parts/a.bin", "parts/sub", "parts/sub/b.bin"]
    # a second write replaces the folder as a whole
    write_atomic_files(main, {"m.txt": b"main 2", "parts/c.bin": b"c"})
    assert listing(tmp_path) == ["m.txt", "parts", "parts/c.bin"]
    assert main.read_bytes() == b"main 2"


def test_write_atomic_files_failing_midway_restores(tmp_path, monkeypatch):
    main = tmp_path / "m.txt"
    write_atomic_files(main, {"m.txt": b"old", "parts/a.bin": b"a"})
    real_write = type(main).write_bytes
    calls = []

    def failing_write(self, data):
        calls.append(self.name)
        if len(calls) == 2:
            raise OSError(28, "No space left on device")
        return real_write(self, data)

    monkeypatch.setattr(type(main), "write_bytes", failing_write)
    with pytest.raises(ExportError, match="No space left"):
        write_atomic_files(main, {"m.txt": b"new", "parts/x.bin": b"x", "parts/y.bin": b"y"})
    monkeypatch.undo()
    assert listing(tmp_path) == ["m.txt", "parts", "parts/a.bin"]
    assert main.read_bytes() == b"old"


@pytest.mark.parametrize(
    "files",
    [
        {"other.txt": b"no main file"},
        {"m.txt": b"x", "../escape.txt": b"x"},
        {"m.txt": b"x", "/abs.txt": b"x"},
        {"m.txt": "text, not bytes"},
    ],
)
def test_write_atomic_files_rejects_bad_sets(tmp_path, files):
    with pytest.raises(KinegamiError):
        write_atomic_files(tmp_path / "m.txt", files)
    assert listing(tmp_path) == []


def test_interrupt_during_files_write_cleans_up(tmp_path, monkeypatch):
    main = tmp_path / "m.txt"
    real_replace = os.replace

    def interrupted(src, dst):
        if os.fspath(dst) == os.fspath(main):
            raise KeyboardInterrupt
        return real_replace(src, dst)

    monkeypatch.setattr(os, "replace", interrupted)
    with pytest.raises(KeyboardInterrupt):
        write_atomic_files(main, {"m.txt": b"main", "parts/a.bin": b"a"})
    assert listing(tmp_path) == []


def test_obj_through_export_is_the_writer_output(tmp_path, example_1a):
    from kinegami.export.mesh import write_obj

    stream = io.StringIO()
    write_obj(example_1a, stream, units="cm")
    path = export(example_1a, tmp_path / "c.obj", units="cm")
    assert path.read_text(encoding="utf-8") == stream.getvalue()


# --- one registry: every format from every entry point -------------------------------------


def test_one_registry_behind_every_name():
    import kinegami
    from kinegami import export as from_package
    from kinegami.export import EXPORTERS
    from kinegami.export import export as from_subpackage

    assert from_package is kinegami.export is from_subpackage is export is registry.export
    assert sys.modules["kinegami.export.registry"] is registry
    assert set(EXPORTERS) == {s for s, fmt in FORMATS.items() if fmt.accepts != "chain"}
    assert all(EXPORTERS[s] is FORMATS[s] for s in EXPORTERS)
    with pytest.raises(TypeError):
        EXPORTERS[".dxf"] = None  # a read-only view: register() changes the registry


@pytest.mark.parametrize("suffix", sorted(FORMATS))
def test_every_registered_suffix_from_export_and_save(tmp_path, example_1a, suffix):
    """export(chain, path) writes every format; pattern.save(path) and save_pattern every
    format that takes a pattern (the others name the KinematicChain they need)."""
    pattern = example_1a.creasePattern()
    assert export(example_1a, tmp_path / "chain" / f"c{suffix}").stat().st_size > 0
    if FORMATS[suffix].accepts == "chain":
        with pytest.raises(InvalidTypeError, match="KinematicChain"):
            pattern.save(tmp_path / "pattern" / f"p{suffix}")
        return
    saved = pattern.save(tmp_path / "pattern" / f"p{suffix}")
    exported = export(pattern, tmp_path / "pattern" / f"q{suffix}")
    assert saved == tmp_path / "pattern" / f"p{suffix}"
    if suffix in (".svg", ".fold"):  # no creation time or GUID in the file
        assert saved.read_bytes() == exported.read_bytes()
    if suffix == ".svg":  # a chain's FOLD keeps the chain's frame; its SVG is its pattern's
        assert saved.read_bytes() == (tmp_path / "chain" / f"c{suffix}").read_bytes()


def test_pattern_save_writes_a_pdf(tmp_path, example_1a):
    path = example_1a.creasePattern().save(tmp_path / "x.pdf")
    assert path.read_bytes().startswith(b"%PDF")


def test_missing_library_names_the_extra_to_install(tmp_path, example_1a, monkeypatch):
    """A library an exporter imports when it runs (matplotlib for PDF) is missing: an
    ExporterUnavailableError (a KinegamiError and an ImportError) saying what to install."""
    monkeypatch.setitem(sys.modules, "matplotlib.backends.backend_pdf", None)
    with pytest.raises(ExporterUnavailableError, match=r"pip install 'kinegami\[pdf\]'") as info:
        example_1a.creasePattern().save(tmp_path / "x.pdf")
    assert isinstance(info.value, ImportError) and isinstance(info.value, KinegamiError)
    assert "matplotlib" in str(info.value)
    assert listing(tmp_path) == []


def test_exporter_returning_the_wrong_type_writes_nothing(tmp_path, example_1a, formats):
    register(".bad", lambda chain, **options: 42, "chain")
    with pytest.raises(KinegamiError, match="returned int"):
        export(example_1a, tmp_path / "x.bad")
    assert listing(tmp_path) == []


def test_text_exporters_return_the_file(example_1a):
    """The exporters behind the registry return the data; the stream writers write it."""
    from kinegami.export import dxf, fold, mesh, svg

    pattern = example_1a.creasePattern()
    for data, writer in ((svg.svg_data, svg.write_svg), (fold.fold_data, fold.write_fold),
                         (mesh.obj_data, mesh.write_obj)):  # fmt: skip
        subject = example_1a if data is mesh.obj_data else pattern
        stream = io.StringIO()
        writer(subject, stream)
        assert stream.getvalue() == data(subject)
    assert isinstance(dxf.dxf_data(pattern), str)
    assert isinstance(mesh.stl_data(example_1a), bytes)
