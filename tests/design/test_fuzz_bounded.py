"""Bounded time and memory for any input (issue 29, docs/limits.md): a short seeded run of the
fuzzers of benchmarks/fuzz.py.

Random design files (chains, trees, DH tables, values at and past every limit, hostile values)
are loaded and their chains asked for patterns, clearance, sweeps and exports; random API
operation sequences edit chains and trees; the command line runs on random designs. Each case
runs in a worker process capped at 2 GiB of address space and must end within 20 s of CPU; every
failure must be a one-line KinegamiError, every refused edit must leave the chain
bit-identical, and on the command line every failure is one error line. The long run (10,000
of each) is ``python benchmarks/fuzz.py``; these runs are a few hundred cases.
"""

from __future__ import annotations

import importlib.util
import sys
from pathlib import Path

import pytest

BENCHMARKS = Path(__file__).resolve().parents[2] / "benchmarks"


@pytest.fixture(scope="module")
def fuzz():
    """benchmarks/fuzz.py as a module."""
    spec = importlib.util.spec_from_file_location("fuzz", BENCHMARKS / "fuzz.py")
    module = importlib.util.module_from_spec(spec)
    sys.modules["fuzz"] = module
    try:
        spec.loader.exec_module(module)
        yield module
    finally:
        sys.modules.pop("fuzz", None)


def _clean(result) -> None:
    problems = "\n".join(f"seed {seed}: {status}: {detail}"
                         for seed, status, detail in result["problems"])  # fmt: skip
    assert not result["problems"], problems


def test_fuzzed_design_files(fuzz):
    result = fuzz.run("design:small", list(range(100)), workers=2)
    _clean(result)
    assert result["cases"] == result["ok"] == 100
    # both kinds of answer were met: designs that load and designs refused in one line
    assert result["outcomes"]["loaded"] > 25 and result["outcomes"]["refused"] > 25


def test_random_operation_sequences(fuzz):
    result = fuzz.run("operations:small", list(range(60)), workers=2)
    _clean(result)
    assert result["outcomes"]["chain"] > 10 and result["outcomes"]["tree"] > 10


def test_the_command_line_on_fuzzed_designs(fuzz):
    result = fuzz.run("cli", list(range(16)), workers=2)
    _clean(result)
    assert result["cases"] == 16


def test_the_runner_catches_hangs_memory_errors_and_bad_failures(fuzz):
    result = fuzz.run("selftest", [0, 1, 2, 3, 4, 5], workers=1, timeout=2.0)
    found = {seed: status for seed, status, _ in result["problems"]}
    assert found == {1: "hang", 2: "violation", 3: "violation", 5: "crash"}
    assert result["cases"] == 6 and result["ok"] == 2
    details = {seed: detail for seed, _, detail in result["problems"]}
    assert "MemoryError" in details[2] and "ValueError" in details[3]


def test_events_that_arrive_together_are_all_read(fuzz, monkeypatch):
    """A worker's lines can reach the runner in one read (a case that ends as the next
    starts): every one of them counts, so the next case's start is seen and its hang caught
    (a buffered readline kept the second line where the selector never looked: the runner
    then waited for ever, as CI once did)."""
    import subprocess

    script = ("import sys, time; sys.stdout.write('{\"start\": 0}\\n{\"seed\": 0, "
              "\"status\": \"ok\", \"detail\": \"fine\"}\\n{\"start\": 1}\\n'); "
              "sys.stdout.flush(); end = time.monotonic() + 60\n"
              "while time.monotonic() < end: pass")  # fmt: skip

    def spawn(kind, seeds, memory, nice):
        return subprocess.Popen([sys.executable, "-c", script], stdout=subprocess.PIPE,
                                stderr=subprocess.PIPE, text=True)  # fmt: skip

    monkeypatch.setattr(fuzz, "_spawn", spawn)
    result = fuzz.run("selftest", [0, 1], workers=1, timeout=1.0)
    assert result["ok"] == 1 and result["cases"] == 2
    assert [(seed, status) for seed, status, _ in result["problems"]] == [(1, "hang")]


def test_a_design_text_depends_on_its_seed_only(fuzz):
    assert fuzz.design_text(7) == fuzz.design_text(7)
    assert fuzz.design_text(7) != fuzz.design_text(8)
