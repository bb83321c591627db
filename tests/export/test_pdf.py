"""PDF export: 1:1 sheet tiled over A4 / Letter pages, read back with pypdf."""

from __future__ import annotations

import io
import math
import warnings
from pathlib import Path

import numpy as np
import pypdf
import pytest

from kinegami import pattern as catalog
from kinegami.errors import InvalidParameterError, InvalidTypeError
from kinegami.export.pdf import (
    FOOTER,
    TITLE_STEP,
    draw_page,
    pdf_layout,
    scale_bar_segment,
    write_pdf,
)
from kinegami.export.registry import export
from kinegami.pattern.sheet import flatten

PT = 72.0 / 25.4  # points per mm
PAPER_POINTS = {"A4": (595.28, 841.89), "Letter": (612.0, 792.0)}
PAPER_MM = {"A4": (210.0, 297.0), "Letter": (215.9, 279.4)}
MOUNTAIN = (0.0, 0.0, 1.0)
VALLEY = (1.0, 0.0, 0.0)
LEGEND_SAMPLE = 8.0  # mm of every line style drawn in each page's legend


def pdf_bytes(pattern, **options) -> bytes:
    buffer = io.BytesIO()
    write_pdf(pattern, buffer, **options)
    return buffer.getvalue()


def read(data: bytes) -> pypdf.PdfReader:
    return pypdf.PdfReader(io.BytesIO(data))


def stroked_segments(page) -> list[tuple[tuple[float, ...], np.ndarray]]:
    """(stroke colour, [[x0, y0], [x1, y1]] in points) of every ``m ... l`` in the page."""
    tokens = page.get_contents().get_data().decode("latin-1").split()
    numbers: list[float] = []
    color: tuple[float, ...] = (0.0, 0.0, 0.0)
    saved: list[tuple[float, ...]] = []
    current = None
    out = []
    for token in tokens:
        if token == "q":
            saved.append(color)
        elif token == "Q":
            color = saved.pop()
        elif token == "RG":
            color = tuple(numbers[-3:])
        elif token == "G":
            color = (numbers[-1],) * 3
        elif token == "m":
            current = np.array(numbers[-2:])
        elif token == "l":
            point = np.array(numbers[-2:])
            out.append((color, np.array([current, point])))
            current = point
        else:
            try:
                numbers.append(float(token))
                continue
            except ValueError:
                pass
        numbers = []
    return out


def text_spans(page) -> list[tuple[str, float, float, float]]:
    """(text, left, right, baseline) of every horizontal text shown on a page, mm from the
    page's lower-left corner. The width is the sum of the glyph widths in the font's own
    /Widths table (the exporter's kerning, ignored here, moves the end by < 0.3 mm; a glyph
    outside the table, such as the arrows of the neighbours' labels, counts as the widest)."""
    spans = []

    def visit(text, cm, tm, font, size):
        if not text.strip() or cm[1] != 0.0 or cm[0] <= 0.0:  # rotated: neighbour labels
            return
        widths = [float(w) for w in font["/Widths"].get_object()]
        first, scale = int(font["/FirstChar"]), float(font["/FontMatrix"][0])
        glyphs = [widths[ord(c) - first] if 0 <= ord(c) - first < len(widths) else max(widths)
                  for c in text]  # fmt: skip
        width = sum(glyphs) * scale * size * cm[0]
        x, y = cm[4] + tm[4] * cm[0], cm[5] + tm[5] * cm[3]
        spans.append((text, x / PT, (x + width) / PT, y / PT))

    page.extract_text(visitor_text=visit)
    return spans


def assert_footer_inside(page, margin: float, window_bottom: float) -> list:
    """Every text below the window (the footer) lies within the page less its margins, and
    every text within the page; returns the footer's spans."""
    width, height = float(page.mediabox.width) / PT, float(page.mediabox.height) / PT
    spans = text_spans(page)
    footer = [s for s in spans if s[3] < window_bottom]
    assert footer
    for text, left, right, baseline in spans:
        assert 0.0 <= left and right <= width and 0.0 < baseline < height, text
    for text, left, right, baseline in footer:
        assert left >= margin - 1e-6 and right <= width - margin + 0.3, (text, left, right)
        assert baseline >= margin, text
    return footer


def lengths_mm(segments) -> np.ndarray:
    return np.array([np.linalg.norm(s[1] - s[0]) / PT for s in segments])


def expected_tiling(sheet_w, sheet_h, paper, margin=10.0, overlap=0.0):
    """(pages, orientation) computed from the documented layout: window = paper - 2 margin
    (width) and paper - 2 margin - footer (height); fewer pages wins, portrait on a tie."""
    best = None
    for orientation in ("portrait", "landscape"):
        w, h = PAPER_MM[paper]
        if orientation == "landscape":
            w, h = h, w
        win_w, win_h = w - 2 * margin, h - 2 * margin - 14.0
        cols = 1 if sheet_w <= win_w else math.ceil((sheet_w - overlap) / (win_w - overlap))
        rows = 1 if sheet_h <= win_h else math.ceil((sheet_h - overlap) / (win_h - overlap))
        if best is None or rows * cols < best[0]:
            best = (rows * cols, orientation, rows, cols)
    return best


def sheet_size(pattern, factor):
    sheet = flatten(pattern)
    return (sheet.width + sheet.sideLength) * factor, sheet.height * factor


@pytest.fixture(scope="module")
def example_pattern(example_1a_factory):
    """The crease pattern of the paper's Example 1A (r = 1, n = 4)."""
    return example_1a_factory().creasePattern()


def test_footer_is_the_documented_14_mm():
    assert FOOTER == 14.0


@pytest.mark.parametrize("paper", ["A4", "Letter"])
@pytest.mark.parametrize("scale", [1.0, 4.0, 12.0])
def test_page_count_and_size(example_pattern, paper, scale):
    reader = read(pdf_bytes(example_pattern, paper=paper, scale=scale))
    width, height = sheet_size(example_pattern, scale)
    pages, orientation, rows, cols = expected_tiling(width, height, paper)
    assert len(reader.pages) == pages
    w, h = PAPER_POINTS[paper]
    if orientation == "landscape":
        w, h = h, w
    for page in reader.pages:
        box = page.mediabox
        assert abs(float(box.width) - w) <= 0.5 and abs(float(box.height) - h) <= 0.5


@pytest.mark.parametrize("orientation", ["portrait", "landscape"])
def test_forced_orientation_and_overlap(long_pattern, orientation):
    layout = pdf_layout(long_pattern, scale=2.0, orientation=orientation, overlap=15.0)
    reader = read(pdf_bytes(long_pattern, scale=2.0, orientation=orientation, overlap=15.0))
    width, height = sheet_size(long_pattern, 2.0)
    w, h = PAPER_MM["A4"] if orientation == "portrait" else PAPER_MM["A4"][::-1]
    win_w, win_h = w - 20.0, h - 34.0
    cols = 1 if width <= win_w else math.ceil((width - 15.0) / (win_w - 15.0))
    rows = 1 if height <= win_h else math.ceil((height - 15.0) / (win_h - 15.0))
    assert (layout.rows, layout.cols) == (rows, cols)
    assert len(reader.pages) == rows * cols > 1
    box = reader.pages[0].mediabox
    assert abs(float(box.width) - w * PT) <= 0.5 and abs(float(box.height) - h * PT) <= 0.5
    # neighbouring windows overlap by exactly 15 mm and together cover the sheet
    tiles = layout.tiles
    for a in tiles:
        for b in tiles:
            if (b.row, b.col) == (a.row + 1, a.col):
                assert a.window[1] - b.window[3] == pytest.approx(-15.0)
            if (b.row, b.col) == (a.row, a.col + 1):
                assert a.window[2] - b.window[0] == pytest.approx(15.0)
    xmin, ymin, xmax, ymax = layout.sheet_bounds
    assert min(t.window[0] for t in tiles) <= xmin and max(t.window[2] for t in tiles) >= xmax
    assert min(t.window[1] for t in tiles) <= ymin and max(t.window[3] for t in tiles) >= ymax


def test_lines_are_full_size_on_a_single_page(example_pattern):
    """Every mountain and valley line keeps its length in mm: 1 mm of sheet = 1 mm of paper."""
    scale = 2.0
    reader = read(pdf_bytes(example_pattern, scale=scale))
    assert len(reader.pages) == 1
    segments = stroked_segments(reader.pages[0])
    sheet = flatten(example_pattern)
    content_bottom = (10.0 + FOOTER) * PT
    for color, kind in ((MOUNTAIN, "M"), (VALLEY, "V")):
        drawn = [s for c, s in segments if c == color and s[:, 1].min() > content_bottom - 1e-6]
        expected = np.sort(sheet.lengths()[sheet.kinds == kind] * scale)
        np.testing.assert_allclose(np.sort(lengths_mm(drawn)), expected, atol=1e-3)
        legend = [s for c, s in segments if c == color and s[:, 1].max() < content_bottom]
        np.testing.assert_allclose(lengths_mm(legend), [LEGEND_SAMPLE], atol=1e-3)
    # the creases span the sheet: their extent in mm is the sheet's
    creases = np.array([s for c, s in segments if c in (MOUNTAIN, VALLEY)
                        and s[:, 1].min() > content_bottom - 1e-6])  # fmt: skip
    extent = (creases.reshape(-1, 2).max(axis=0) - creases.reshape(-1, 2).min(axis=0)) / PT
    both = sheet.segments[np.isin(sheet.kinds, ("M", "V"))].reshape(-1, 2)
    np.testing.assert_allclose(extent, (both.max(axis=0) - both.min(axis=0)) * scale, atol=1e-3)


def test_lines_split_over_pages_keep_their_total_length(long_pattern):
    scale = 1.5
    data = pdf_bytes(long_pattern, scale=scale)
    reader = read(data)
    layout = pdf_layout(long_pattern, scale=scale)
    assert len(reader.pages) == layout.page_count > 1
    sheet = flatten(long_pattern)
    for color, kind in ((MOUNTAIN, "M"), (VALLEY, "V")):
        total = sum(
            lengths_mm([s for c, s in stroked_segments(page) if c == color]).sum()
            for page in reader.pages
        )
        total -= LEGEND_SAMPLE * len(reader.pages)
        assert total == pytest.approx(sheet.total_length(kind) * scale, rel=1e-6)
    # on every page the creases stay inside the window
    x, y, w, h = layout.content
    for page in reader.pages:
        creases = [s for c, s in stroked_segments(page) if c in (MOUNTAIN, VALLEY)]
        inside = [s for s in creases if s[:, 1].min() > (y - 1.0) * PT]
        points = np.array(inside).reshape(-1, 2) / PT
        assert points[:, 0].min() >= x - 1e-6 and points[:, 0].max() <= x + w + 1e-6
        assert points[:, 1].min() >= y - 1e-6 and points[:, 1].max() <= y + h + 1e-6


def test_scale_bar_and_crop_marks_on_every_page(long_pattern):
    layout = pdf_layout(long_pattern, scale=1.5, scale_bar=40.0)
    reader = read(pdf_bytes(long_pattern, scale=1.5, scale_bar=40.0))
    bar = scale_bar_segment(layout) * PT
    x, y, w, h = layout.content
    corners = [(x, y), (x + w, y), (x, y + h), (x + w, y + h)]
    for page in reader.pages:
        black = [s for c, s in stroked_segments(page) if c == (0.0, 0.0, 0.0)]
        bars = [s for s in black if np.allclose(s, bar, atol=1e-3)]
        assert len(bars) == 1
        assert lengths_mm(bars)[0] == pytest.approx(40.0, abs=1e-4)
        assert bars[0][0, 1] == pytest.approx(bars[0][1, 1])  # horizontal
        marks = [s / PT for s in black if abs(lengths_mm([s])[0] - 4.0) < 1e-4]
        for cx, cy in corners:  # two marks point at every window corner, 1.5 mm away
            near = [m for m in marks if min(np.hypot(*(m - (cx, cy)).T)) == pytest.approx(1.5)]
            assert len(near) == 2, (cx, cy)
    text = reader.pages[0].extract_text()
    assert "40 mm" in text and "A1" in text and f"of {layout.page_count}" in text


def test_draw_page_maps_one_mm_to_one_mm(example_pattern):
    layout = pdf_layout(example_pattern, paper="Letter")
    figure = draw_page(layout, 0)
    w, h = figure.get_size_inches() * 25.4
    assert (w, h) == pytest.approx((215.9, 279.4))
    ax = figure.axes[0]
    figure.set_dpi(72.0)
    a, b = ax.transData.transform([(0.0, 0.0), (100.0, 50.0)])
    np.testing.assert_allclose(b - a, (100.0 * PT, 50.0 * PT), rtol=1e-12)
    np.testing.assert_allclose(a, (0.0, 0.0), atol=1e-9)


def test_page_labels_and_order(long_pattern):
    layout = pdf_layout(long_pattern, scale=4.0, paper="Letter")
    assert layout.rows > 1
    labels = [t.label for t in layout.tiles]
    assert labels[0] == "A1" and labels[layout.cols] == "B1"
    assert [t.page for t in layout.tiles] == list(range(1, layout.page_count + 1))
    # row A is the top of the sheet (the distal end)
    assert layout.tiles[0].window[3] > layout.tiles[-1].window[3]


def test_perforated_and_skip_options(example_pattern):
    plain = read(pdf_bytes(example_pattern, scale=3.0))
    perforated = read(pdf_bytes(example_pattern, scale=3.0, perforate=True, dash=2.0, gap=1.0))
    assert len(perforated.pages) == len(plain.pages)
    dashes = [s for p in perforated.pages for c, s in stroked_segments(p) if c == VALLEY]
    assert np.all(lengths_mm(dashes) <= max(2.0, LEGEND_SAMPLE) + 1e-6)
    skipped = pdf_layout(example_pattern, skip_creases_on_cut=True)
    assert skipped.segments.shape[0] < pdf_layout(example_pattern).segments.shape[0]


def test_export_dispatch_for_chains_and_patterns(tmp_path, example_1a):
    path = export(example_1a, tmp_path / "chain.pdf", twistPortion=0.3, scale=2.0)
    assert path.read_bytes().startswith(b"%PDF")
    twisted = export(example_1a.creasePattern(0.3), tmp_path / "pattern.pdf", scale=2.0)
    a = [stroked_segments(p) for p in read(path.read_bytes()).pages]
    b = [stroked_segments(p) for p in read(twisted.read_bytes()).pages]
    assert len(a) == len(b)
    for page_a, page_b in zip(a, b, strict=True):
        assert len(page_a) == len(page_b)
        for (ca, sa), (cb, sb) in zip(page_a, page_b, strict=True):
            assert ca == cb and np.allclose(sa, sb)


HAND = Path(__file__).resolve().parents[2] / "examples" / "designs" / "hand.json"


def test_a_tree_pdfs_footers_lie_inside_its_pages(tmp_path):
    """The tree build's PDF titles every sheet with its label (long: joints, junction, where
    it starts): each footer wraps inside the page (it used to run 58 mm past the right edge)."""
    from kinegami.design import load_design_with_info
    from kinegami.design.reader import carry_origin
    from kinegami.export.tree_build import sheet_labels, write_tree_files
    from kinegami.fabrication.sheets import fabricate, fit_junctions

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        tree, info = load_design_with_info(HAND)
        fitted, _ = fit_junctions(tree)
        fabrication = fabricate(fitted)
    names = carry_origin(tree, fitted).names  # as kinegami build names the joints
    [path] = write_tree_files(fabrication, tmp_path, "hand", ["pdf"], units=info.units,
                              names=names)  # fmt: skip
    labels = sheet_labels(fabrication, names, info.units)
    reader = read(path.read_bytes())
    assert len(reader.pages) == len(labels) == 3  # one page per sheet
    wrapped = 0
    for page, label, sheet in zip(reader.pages, labels, fabrication.sheets, strict=True):
        layout = pdf_layout(sheet.pattern, units=info.units, title=label)
        footer = assert_footer_inside(page, 10.0, layout.content[1])
        lines = len(layout.title_lines)
        bottom = sorted(footer, key=lambda s: s[3])[:lines]  # the title: the lowest lines
        text = "".join(s[0] for s in reversed(bottom))
        assert text.replace(" ", "") == (
            f"{label}, 1 unit = 1 cm; print at 100 % (actual size); trim along the crop marks"
        ).replace(" ", "")
        wrapped += lines > 1
    assert wrapped == 3


@pytest.mark.parametrize("orientation", ["portrait", "landscape"])
def test_a_long_title_wraps_and_the_footer_grows(example_pattern, orientation):
    word = "x" * 400  # longer than a line: cut inside the word
    title = "a long title " * 30 + word
    layout = pdf_layout(example_pattern, title=title, orientation=orientation, scale=3.0)
    short = pdf_layout(example_pattern, orientation=orientation, scale=3.0)
    lines = len(layout.title_lines)
    assert lines >= 4 and len(short.title_lines) == 1
    assert layout.footer == pytest.approx(FOOTER + (lines - 1) * TITLE_STEP)
    assert short.footer == FOOTER
    x, y, w, h = layout.content
    assert y == pytest.approx(10.0 + layout.footer)
    assert h == pytest.approx(short.content[3] - (lines - 1) * TITLE_STEP)
    reader = read(pdf_bytes(example_pattern, title=title, orientation=orientation, scale=3.0))
    for page in reader.pages:
        footer = assert_footer_inside(page, 10.0, y)
        bottom = sorted(footer, key=lambda s: s[3])[:lines]  # the title: the lowest lines
        text = "".join(s[0] for s in reversed(bottom))
        assert text.replace(" ", "").startswith(title.replace(" ", ""))
        # the sheet's lines stay above the footer
        creases = [s for c, s in stroked_segments(page) if c in (MOUNTAIN, VALLEY)]
        sheet = [s for s in creases if s[:, 1].min() > (y - 1e-6) * PT]
        assert len(sheet) == len(creases) - 2  # all but the legend's two samples


def _boxes_overlap(a, b) -> bool:
    return a[0] < b[2] and b[0] < a[2] and a[1] < b[3] and b[1] < a[3]


@pytest.mark.parametrize(
    ("margin", "scale_bar", "rows", "beside"),
    [(10.0, 50.0, 1, True), (20.0, 50.0, 1, False), (48.0, 40.0, 2, False)],
)
def test_the_legend_never_runs_into_the_scale_bar(example_pattern, margin, scale_bar, rows,
                                                  beside):  # fmt: skip
    """Perforated, the legend is 118 mm long: in a narrower window it goes on rows of its own,
    below the scale bar, instead of running into it (it did with margin=20 on A4)."""
    options = {"perforate": True, "margin": margin, "orientation": "portrait", "scale": 2.0,
               "scale_bar": scale_bar}  # fmt: skip
    layout = pdf_layout(example_pattern, **options)
    page = read(pdf_bytes(example_pattern, **options)).pages[0]
    footer = assert_footer_inside(page, margin, layout.content[1])
    boxes = [(left, base - 0.6, right, base + 2.0) for _, left, right, base in footer]
    (x0, y0), (x1, _) = scale_bar_segment(layout)
    bar = (x0, y0, x1, y0 + 2.0)  # the bar and its ticks
    for i, box in enumerate(boxes):
        assert not _boxes_overlap(box, bar), footer[i]
        for other in boxes[i + 1 :]:
            assert not _boxes_overlap(box, other), (footer[i], other)
    samples = [s for c, s in stroked_segments(page) if c in (MOUNTAIN, VALLEY)
               and s[:, 1].max() < layout.content[1] * PT]  # fmt: skip
    for sample in samples:
        assert sample[:, 0].max() / PT <= x0 or sample[:, 1].max() / PT < y0
    assert len({round(entry[3], 6) for entry in layout.legend}) == rows
    assert bool(y0 == pytest.approx(min(entry[3] for entry in layout.legend))) is beside


@pytest.mark.parametrize(
    ("margin", "words"), [(87.0, "too narrow for the legend"), (80.0, "too narrow for the page")]
)
def test_a_window_too_narrow_for_the_footer_is_refused(example_pattern, margin, words):
    with pytest.raises(InvalidParameterError, match=f"margin={margin:g} mm .*{words}"):
        pdf_layout(example_pattern, margin=margin, perforate=True, scale_bar=4.0)


# --- bad input -----------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("options", "error", "words"),
    [
        ({"paper": "A3"}, InvalidParameterError, "paper"),
        ({"orientation": "sideways"}, InvalidParameterError, "orientation"),
        ({"margin": 2.0}, InvalidParameterError, "margin"),
        ({"margin": 90.0}, InvalidParameterError, "margin"),
        ({"overlap": 200.0}, InvalidParameterError, "overlap"),
        ({"scale_bar": 150.0}, InvalidParameterError, "scale_bar"),
        ({"scale": 100.0, "max_pages": 3}, InvalidParameterError, "max_pages"),
        ({"margin": "10"}, InvalidTypeError, "margin"),
        ({"papr": "A4"}, InvalidTypeError, "papr"),
        ({"units": "ft"}, InvalidParameterError, "units"),
    ],
)
def test_bad_options(example_pattern, options, error, words):
    stream = io.BytesIO()
    with pytest.raises(error, match=words):
        write_pdf(example_pattern, stream, **options)
    assert stream.getvalue() == b""


def test_only_patterns(example_1a):
    with pytest.raises(InvalidTypeError, match="TubularPattern"):
        write_pdf(example_1a, io.BytesIO())
    with pytest.raises(InvalidTypeError, match="TubularPattern"):
        pdf_layout(catalog)


def test_failed_export_leaves_nothing(tmp_path, example_pattern):
    with pytest.raises(InvalidParameterError):
        export(example_pattern, tmp_path / "p.pdf", paper="A5")
    assert list(tmp_path.iterdir()) == []
