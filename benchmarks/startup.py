"""Start-up costs, each measured in fresh Python processes: what a user waits for once.

* the first ``creasePattern()`` of a 32-joint compact chain, including the pattern modules it
  imports (the chain is built first, untimed);
* the first DXF save of a 32-joint compact chain's crease pattern, including every import it
  pays (the chain and its pattern are built first, untimed);
* ``kinegami validate examples/designs/example1.json``, the whole process;
* ``import kinegami``.

Each is the median of a few processes, after one warm-up process that writes the bytecode
cache (to a temporary ``PYTHONPYCACHEPREFIX``, so the source tree is not touched), as for an
installed package. Run alone: ``python benchmarks/startup.py``; ``benchmarks/run.py``
appends these rows to its table.
"""

from __future__ import annotations

import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
EXAMPLE = ROOT / "examples" / "designs" / "example1.json"

#: Fresh processes per measurement (after the warm-up).
REPEAT = 5

_FIRST_DXF_SAVE = """
import sys, tempfile, time
sys.path.insert(0, {benchmarks!r})
from run import compact_chain
pattern = compact_chain().creasePattern()
with tempfile.TemporaryDirectory() as folder:
    t0 = time.perf_counter()
    pattern.save(dxfName=folder + "/chain.dxf")
    print(time.perf_counter() - t0)
"""

_FIRST_PATTERN = """
import sys, time
sys.path.insert(0, {benchmarks!r})
from run import compact_chain
chain = compact_chain()
t0 = time.perf_counter()
chain.creasePattern()
print(time.perf_counter() - t0)
"""

_IMPORT = """
import time
t0 = time.perf_counter()
import kinegami
print(time.perf_counter() - t0)
"""


def _environment(cache: str) -> dict[str, str]:
    env = dict(os.environ)
    env.pop("PYTHONDONTWRITEBYTECODE", None)
    env["PYTHONPYCACHEPREFIX"] = cache
    env.setdefault("MPLBACKEND", "Agg")
    return env


def _reported(code: str, env: dict[str, str]) -> float:
    """Seconds printed by ``code`` run in a new interpreter."""
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                          env=env, cwd=ROOT, check=True)  # fmt: skip
    return float(done.stdout.split()[-1])


def _process(command: list[str], env: dict[str, str]) -> float:
    """Wall-clock seconds of a whole process."""
    t0 = time.perf_counter()
    subprocess.run(command, capture_output=True, env=env, cwd=ROOT, check=True)
    return time.perf_counter() - t0


def _median(measure, repeat: int) -> float:
    measure()  # warm-up: writes the bytecode cache
    return statistics.median(measure() for _ in range(repeat))


def _kinegami_command() -> list[str]:
    script = Path(sys.executable).with_name("kinegami")
    return [str(script)] if script.exists() else [sys.executable, "-m", "kinegami"]


def rows(repeat: int = REPEAT) -> list[tuple[str, str, str]]:
    """(measurement, result, goal) rows of the start-up costs (fresh processes)."""
    with tempfile.TemporaryDirectory(prefix="kinegami-pycache-") as cache:
        env = _environment(cache)
        code = _FIRST_PATTERN.format(benchmarks=str(ROOT / "benchmarks"))
        first_pattern = _median(lambda: _reported(code, env), repeat)
        code = _FIRST_DXF_SAVE.format(benchmarks=str(ROOT / "benchmarks"))
        first_save = _median(lambda: _reported(code, env), repeat)
        validate = [*_kinegami_command(), "validate", str(EXAMPLE)]
        validate_time = _median(lambda: _process(validate, env), repeat)
        import_time = _median(lambda: _reported(_IMPORT, env), repeat)
    return [
        ("first creasePattern() in a fresh process, 32-joint compact chain (with its imports)",
         f"{first_pattern * 1e3:.1f} ms", "<= 8.2 ms (10x the reference's 82 ms)"),
        ("first DXF save in a fresh process, 32-joint compact chain (with its imports)",
         f"{first_save * 1e3:.1f} ms", "<= 35 ms (10x the reference's 352 ms)"),
        ("kinegami validate example1.json, whole process", f"{validate_time:.2f} s", "<= 0.5 s"),
        ("import kinegami, fresh process", f"{import_time * 1e3:.0f} ms", "-"),
    ]  # fmt: skip


def main() -> None:
    table = rows()
    width = max(len(r[0]) for r in table)
    print(f"{'measurement':<{width}}  {'result':>12}  goal")
    print("-" * (width + 28))
    for name, value, goal in table:
        print(f"{name:<{width}}  {value:>12}  {goal}")


if __name__ == "__main__":
    main()
