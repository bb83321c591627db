"""benchmarks/run.py reports its progress on stderr, one line per group of measurements, and
prints the same table on stdout (no timing is asserted: tests never time anything)."""

from __future__ import annotations

import importlib.util
import io
import re
import sys
from pathlib import Path

import pytest

BENCHMARKS = Path(__file__).resolve().parents[1] / "benchmarks"


@pytest.fixture(scope="module")
def run():
    """benchmarks/run.py as a module (its folder on sys.path: it imports startup.py)."""
    sys.path.insert(0, str(BENCHMARKS))
    try:
        spec = importlib.util.spec_from_file_location("benchmarks_run", BENCHMARKS / "run.py")
        module = importlib.util.module_from_spec(spec)
        spec.loader.exec_module(module)
        yield module
    finally:
        sys.path.remove(str(BENCHMARKS))


def test_each_step_is_reported_as_it_starts_and_ends(run):
    seen = []
    stream = io.StringIO()

    def step(name):
        def rows():
            seen.append(stream.getvalue())  # what was reported when the step began
            return [(name, "1 ms", "-")]

        return rows

    rows = run.run_steps([("first", step("a")), ("second", step("b"))], stream)
    assert rows == [("a", "1 ms", "-"), ("b", "1 ms", "-")]
    assert seen[0] == "[1/2] first ..."
    assert re.fullmatch(r"\[1/2\] first \.\.\. \d+\.\d s\n\[2/2\] second \.\.\.", seen[1])
    assert re.fullmatch(
        r"\[1/2\] first \.\.\. \d+\.\d s\n\[2/2\] second \.\.\. \d+\.\d s\n", stream.getvalue()
    )


def test_a_failing_step_is_reported_and_raises(run):
    stream = io.StringIO()

    def broken():
        raise ValueError("no")

    with pytest.raises(ValueError, match="no"):
        run.run_steps([("broken", broken), ("never", lambda: [])], stream)
    assert stream.getvalue() == "[1/2] broken ... failed\n"


def test_the_steps_cover_the_table_in_order(run):
    names = [name for name, _ in run.steps(10, 20)]
    assert len(names) == len(set(names))
    assert "scale: 100-400-joint safe chains, a 1,000-row DH table" in names
    assert names[0] == "CSC paths" and names[-1] == "start-up, fresh processes"
    assert "compact, 16-joint safe chains (20 seeds) and the gallery" in names
    short = [name for name, _ in run.steps(3, 0)]  # no compaction: neither the chains' nor
    assert len(short) == len(names) - 2
    assert not [n for n in short if "compact" in n.lower() and "16" in n]
    assert "48-joint safe chains (3 seeds)" in short


def test_only_runs_the_chosen_measurements(run, capsys):
    run.main(["--only", "csc"])
    out, err = capsys.readouterr()
    assert re.fullmatch(r"\[1/1\] CSC paths \.\.\. \d+\.\d s\n", err)
    lines = out.splitlines()
    assert lines[0].split() == ["measurement", "result", "goal"]
    width = len(lines[1]) - 28  # the names' column: the rule is 28 longer
    assert [line[:width].rstrip() for line in lines[2:]] == [
        "CSC solve, one link",
        "CSC solve_csc_all (every path), one link",
        "  most paths for one of those frame pairs",
    ]
    with pytest.raises(SystemExit):
        run.main(["--only", "nothing like it"])
    assert "no measurement has that in its name" in capsys.readouterr().err
