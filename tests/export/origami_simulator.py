"""Drive an unchanged copy of Origami Simulator in headless Chromium (Playwright).

The simulator's folder is served over http on localhost; a file is imported through the
simulator's own file input (``#fileSelector``; for SVG, its import dialog's "Import SVG" button
with the default vertex merge tolerance), folded to 100 % with the simulator's own fold-percent
mechanism (``globals.creasePercent`` and ``globals.shouldChangeCreasePercent``, as the slider
sets them) and solved by its dynamic solver, stepped from the page (``globals.model.step``) so a
run is repeatable. The results are read from the page: the average vertex error readout
(``#globalError``, in %), the node positions (``globals.model.getPositionsArray()``, the model
scaled to a unit bounding sphere), the nodes' flat positions and the creases' target angles.

Where the simulator comes from: the folder ``KINEGAMI_ORIGAMI_SIMULATOR`` names (a copy of
https://github.com/amandaghassaei/OrigamiSimulator; .ci/run sets it); the browser:
tests/headless_chromium.py (Debian's chromium, also used by the editor's browser tests).
"""

from __future__ import annotations

import functools
import http.server
import math
import os
import threading
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from headless_chromium import chromium_path, launch


def simulator_folder() -> Path | None:
    """The simulator's folder (``KINEGAMI_ORIGAMI_SIMULATOR``), or None when it is not set."""
    folder = os.environ.get("KINEGAMI_ORIGAMI_SIMULATOR")
    return Path(folder) if folder else None


@dataclass
class SimulatorFold:
    """What the simulator made of one file."""

    name: str
    nodes: int  # vertices after the simulator's import (merging, splitting)
    error: float  # average vertex error at the end, percent
    errors: list  # (steps, error %, largest |coordinate|, fold angle deviation) per chunk
    positions: np.ndarray  # (nodes, 3), folded, model units (unit bounding sphere when flat)
    flat: np.ndarray  # (nodes, 3), the flat sheet, model units
    targets: np.ndarray  # target angle of every fold crease, degrees
    steps: int
    seconds: float
    warnings: list

    @property
    def blown_up(self) -> bool:
        """Some coordinate or error was ever non-finite or absurd (above 1e3 model units)."""
        return any(
            not (math.isfinite(e) and math.isfinite(c) and c < 1e3) for _, e, c, _ in self.errors
        )

    @property
    def largest_coordinate(self) -> float:
        """Largest |coordinate| over the whole run (model units)."""
        return max(c for _, _, c, _ in self.errors)

    @property
    def deviation(self) -> float:
        """Mean |fold angle - target| over the fold creases at the end, degrees."""
        return self.errors[-1][3]


class _QuietHandler(http.server.SimpleHTTPRequestHandler):
    def log_message(self, *args):  # silence the access log
        pass


_STATE = """() => {
    let largest = 0;
    for (const v of globals.model.getPositionsArray()) {
        if (!Number.isFinite(v)) { largest = Infinity; break; }
        largest = Math.max(largest, Math.abs(v));
    }
    return [parseFloat(document.getElementById('globalError').textContent), largest];
}"""

_POSITIONS = "() => Array.from(globals.model.getPositionsArray())"

_CREASES = """() => globals.model.getCreases().map(c => [c.edge.nodes[0].getIndex(),
    c.edge.nodes[1].getIndex(), c.node1.getIndex(), c.node2.getIndex(),
    Math.abs(c.getTargetTheta())])"""


def fold_angle_deviation(X: np.ndarray, creases: np.ndarray) -> float:
    """Mean |fold angle - target| over the fold creases (degrees), from the node positions.

    ``creases`` rows: the crease's two nodes, the opposite node of each of its two triangles,
    |target angle| (radians), as the simulator's creases hold them. The fold angle's magnitude
    is pi minus the angle between the two triangles at the crease.
    """
    if not creases.size:
        return 0.0
    e0, e1, n1, n2 = (creases[:, j].astype(np.intp) for j in range(4))
    axis = X[e1] - X[e0]
    axis /= np.linalg.norm(axis, axis=1)[:, None]

    def wing(n):
        w = X[n] - X[e0]
        w -= np.einsum("ij,ij->i", w, axis)[:, None] * axis
        return w / np.linalg.norm(w, axis=1)[:, None]

    between = np.arccos(np.clip(np.einsum("ij,ij->i", wing(n1), wing(n2)), -1.0, 1.0))
    folded = np.pi - between
    fold = creases[:, 4] > 0  # the creases with a target (type 1)
    return float(np.degrees(np.abs(folded[fold] - creases[fold, 4])).mean())


_READ = """() => ({
    positions: Array.from(globals.model.getPositionsArray()),
    flat: globals.model.getNodes().map(n => {
        const p = n.getOriginalPosition(); return [p.x, p.y, p.z]; }),
    targets: globals.model.getCreases().filter(c => c.type == 1)
        .map(c => c.getTargetTheta() * 180 / Math.PI),
})"""


class OrigamiSimulator:
    """Context manager: an http server for the simulator and one headless Chromium."""

    def __init__(self, folder: Path | None = None, chromium: Path | None = None):
        folder = folder or simulator_folder()
        if folder is None:
            raise ValueError("no Origami Simulator: set KINEGAMI_ORIGAMI_SIMULATOR to its folder")
        self.folder = Path(folder)
        self.chromium = Path(chromium or chromium_path())

    def __enter__(self) -> OrigamiSimulator:
        from playwright.sync_api import sync_playwright

        handler = functools.partial(_QuietHandler, directory=str(self.folder))
        self._server = http.server.ThreadingHTTPServer(("127.0.0.1", 0), handler)
        threading.Thread(target=self._server.serve_forever, daemon=True).start()
        self.url = f"http://127.0.0.1:{self._server.server_address[1]}/index.html?model=none"
        self._playwright = sync_playwright().start()
        try:
            self._browser = launch(self._playwright, self.chromium)
        except BaseException:
            self._playwright.stop()
            self._server.shutdown()
            raise
        return self

    def __exit__(self, *exc) -> None:
        try:
            self._browser.close()
        finally:
            self._playwright.stop()
            self._server.shutdown()
            self._server.server_close()

    def fold(
        self,
        path: Path,
        *,
        below: float,
        within: float,
        max_steps: int,
        chunk: int = 1000,
        screenshot: Path | None = None,
        track: list | None = None,
    ) -> SimulatorFold:
        """Import ``path``, fold to 100 % and step the solver in chunks until, after two chunks
        in a row, the average vertex error is below ``below`` (percent) and the creases are
        within ``within`` degrees of their target angles on average (the sheet is folded, not
        only unstrained), or ``max_steps``, or a blow-up."""
        start = time.monotonic()
        page = self._browser.new_page(viewport={"width": 320, "height": 240})
        warnings: list[str] = []
        page.on("console", lambda m: warnings.append(m.text) if m.type == "warning" else None)
        try:
            page.goto(self.url)
            page.wait_for_function("window.globals && globals.pattern && globals.threeView")
            page.evaluate("globals.threeView.pauseSimulation()")
            page.set_input_files("#fileSelector", str(path))
            if path.suffix.lower() == ".svg":
                page.click("#doSVGImport")  # the import dialog, default merge tolerance
            page.wait_for_function(
                "globals.model.getNodes().length > 0 && !globals.needsSync"
                " && !globals.simNeedsSync",
                timeout=120_000,
            )
            page.evaluate(
                "globals.creasePercent = 1; globals.shouldChangeCreasePercent = true;"
                "globals.controls.updateCreasePercent();"
            )
            creases = np.array(page.evaluate(_CREASES), dtype=float).reshape(-1, 5)
            errors: list[tuple[int, float, float, float]] = []
            done = 0
            while done < max_steps:
                page.evaluate(f"globals.model.step({chunk})")
                done += chunk
                error, largest = page.evaluate(_STATE)
                if not (math.isfinite(error) and math.isfinite(largest) and largest < 1e3):
                    errors.append((done, float(error), float(largest), math.inf))
                    break  # blown up
                X = np.array(page.evaluate(_POSITIONS), dtype=float).reshape(-1, 3)
                errors.append(
                    (done, float(error), float(largest), fold_angle_deviation(X, creases))
                )
                if track is not None:
                    track.append(X)
                last = errors[-2:]
                if len(last) == 2 and all(e < below and d < within for _, e, _, d in last):
                    break
            data = page.evaluate(_READ)
            if screenshot is not None:
                if path.suffix.lower() == ".svg":
                    # the simulator lays the SVG's sheet out turned by a half turn about x
                    # relative to the FOLD's (our SVG negates y): show it the FOLD's way up
                    page.evaluate("globals.threeView.modelWrapper.rotation.x = Math.PI")
                page.set_viewport_size({"width": 800, "height": 600})
                page.wait_for_timeout(500)  # a few animation frames at the new size
                page.screenshot(path=str(screenshot))
        finally:
            page.close()
        return SimulatorFold(
            name=path.name,
            nodes=len(data["flat"]),
            error=errors[-1][1],
            errors=errors,
            positions=np.array(data["positions"], dtype=float).reshape(-1, 3),
            flat=np.array(data["flat"], dtype=float),
            targets=np.array(data["targets"], dtype=float),
            steps=done,
            seconds=time.monotonic() - start,
            warnings=warnings,
        )


def shape_distance(A: np.ndarray, B: np.ndarray, *, mirror: bool = False) -> float:
    """RMS distance between the point sets A and B (same order) after the best similarity
    transform of A (rotation, translation and scale; with ``mirror``, a reflection instead of
    the rotation), relative to the RMS radius of B."""
    a = A - A.mean(axis=0)
    b = B - B.mean(axis=0)
    a = a / np.sqrt((a**2).sum(axis=1).mean())
    b = b / np.sqrt((b**2).sum(axis=1).mean())
    u, s, vt = np.linalg.svd(a.T @ b)
    d = np.ones(3)
    if (np.linalg.det(u @ vt) < 0) != mirror:
        d[-1] = -1.0
    R = u @ np.diag(d) @ vt
    scale = float((s * d).sum()) / float((a**2).sum())
    return float(np.sqrt(((scale * a @ R - b) ** 2).sum(axis=1).mean()))


def match_nodes(sheet: np.ndarray, flat: np.ndarray, *, svg: bool) -> tuple[np.ndarray, float]:
    """The simulator node of every vertex of our file, and the worst mismatch.

    ``sheet`` is the FOLD file's ``vertices_coords`` (x, y), ``flat`` the simulator's flat node
    positions (x, 0, z). The simulator lays a FOLD vertex (x, y) at (x, 0, y) and an SVG point
    at (x, 0, y_svg) with y_svg = -y (our SVG negates y), then centres and scales the sheet; so
    after centring and scaling both, the nodes are the file's vertices. The mismatch is relative
    to the sheet's RMS radius.
    """
    from scipy.spatial import cKDTree

    def standard(points):
        points = points - points.mean(axis=0)
        return points / np.sqrt((points**2).sum(axis=1).mean())

    ours = standard(sheet * np.array([1.0, -1.0 if svg else 1.0]))
    theirs = standard(flat[:, [0, 2]])
    distance, index = cKDTree(theirs).query(ours)
    return index, float(distance.max())


def handedness_agreement(A: np.ndarray, B: np.ndarray, flat: np.ndarray, k: int = 6) -> tuple:
    """How often two folded states of one sheet (same node order) turn the same way locally.

    For every node and every three of its k nearest neighbours in the flat sheet (``flat``, in
    the x-z plane as the simulator lays it out), the sign of the tetrahedron's volume. A rigid
    motion keeps every sign, a reflection flips every one, and the signs settle as soon as the
    tube's cross-sections have folded, long before a floppy chain has come to rest. Returns
    (fraction of the tetrahedra clearly out of plane in both states whose signs agree, count);
    (nan, 0) if there are none.
    """
    from itertools import combinations

    from scipy.spatial import cKDTree

    _, near = cKDTree(flat[:, [0, 2]]).query(flat[:, [0, 2]], k=k + 1)
    quads = np.array(
        [(row[0], *trio) for row in near for trio in combinations(row[1:], 3)], dtype=np.intp
    )

    def volumes(X):
        u, v, w = (X[quads[:, j]] - X[quads[:, 0]] for j in (1, 2, 3))
        scale = np.linalg.norm(u, axis=1) * np.linalg.norm(v, axis=1) * np.linalg.norm(w, axis=1)
        return np.einsum("ij,ij->i", u, np.cross(v, w)) / np.where(scale > 0, scale, np.inf)

    a, b = volumes(A), volumes(B)
    clear = (np.abs(a) > 0.1) & (np.abs(b) > 0.1)
    if not clear.any():
        return math.nan, 0
    return float((np.sign(a[clear]) == np.sign(b[clear])).mean()), int(clear.sum())
