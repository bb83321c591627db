"""How long the editor's page waits for an answer while a long job runs, measured in the browser:
``python benchmarks/editor_jobs.py [design ...]`` (default: the PUMA and the paper's hand).

``kinegami edit`` serves the design (in this process, as the command does) and headless
Chromium (tests/headless_chromium.py: Debian's chromium through Playwright, software WebGL)
opens it. The page records, with its own clock (``performance.now()``), when each key press or
pointer press happened and when the selected joint's text in the panel changed (a
MutationObserver); an interaction's latency is the time from the one to the other: the browser
sends the event, the server runs the command, redraws and sends the answer, the page shows it.
Two interactions alternate: a joint picked in the Joint list (the text names it) and a state
slider moved by a key press (the text gives the new state). They run with no job (idle), then
while Compact runs (from the Compact button until it ends). Prints the count, median, 95th
percentile and maximum per design, phase and interaction (milliseconds), and the longest
stall of the server process in each phase: a thread that sleeps 10 ms at a time records by
how much it wakes late (a computation holding the interpreter lock would show here). The load
average is printed too: on a shared machine the figures follow it. See docs/editor.md
(Background jobs).
"""

from __future__ import annotations

import statistics
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "tests"))  # headless_chromium: the tests' one Chromium setup

DESIGNS = {"puma": ROOT / "examples/designs/puma.json", "hand": ROOT / "examples/designs/hand.json"}

#: Installed in the page: the times of key and pointer presses, and of each change of the
#: selected joint's text (the panel paragraph "state ... in [...]" and its siblings).
PROBE = """
() => {
  const probe = (window.__probe = {events: [], changes: [], last: null});
  const text = () => {
    for (const p of document.querySelectorAll("p")) {
      if (p.textContent.startsWith("state ") && p.textContent.includes(" in [")) {
        return p.parentElement.textContent;
      }
    }
    return null;
  };
  for (const kind of ["keydown", "pointerdown"]) {
    window.addEventListener(kind, () => probe.events.push(performance.now()), true);
  }
  new MutationObserver(() => {
    const now = text();
    if (now !== probe.last) {
      probe.last = now;
      probe.changes.push(performance.now());
    }
  }).observe(document.body, {subtree: true, childList: true, characterData: true});
}
"""


def _latency(page, prepare, act, timeout: float = 60.0) -> float:
    """Milliseconds from the event ``act()`` makes (after ``prepare()``, e.g. opening a menu)
    to the next change of the joint's text."""
    prepare()
    events = page.evaluate("() => window.__probe.events.length")
    act()
    end = time.monotonic() + timeout
    while time.monotonic() < end:
        answer = page.evaluate(
            """(n) => {
                 const p = window.__probe;
                 if (p.events.length <= n) return null;
                 const t = p.events[n];
                 const c = p.changes.find((x) => x >= t);
                 return c === undefined ? null : c - t;
               }""",
            events,
        )
        if answer is not None:
            return float(answer)
        time.sleep(0.01)
    raise TimeoutError("the page did not answer")


def _interactions(page, view, joints: list[int]):
    """Endless alternating interactions, as (kind, prepare, act): pick a joint in the Joint
    list (the menu opened first), then move its state slider by a key press (the i-th slider
    is that of the i-th movable joint)."""
    labels = ("(none)",) + view._labels()
    k = 0
    while True:
        slot = k % len(joints)
        joint = joints[slot]
        yield ("pick a joint",
               lambda: page.get_by_role("combobox", name="Joint", exact=True).click(),
               lambda joint=joint: page.get_by_role("option", name=labels[joint + 1],
                                                    exact=True).click())  # fmt: skip
        key = "ArrowRight" if (k // len(joints)) % 2 == 0 else "ArrowLeft"
        slider = page.get_by_role("slider").nth(slot)
        yield ("slider key", slider.focus, lambda key=key, slider=slider: slider.press(key))
        k += 1


class Stalls:
    """A thread of this (the server's) process that sleeps 10 ms at a time and records how
    late it wakes: ``worst(since)`` is the longest delay since then (milliseconds)."""

    def __init__(self):
        import threading

        self.samples: list[tuple[float, float]] = []
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._run, daemon=True)
        self._thread.start()

    def _run(self) -> None:
        while not self._stop.is_set():
            start = time.perf_counter()
            time.sleep(0.01)
            self.samples.append((start, (time.perf_counter() - start - 0.01) * 1e3))

    def worst(self, since: float, until: float) -> float:
        return max((late for t, late in self.samples if since <= t <= until), default=0.0)

    def stop(self) -> None:
        self._stop.set()


def measure(name: str, path: Path, browser, idle: int = 12) -> dict:
    """``{(phase, interaction): [milliseconds, ...]}`` for the design ``path``."""
    from kinegami.editor.server import EditorServer

    server = EditorServer(path, port=0, autosave=False)
    page = browser.new_page(viewport={"width": 1280, "height": 720})
    try:
        page.goto(server.url)
        end = time.monotonic() + 120.0
        while not server.views and time.monotonic() < end:
            time.sleep(0.1)
        view = next(iter(server.views.values()))
        page.get_by_text("Configuration", exact=True).wait_for(timeout=120_000)
        page.get_by_role("slider").first.wait_for(timeout=120_000)
        time.sleep(2.0)  # the first drawing
        page.evaluate(PROBE)
        movable = [row.index for row in view.model.joint_table() if row.movable]
        joints = movable[:3]
        view.click_joint(movable[-1])  # then the first pick is an answer to wait for
        page.get_by_text("state ", exact=False).first.wait_for()
        actions = _interactions(page, view, joints)
        results: dict[tuple[str, str], list[float]] = {}
        stalls = Stalls()
        begun = time.perf_counter()
        for _ in range(idle):
            kind, prepare, act = next(actions)
            results.setdefault(("idle", kind), []).append(_latency(page, prepare, act))
            time.sleep(0.2)
        idle_end = time.perf_counter()
        page.get_by_role("button", name="Compact", exact=True).click()
        started = time.monotonic()
        job_begun = time.perf_counter()
        while view.job is None and time.monotonic() - started < 10.0:
            time.sleep(0.02)
        job = view.job
        while job is not None and not job.finished.is_set():
            kind, prepare, act = next(actions)
            try:
                latency = _latency(page, prepare, act)
            except Exception:
                if job.finished.is_set():  # it ended meanwhile: its dialog covers the page
                    break
                raise
            if not job.finished.is_set():
                results.setdefault(("while compacting", kind), []).append(latency)
            time.sleep(0.2)
        seconds = time.monotonic() - started
        stalls.stop()
        outcome = None if job is None else job.outcome
        print(f"{name}: Compact ran {seconds:.1f} s ({outcome}; {view.message}); the server's "
              f"longest stall: idle {stalls.worst(begun, idle_end):.0f} ms, while compacting "
              f"{stalls.worst(job_begun, time.perf_counter()):.0f} ms", flush=True)  # fmt: skip
        return results
    finally:
        page.close()
        server.stop()


def main(argv: list[str]) -> int:
    import headless_chromium

    reason = headless_chromium.missing("viser")
    if reason is not None:
        print(f"cannot run: {reason}")
        return 1
    import os

    names = argv or list(DESIGNS)
    rows = []
    print("load average at the start: " + ", ".join(f"{v:.1f}" for v in os.getloadavg()))
    with headless_chromium.browser() as browser:
        for name in names:
            path = DESIGNS.get(name, Path(name))
            for (phase, kind), values in measure(name, path, browser).items():
                values = sorted(values)
                p95 = values[min(len(values) - 1, round(0.95 * (len(values) - 1)))]
                rows.append((name, phase, kind, len(values), statistics.median(values), p95,
                             values[-1]))  # fmt: skip
    print(f"{'design':<8} {'phase':<17} {'interaction':<13} {'n':>3} {'median':>7} {'p95':>7} "
          f"{'max':>7}  (ms)")  # fmt: skip
    for name, phase, kind, n, median, p95, worst in rows:
        print(f"{name:<8} {phase:<17} {kind:<13} {n:>3} {median:>7.1f} {p95:>7.1f} "
              f"{worst:>7.1f}")  # fmt: skip
    print("load average at the end: " + ", ".join(f"{v:.1f}" for v in os.getloadavg()))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
