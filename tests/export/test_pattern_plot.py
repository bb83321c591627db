"""show_pattern: the matplotlib view of the flat sheet (paper Figure 5(g))."""

import matplotlib.pyplot as plt
import numpy as np
import pytest
from matplotlib.collections import LineCollection
from matplotlib.colors import to_rgba
from matplotlib.figure import Figure
from matplotlib.patches import Rectangle

from kinegami.errors import InvalidParameterError, InvalidTypeError
from kinegami.pattern.sheet import flatten
from kinegami.viz import _backend
from kinegami.viz.pattern_plot import PATTERN_ARTIST_GIDS, show_pattern


def _collections(ax) -> dict:
    return {c.get_gid(): c for c in ax.collections if isinstance(c, LineCollection)}


def test_returns_figure_and_axes_with_colours_and_counts(composite6):
    fig, ax = show_pattern(composite6)
    assert isinstance(fig, Figure) and ax.figure is fig
    sheet = flatten(composite6)
    lines = _collections(ax)
    assert set(lines) == {"mountain", "valley", "boundary", "cut"} <= set(PATTERN_ARTIST_GIDS)
    assert len(lines["valley"].get_segments()) == sheet.count("V")
    assert len(lines["mountain"].get_segments()) == sheet.count("M")
    assert len(lines["boundary"].get_segments()) == 4
    assert len(lines["cut"].get_segments()) == 4
    assert np.allclose(lines["valley"].get_colors(), to_rgba("red"))
    assert np.allclose(lines["mountain"].get_colors(), to_rgba("blue"))
    assert ax.get_aspect() == 1.0


def test_glue_tab_shading(composite6):
    _, ax = show_pattern(composite6)
    tabs = [p for p in ax.patches if isinstance(p, Rectangle) and p.get_gid() == "glue-tab"]
    assert len(tabs) == 2
    sheet = flatten(composite6)
    got = sorted((p.get_x(), p.get_x() + p.get_width()) for p in tabs)
    assert np.allclose(got, sheet.glueTabs)
    _, ax = show_pattern(composite6, showGlueTab=False)
    assert not [p for p in ax.patches if p.get_gid() == "glue-tab"]


def test_options_change_colours_and_hide_outlines(revolute6):
    _, ax = show_pattern(
        revolute6, valleyColor="orange", mountainColor="k", showCut=False, showBoundary=False,
        linewidth=2.5,
    )  # fmt: skip
    lines = _collections(ax)
    assert set(lines) == {"mountain", "valley"}
    assert np.allclose(lines["valley"].get_colors(), to_rgba("orange"))
    assert np.allclose(lines["mountain"].get_linewidths(), 2.5)


def test_creases_on_cut_can_be_hidden(revolute6):
    _, ax = show_pattern(revolute6, showCreasesOnCut=False)
    expected = flatten(revolute6, skip_creases_on_cut=True).count("M")
    assert len(_collections(ax)["mountain"].get_segments()) == expected


def test_saves_png(tmp_path, composite6):
    fig, _ = show_pattern(composite6, title="composite")
    path = tmp_path / "pattern.png"
    fig.savefig(path, dpi=60)
    assert path.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_draws_into_given_axes(revolute6):
    fig, ax = plt.subplots()
    got_fig, got_ax = show_pattern(revolute6, ax=ax)
    assert got_fig is fig and got_ax is ax
    assert len(plt.get_fignums()) == 1


def test_unknown_option_is_named(revolute6):
    with pytest.raises(InvalidTypeError, match="valleyColour"):
        show_pattern(revolute6, valleyColour="red")


@pytest.mark.parametrize(
    ("options", "error"),
    [
        ({"valleyColor": "not-a-colour"}, InvalidParameterError),
        ({"linewidth": 0}, InvalidParameterError),
        ({"linewidth": "1"}, InvalidTypeError),
        ({"glueTabOpacity": 2.0}, InvalidParameterError),
        ({"showGlueTab": 1}, InvalidTypeError),
        ({"block": "no"}, InvalidTypeError),
        ({"ax": "axes"}, InvalidTypeError),
        ({"title": 3}, InvalidTypeError),
    ],
)
def test_bad_option_values(revolute6, options, error):
    with pytest.raises(error):
        show_pattern(revolute6, **options)


def test_show_not_called_on_headless_backend(revolute6, monkeypatch):
    calls = []
    monkeypatch.setattr(plt, "show", lambda *a, **k: calls.append(k))
    show_pattern(revolute6)
    assert calls == []


def test_show_called_on_interactive_backend_only_for_own_figure(revolute6, monkeypatch):
    calls = []
    monkeypatch.setattr(plt, "show", lambda *a, **k: calls.append(k))
    monkeypatch.setattr(_backend, "backend_is_interactive", lambda: True)
    show_pattern(revolute6, block=False)
    assert calls == [{"block": False}]
    show_pattern(revolute6)
    assert calls[-1] == {}
    _, ax = plt.subplots()
    show_pattern(revolute6, ax=ax)
    assert len(calls) == 2


def test_pattern_type_checked():
    with pytest.raises(InvalidTypeError):
        show_pattern(None)
