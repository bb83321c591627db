"""DXF export: round trip through ezdxf, layers, colours, units, perforation, speed."""

from collections import defaultdict

import ezdxf
import numpy as np
import pytest
from numpy.testing import assert_allclose

from kinegami.errors import InvalidParameterError, InvalidTypeError
from kinegami.export import save_pattern
from kinegami.export._options import dash_segments
from kinegami.export.dxf import dxf_document
from kinegami.pattern.sheet import flatten

from .conftest import build
from .helpers import lengths, point_segment_distance
from .reference_values import (
    CLIPPED_COUNTS,
    DXF_INSUNITS_MM,
    DXF_LAYER_COLORS,
    DXF_MEASUREMENT_METRIC,
    DXF_VERSION_CODE,
    OUTLINE_LINES,
    UNITS_IN_MM,
)

LAYER_KIND = {"Mountain": "M", "Valley": "V", "Boundary": "B", "Cut": "C"}


def read_lines(path):
    """{layer: (k, 2, 2) array of LINE ends} and the document, read back with ezdxf."""
    doc = ezdxf.readfile(path)
    by_layer = defaultdict(list)
    for entity in doc.modelspace():
        assert entity.dxftype() == "LINE"
        s, e = entity.dxf.start, entity.dxf.end
        by_layer[entity.dxf.layer].append([[s.x, s.y], [e.x, e.y]])
    return {k: np.array(v).reshape(-1, 2, 2) for k, v in by_layer.items()}, doc


def test_round_trip_header_layers_counts_lengths(tmp_path, composite6):
    path = save_pattern(composite6, tmp_path / "composite.dxf")
    lines, doc = read_lines(path)
    auditor = doc.audit()
    assert not auditor.has_errors, [str(e) for e in auditor.errors]
    assert doc.dxfversion == DXF_VERSION_CODE
    assert doc.header["$INSUNITS"] == DXF_INSUNITS_MM
    assert doc.header["$MEASUREMENT"] == DXF_MEASUREMENT_METRIC
    sheet = flatten(composite6)
    for layer, color in DXF_LAYER_COLORS.items():
        assert doc.layers.get(layer).dxf.color == color
        kind = LAYER_KIND[layer]
        assert lines[layer].shape[0] == sheet.count(kind)
        assert_allclose(lengths(lines[layer]).sum(), sheet.total_length(kind), rtol=1e-10)
        assert_allclose(
            np.sort(lines[layer].ravel()), np.sort(sheet.select(kind).ravel()), atol=1e-9
        )


def test_every_entity_has_its_explicit_colour(tmp_path, revolute6):
    _, doc = read_lines(save_pattern(revolute6, tmp_path / "r.dxf"))
    for entity in doc.modelspace():
        assert entity.dxf.hasattr("color")
        assert entity.dxf.color == DXF_LAYER_COLORS[entity.dxf.layer]
        assert entity.dxf.linetype == "BYLAYER"


def test_handles_unique_and_below_handseed(tmp_path, revolute6):
    _, doc = read_lines(save_pattern(revolute6, tmp_path / "r.dxf"))
    handles = [int(e.dxf.handle, 16) for e in doc.entitydb.values()]
    assert len(handles) == len(set(handles))
    assert max(handles) < int(doc.header["$HANDSEED"], 16)


@pytest.mark.parametrize("name", list(CLIPPED_COUNTS))
def test_clipped_counts_in_the_file(tmp_path, name):
    spec, (mountains, valleys) = CLIPPED_COUNTS[name]
    lines, _ = read_lines(save_pattern(build(spec), tmp_path / "p.dxf"))
    counts = {layer: lines.get(layer, np.zeros((0, 2, 2))).shape[0] for layer in DXF_LAYER_COLORS}
    assert counts == {
        "Mountain": mountains,
        "Valley": valleys,
        "Boundary": OUTLINE_LINES,
        "Cut": OUTLINE_LINES,
    }


def test_fast_writer_matches_ezdxf_entities(tmp_path, composite6):
    fast, _ = read_lines(save_pattern(composite6, tmp_path / "fast.dxf"))
    dxf_document(composite6).saveas(tmp_path / "slow.dxf")
    slow, slow_doc = read_lines(tmp_path / "slow.dxf")
    assert not slow_doc.audit().has_errors
    assert fast.keys() == slow.keys()
    for layer in fast:
        assert_allclose(fast[layer], slow[layer], atol=1e-9)


@pytest.mark.parametrize("units", list(UNITS_IN_MM))
def test_units_scale_lengths(tmp_path, revolute6, units):
    base, _ = read_lines(save_pattern(revolute6, tmp_path / "mm.dxf"))
    scaled, doc = read_lines(save_pattern(revolute6, tmp_path / f"{units}.dxf", units=units))
    assert doc.header["$INSUNITS"] == DXF_INSUNITS_MM  # the file stays in millimetres
    for layer in base:
        assert_allclose(scaled[layer], UNITS_IN_MM[units] * base[layer], rtol=1e-10, atol=1e-9)


def test_scale_multiplies_units(tmp_path, revolute6):
    base, _ = read_lines(save_pattern(revolute6, tmp_path / "mm.dxf"))
    scaled, _ = read_lines(save_pattern(revolute6, tmp_path / "s.dxf", units="cm", scale=2.5))
    for layer in base:
        assert_allclose(scaled[layer], 25.0 * base[layer], rtol=1e-10, atol=1e-9)


def test_perforation_dash_counts_and_lengths(tmp_path, revolute6):
    dash, gap, scale = 0.7, 0.4, 5.0
    lines, doc = read_lines(
        save_pattern(revolute6, tmp_path / "p.dxf", scale=scale, dash=dash, gap=gap)
    )
    assert not doc.audit().has_errors
    sheet = flatten(revolute6)
    for layer, kind in (("Mountain", "M"), ("Valley", "V")):
        folds = sheet.select(kind) * scale
        L = lengths(folds)
        period = dash + gap
        counts = np.ceil(L / period).astype(int)
        expected = sum(
            min(dash, ell - k * period) for ell, c in zip(L, counts, strict=True) for k in range(c)
        )
        got = lines[layer]
        assert got.shape[0] == counts.sum()
        assert_allclose(lengths(got).sum(), expected, rtol=1e-9)
        assert (lengths(got) <= dash + 1e-9).all()
    for layer in ("Boundary", "Cut"):
        assert lines[layer].shape[0] == OUTLINE_LINES


def test_dashes_cover_each_fold_line_with_the_requested_gaps():
    seg = np.array([[[1.0, 2.0], [1.0 + 3.0 * 3.3, 2.0 + 4.0 * 3.3]]])  # length 16.5
    dashes, source = dash_segments(seg, 2.0, 1.5)
    assert (source == 0).all()
    L = lengths(dashes)
    assert_allclose(L[:-1], 2.0)
    assert 0 < L[-1] <= 2.0
    gaps = np.hypot(*(dashes[1:, 0] - dashes[:-1, 1]).T)
    assert_allclose(gaps, 1.5)
    assert_allclose(dashes[0, 0], seg[0, 0])
    assert_allclose(np.hypot(*(dashes[-1, 1] - seg[0, 0])), min(16.5, 4 * 3.5 + 2.0))
    assert point_segment_distance(dashes.reshape(-1, 2), seg[0, 0], seg[0, 1]).max() < 1e-12
    assert_allclose(L.sum() + gaps.sum(), np.hypot(*(dashes[-1, 1] - dashes[0, 0])))


def test_dashes_of_a_line_shorter_than_one_dash():
    dashes, _ = dash_segments(np.array([[[0.0, 0.0], [0.5, 0.0]]]), 2.0, 1.0)
    assert_allclose(dashes, [[[0.0, 0.0], [0.5, 0.0]]])


def test_dash_ending_exactly_at_the_line_end_leaves_no_empty_dash():
    dashes, _ = dash_segments(np.array([[[0.0, 0.0], [5.0, 0.0]]]), 2.0, 1.0)
    assert_allclose(lengths(dashes), [2.0, 2.0])


def test_perforate_true_uses_default_lengths(tmp_path, revolute6):
    lines, _ = read_lines(save_pattern(revolute6, tmp_path / "p.dxf", scale=10.0, perforate=True))
    assert lines["Mountain"].shape[0] > flatten(revolute6).count("M")
    assert lengths(lines["Mountain"]).max() <= 1.0 + 1e-9


@pytest.mark.parametrize(
    ("options", "error", "match"),
    [
        ({"units": "furlong"}, InvalidParameterError, "units"),
        ({"scale": 0.0}, InvalidParameterError, "scale"),
        ({"scale": "2"}, InvalidTypeError, "scale"),
        ({"perforate": False, "dash": 1.0}, InvalidParameterError, "perforate"),
        ({"dash": -1.0}, InvalidParameterError, "dash"),
        ({"gap": float("nan")}, InvalidParameterError, "gap"),
        ({"perforate": "yes"}, InvalidTypeError, "perforate"),
        ({"colour": "red"}, InvalidTypeError, "colour"),
    ],
)
def test_bad_options(tmp_path, revolute6, options, error, match):
    with pytest.raises(error, match=match):
        save_pattern(revolute6, tmp_path / "bad" / "p.dxf", **options)
    assert not (tmp_path / "bad").exists()


def test_skip_creases_on_cut_option(tmp_path, revolute6):
    lines, _ = read_lines(save_pattern(revolute6, tmp_path / "p.dxf", skip_creases_on_cut=True))
    assert lines["Mountain"].shape[0] == flatten(revolute6, skip_creases_on_cut=True).count("M")


def test_long_pattern_round_trip(tmp_path, long_pattern):
    lines, doc = read_lines(save_pattern(long_pattern, tmp_path / "long.dxf"))
    assert not doc.audit().has_errors
    sheet = flatten(long_pattern)
    for layer, kind in LAYER_KIND.items():
        assert lines[layer].shape[0] == sheet.count(kind)


# --- the stored template: the file ezdxf writes, without importing ezdxf ---------------------


def _normalised(text: str) -> list[str]:
    """DXF text with what differs between two writes (GUIDs, times) blanked, and the CLASSES
    entries (which ezdxf writes in set order) sorted."""
    import re

    text = re.sub(r"\{[0-9A-F]{8}-[0-9A-F-]{27}\}", "{GUID}", text)
    text = re.sub(r"\n\d+\.\d+\.\d+ @ [^\n]+\n", "\nVERSION @ TIME\n", text)
    text = re.sub(r"(\$TDU?(?:CREATE|UPDATE)\n 40\n)[^\n]+", r"\1JULIAN", text)
    start = text.index("  2\nCLASSES\n")
    end = text.index("  0\nENDSEC\n", start)
    classes = sorted(text[start:end].split("  0\nCLASS\n"))
    return [text[:start], *classes, text[end:]]


@pytest.mark.parametrize("options", [{}, {"units": "cm", "perforate": True}, {"scale": 1e-3}])
def test_skeleton_output_is_what_the_installed_ezdxf_writes(composite6, options):
    """The file dxf_data writes is the one the installed ezdxf writes for the same drawing
    (whatever its version: no skip on a version number)."""
    from kinegami.export import dxf
    from kinegami.export._options import resolve_sheet_options, sheet_lines

    segments, kinds, bounds = sheet_lines(composite6, resolve_sheet_options(options, {}, "DXF"))
    skeleton, first, owner = dxf._ezdxf_skeleton(bounds, segments.shape[0])
    cut = skeleton.index("  2\nENTITIES\n") + len("  2\nENTITIES\n")
    lines = dxf._line_entities(segments, kinds, first, owner, bounds)
    by_ezdxf = skeleton[:cut] + lines + skeleton[cut:]
    assert _normalised(dxf.dxf_data(composite6, **options)) == _normalised(by_ezdxf)


def test_shipped_skeleton_is_what_the_installed_ezdxf_writes():
    """kinegami/export/dxf_skeleton.json (package data) equals the skeleton the installed ezdxf
    makes now, but for GUIDs, times and the version string: an ezdxf that writes another
    document fails here (remake the file with python -m kinegami.export.dxf)."""
    import json
    from importlib import resources

    from kinegami.export import dxf

    made = json.loads(dxf.make_skeleton())
    shipped = json.loads(
        resources.files("kinegami.export").joinpath(dxf.SKELETON_FILE).read_text("utf-8")
    )
    assert (made["first_handle"], made["owner"]) == (shipped["first_handle"], shipped["owner"])
    assert _normalised("\n".join(made["lines"])) == _normalised("\n".join(shipped["lines"]))
    stored = dxf.dxf_skeleton()
    assert set(stored.parts[1::2]) == {"XMIN", "YMIN", "XMAX", "YMAX", "HANDSEED", "ENTITIES",
                                       "FINGERPRINTGUID", "VERSIONGUID", "TDCREATE", "TDUCREATE",
                                       "TDUPDATE", "TDUUPDATE", "CREATED", "WRITTEN"}  # fmt: skip
    assert stored.parts[1::2].count("ENTITIES") == 1
    assert stored.first_handle == int(shipped["first_handle"], 16)


def test_skeleton_is_package_data():
    """The skeleton is a data file the package ships (pyproject's package-data), not code."""
    import tomllib
    from pathlib import Path

    from kinegami.export import dxf

    root = Path(__file__).resolve().parents[2]
    config = tomllib.loads((root / "pyproject.toml").read_text("utf-8"))
    patterns = config["tool"]["setuptools"]["package-data"]["kinegami"]
    assert any(Path("export", dxf.SKELETON_FILE).match(p) for p in patterns)
    assert (root / "kinegami" / "export" / dxf.SKELETON_FILE).is_file()


def test_every_file_gets_new_guids(revolute6):
    import re

    from kinegami.export.dxf import dxf_data

    guids = [re.findall(r"\{[0-9A-F-]{36}\}", dxf_data(revolute6)) for _ in range(2)]
    assert len(guids[0]) == 2 and not set(guids[0]) & set(guids[1])


def test_empty_sheet_of_creases_still_opens(tmp_path):
    """A zero-length tube: only the outlines."""
    from kinegami.pattern import TubeFittingPattern

    path = save_pattern(TubeFittingPattern(4, 1.0, 0.0), tmp_path / "flat.dxf")
    lines, doc = read_lines(path)
    assert not doc.audit().has_errors
    assert sum(len(v) for v in lines.values()) >= 2


def test_saving_a_dxf_does_not_import_ezdxf(tmp_path):
    import subprocess
    import sys

    code = (
        "import sys\nfrom kinegami.pattern import TubeFittingPattern\n"
        f"TubeFittingPattern(4, 10.0, 30.0).save({str(tmp_path / 't.dxf')!r})\n"
        "print([m for m in ('ezdxf', 'kinegami.tree', 'kinegami.chain') if m in sys.modules])\n"
    )
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert done.stdout.strip() == "[]"  # nor the chain and tree packages: a pattern is enough
    lines, doc = read_lines(tmp_path / "t.dxf")
    assert doc.units == DXF_INSUNITS_MM and set(lines) <= set(LAYER_KIND)
