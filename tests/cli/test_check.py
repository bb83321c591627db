"""``kinegami check`` and the clearance line of ``kinegami build``, run as subprocesses: exit codes
0 / 3 / 1, the numbers against the library, ``--json``, ``--motion``, one-line errors, and that
nothing is written."""

from __future__ import annotations

import json
import math
import shutil
from pathlib import Path

import numpy as np
import pytest

from kinegami.chain.joints import RevoluteJoint
from kinegami.clearance import chain_clearance, sweep
from kinegami.design import load_design, load_design_with_info, read_design
from kinegami.design.reader import origin_of

from .helpers import EXAMPLE1, GALLERY, ROOT, assert_clean_failure, fold_back, run, write

DOUBLING_BACK = ROOT / "examples" / "designs" / "doubling_back.json"
PLANAR = ROOT / "examples" / "designs" / "planar_joint.json"  # no pair is ever tested


#: Reference output of the fold-back design 1.9 r apart (tests/clearance: parallel_return(1.9)).
FOLD_BACK_PAIRS = [
    ("joint 0, StartTip 'base'", "link 3, second elbow"),
    ("joint 0, StartTip 'base'", "link 4, twist"),
    ("link 1, straight tube", "link 3, straight tube"),
    ("link 1, straight tube", "link 3, second elbow"),
]
JSON_KEYS = {"design", "name", "units", "r", "ok", "margin", "material", "verdict", "min_clearance",
             "closest", "pairs", "unlisted", "states", "motion"}  # fmt: skip
MOTION_KEYS = {"samples", "seed", "colliding", "colliding_fraction", "worst_pairs",
               "free_intervals"}  # fmt: skip
INTERVAL_KEYS = {"joint", "type", "name", "kind", "state", "range", "free"}
PAIR_KEYS = {"first", "second", "clearance", "points"}


@pytest.fixture
def colliding(tmp_path) -> Path:
    """The fold-back design 1.9 r apart: the returning tube overlaps the way out by 0.1 r."""
    path = write(tmp_path / "fold_back.json", fold_back(1.9))
    assert not load_design(path).clearance().ok
    return path


@pytest.fixture
def colliding_moving(tmp_path) -> Path:
    """The gallery's "Doubling back" (named, movable joints) at states where it self-intersects."""
    document = read_design(DOUBLING_BACK)
    chain = load_design(DOUBLING_BACK)
    ranges = np.array([joint.stateRange() for joint in chain.Joints])
    rng = np.random.default_rng(0)
    for _ in range(200):
        states = 0.9 * (ranges[:, 0] + (ranges[:, 1] - ranges[:, 0]) * rng.random(len(ranges)))
        if not chain.clearance(states).ok:
            break
    else:  # pragma: no cover - the design collides in about a fifth of its configurations
        raise AssertionError("no colliding configuration found")
    document["states"] = [
        math.degrees(s) if isinstance(joint, RevoluteJoint) else float(s)
        for s, joint in zip(states, chain.Joints, strict=True)
    ]  # the design's angleUnits are degrees
    path = write(tmp_path / "doubling_back_colliding.json", document)
    assert not load_design(path).clearance().ok
    return path


def strict_json(text: str) -> dict:
    def no_constant(name):
        raise AssertionError(f"not strict JSON: {name}")

    data = json.loads(text, parse_constant=no_constant)
    assert isinstance(data, dict)
    return data


def library(path: Path):
    chain, info = load_design_with_info(path)
    names = origin_of(chain).names
    return chain, info, names, chain_clearance(chain, names=names)


def listing(folder: Path) -> list:
    return sorted((str(p.relative_to(folder)), p.stat().st_size) for p in folder.rglob("*"))


# --- exit codes ------------------------------------------------------------------------------
@pytest.mark.parametrize("design", GALLERY, ids=[p.stem for p in GALLERY])
def test_every_gallery_design_is_clear(design):
    result = run("check", design)
    assert result.returncode == 0, result.stdout + result.stderr
    assert result.stderr == ""
    assert "clear at its states" in result.stdout.splitlines()[0]


def test_a_clear_design_exits_0_with_its_minimum_clearance():
    _, _, _, report = library(EXAMPLE1)
    result = run("check", EXAMPLE1)
    assert result.returncode == 0, result.stderr
    lines = result.stdout.splitlines()
    assert lines[0] == f"Example 1 ({EXAMPLE1}): clear at its states"
    # in mm as build prints sizes, and in the design's unit (cm), to about r / 100
    mm, cm = report.min_clearance * 10.0, report.min_clearance
    closest = report.closest
    assert lines[1] == (
        f"  clearance: clear with margin 0 mm (0 cm): minimum clearance {mm:.1f} mm ({cm:.2f} "
        f"cm), between {closest.first} and {closest.second}"
    )
    assert len(lines) == 2


def test_a_self_intersecting_design_exits_3_and_names_every_pair(colliding):
    result = run("check", colliding)
    assert result.returncode == 3, result.stderr
    assert result.stderr == ""
    lines = result.stdout.splitlines()
    title = f"Fold back ({colliding})"
    assert lines[0] == f"{title}: self-intersects at its states (4 pairs of parts overlap)"
    assert lines[1] == ("  clearance: self-intersects, parts closer than the margin 0 mm: minimum "
                        "clearance -0.10 mm, between joint 0, StartTip 'base' and link 3, second "
                        "elbow; 4 pairs of parts")  # fmt: skip
    assert lines[2] == "  parts closer than the margin (closest first):"
    _, _, _, report = library(colliding)
    assert [(p.first, p.second) for p in report.pairs] == FOLD_BACK_PAIRS
    assert lines[3:] == [
        f"    {p.first} and {p.second}: overlap {-p.clearance:.2f} mm" for p in report.pairs
    ]
    assert lines[3] == "    joint 0, StartTip 'base' and link 3, second elbow: overlap 0.10 mm"


def test_the_same_design_2_1_r_apart_is_clear(tmp_path):
    result = run("check", write(tmp_path / "apart.json", fold_back(2.1)))
    assert result.returncode == 0, result.stdout + result.stderr
    assert "minimum clearance 0.10 mm, between joint 0, StartTip 'base' and" in result.stdout


def test_a_design_with_nothing_to_test_is_clear():
    result = run("check", PLANAR)
    assert result.returncode == 0
    assert ("  clearance: clear with margin 0 mm: no two parts are far enough apart along the "
            "tube to collide") in result.stdout  # fmt: skip


# --- --motion --------------------------------------------------------------------------------
def test_motion_prints_the_colliding_fraction_and_free_intervals():
    chain, _, names, _ = library(EXAMPLE1)
    motion = sweep(chain, 200, 0, names=names)
    result = run("check", EXAMPLE1, "--motion", 200)
    assert result.returncode == 0, result.stderr
    text = result.stdout
    fraction = 100.0 * motion.colliding_fraction
    assert motion.colliding > 0  # Example 1 collides in part of its range
    assert (f"  motion: {motion.colliding} of 200 sampled configurations self-intersect "
            f"({fraction:.1f}%; seed 0)") in text  # fmt: skip
    pair, count = motion.worst_pairs[0]
    assert f"    {pair.first} and {pair.second}: the deepest overlap in {count} " in text
    # joint 2 is prismatic (lengths in mm and cm), joint 4 revolute (degrees)
    low, high = motion.free_intervals[2]
    lo, hi = chain.Joints[2].stateRange()
    assert (low, high) == (lo, hi)
    assert (f"    joint 2, PrismaticJoint 'prismatic': {10 * low:.1f} to {10 * high:.1f} mm "
            f"({low:.2f} to {high:.2f} cm), its whole range") in text  # fmt: skip
    low, high = motion.free_intervals[4]
    lo, hi = chain.Joints[4].stateRange()
    assert lo < low < high < hi
    assert (f"    joint 4, RevoluteJoint 'revolute': {math.degrees(low):.1f} to "
            f"{math.degrees(high):.1f} deg, of its range {math.degrees(lo):.1f} to "
            f"{math.degrees(hi):.1f} deg") in text  # fmt: skip
    # waypoints and tips do not move: no interval for them
    assert "joint 1," not in text.split("free intervals")[1]


def test_the_seed_picks_the_sample():
    chain, _, names, _ = library(DOUBLING_BACK)
    counts = {seed: sweep(chain, 30, seed, names=names).colliding for seed in (1, 2)}
    assert counts[1] != counts[2]  # else this test could not tell the seeds apart
    for seed, count in counts.items():
        result = run("check", DOUBLING_BACK, "--motion", 30, "--seed", seed)
        assert result.returncode == 0
        assert f"motion: {count} of 30 sampled configurations self-intersect" in result.stdout
        assert f"; seed {seed})" in result.stdout


def test_motion_on_a_design_colliding_at_its_states(colliding_moving):
    result = run("check", colliding_moving, "--motion", 20)
    assert result.returncode == 3
    assert "self-intersects at its states" in result.stdout.splitlines()[0]
    assert "  motion: " in result.stdout
    assert "  free intervals: none (the design self-intersects at its states)" in result.stdout


# --- --json ----------------------------------------------------------------------------------
def test_json_has_the_library_numbers():
    chain, info, names, report = library(EXAMPLE1)
    motion = sweep(chain, 50, 1, names=names)
    result = run("check", EXAMPLE1, "--motion", 50, "--seed", 1, "--json")
    assert result.returncode == 0, result.stderr
    data = strict_json(result.stdout)
    assert set(data) == JSON_KEYS
    assert data["design"] == str(EXAMPLE1)
    assert (data["name"], data["units"], data["r"]) == ("Example 1", "cm", 1.0)
    assert data["ok"] is True and data["pairs"] == [] and data["unlisted"] == 0
    assert data["margin"] == 0.0 and data["verdict"] == report.verdict("cm")
    # lengths in the design's units, as the library gives them
    assert data["min_clearance"] == report.min_clearance
    assert set(data["closest"]) == PAIR_KEYS
    assert data["closest"]["first"] == report.closest.first
    np.testing.assert_array_equal(data["closest"]["points"], report.closest.points)
    assert data["states"] == list(report.states)
    m = data["motion"]
    assert set(m) == MOTION_KEYS
    assert (m["samples"], m["seed"], m["colliding"]) == (50, 1, motion.colliding)
    assert m["colliding_fraction"] == motion.colliding_fraction
    assert [(p["first"], p["second"], p["count"]) for p in m["worst_pairs"]] == [
        (p.first, p.second, n) for p, n in motion.worst_pairs
    ]
    assert [e["joint"] for e in m["free_intervals"]] == [2, 4]  # the joints that move
    for entry in m["free_intervals"]:
        assert set(entry) == INTERVAL_KEYS
        i = entry["joint"]
        assert entry["type"] == type(chain.Joints[i]).__name__
        assert entry["name"] == names[i]
        assert entry["range"] == list(chain.Joints[i].stateRange())  # radians / design units
        assert entry["free"] == list(motion.free_intervals[i])
    assert [e["kind"] for e in m["free_intervals"]] == ["prismatic", "revolute"]


def test_json_of_a_self_intersecting_design(colliding):
    result = run("check", colliding, "--json")
    assert result.returncode == 3
    data = strict_json(result.stdout)
    assert data["ok"] is False and data["motion"] is None
    assert data["min_clearance"] == pytest.approx(-0.1, abs=1e-9)
    assert [(p["first"], p["second"]) for p in data["pairs"]] == FOLD_BACK_PAIRS
    assert data["pairs"][0]["clearance"] == pytest.approx(-0.1, abs=1e-9)
    p, q = (np.array(x) for x in data["pairs"][0]["points"])
    assert np.linalg.norm(p - q) == pytest.approx(1.9, abs=1e-9)


def test_json_free_intervals_are_null_when_colliding_at_the_states(colliding_moving):
    result = run("check", colliding_moving, "--motion", 5, "--json")
    assert result.returncode == 3
    data = strict_json(result.stdout)
    assert data["motion"]["free_intervals"]
    assert all(entry["free"] is None for entry in data["motion"]["free_intervals"])


def test_json_when_nothing_is_tested_is_null_not_infinity():
    result = run("check", PLANAR, "--json")
    assert result.returncode == 0
    data = strict_json(result.stdout)
    assert data["ok"] is True
    assert data["min_clearance"] is None and data["closest"] is None


# --- bad input -------------------------------------------------------------------------------
@pytest.mark.parametrize(
    "args, words",
    [
        (["--motion", "0"], ["--motion", "an integer in [1, 100000]", "got 0"]),
        (["--motion", "-3"], ["--motion", "got -3"]),
        (["--motion", "1000001"], ["--motion", "got 1000001"]),
        (["--motion", "abc"], ["--motion", "got 'abc'"]),
        (["--motion", "1.5"], ["--motion", "got '1.5'"]),
        (["--motion", "1e3"], ["--motion", "got '1e3'"]),
        (["--seed", "-1"], ["--seed", "an integer >= 0", "got -1"]),
        (["--seed", "x", "--motion", "5"], ["--seed", "got 'x'"]),
        (["--motion", "5", "--json", "--seed", ""], ["--seed", "got ''"]),
    ],
)
def test_bad_arguments_are_one_line_errors(args, words):
    result = run("check", EXAMPLE1, *args)
    assert_clean_failure(result, "kinegami check: error:", *words)
    assert result.stdout == ""


@pytest.mark.parametrize("args", [["--motion"], ["--seed"], ["--frobnicate"], []])
def test_unparseable_command_lines_are_usage_errors(args):
    result = run("check", EXAMPLE1, *args) if args else run("check")
    assert result.returncode == 2
    assert "usage: kinegami" in result.stderr
    assert "Traceback" not in result.stderr
    assert len(result.stderr.strip().splitlines()) == 1, result.stderr  # docs/cli.md: one line


@pytest.mark.parametrize(
    "content, words",
    [
        ("{not json", ["bad.json"]),
        (dict(fold_back(1.9), numSides=5), ["bad.json", "numSides"]),
        ({**fold_back(1.9), "joints": [{"type": "BallJoint"}]}, ["bad.json", "BallJoint"]),
    ],
    ids=["syntax", "range", "joint type"],
)
@pytest.mark.parametrize("json_flag", [[], ["--json"]], ids=["text", "json"])
def test_a_malformed_design_is_one_line_and_exit_1(tmp_path, content, words, json_flag):
    path = write(tmp_path / "bad.json", content)
    before = listing(tmp_path)
    result = run("check", path, "--motion", 10, *json_flag)
    assert_clean_failure(result, "kinegami check: error:", *words)
    assert result.stdout == ""
    assert listing(tmp_path) == before


def test_a_missing_design_is_one_line_and_exit_1(tmp_path):
    result = run("check", tmp_path / "missing.json")
    assert_clean_failure(result, "missing.json")


@pytest.mark.parametrize("args", [[], ["--motion", "20"], ["--motion", "20", "--json"]])
def test_nothing_is_written(tmp_path, colliding, args):
    """Neither next to the design nor in the working folder, clear or not."""
    shutil.copy(EXAMPLE1, tmp_path / "example1.json")
    before = listing(tmp_path)
    for design in ("example1.json", colliding.name):
        result = run("check", design, *args, cwd=tmp_path)
        assert result.returncode in (0, 3), result.stderr
        assert listing(tmp_path) == before


def test_help():
    result = run("check", "--help")
    assert result.returncode == 0
    for word in ("usage: kinegami check", "--motion", "--seed", "--json", "3"):
        assert word in result.stdout
    assert "check" in run("--help").stdout


# --- build ------------------------------------------------------------------------------------
def test_build_prints_the_clearance_of_a_clear_design(tmp_path):
    _, _, _, report = library(EXAMPLE1)
    result = run("build", EXAMPLE1, "-o", tmp_path / "out", "--formats", "dxf")
    assert result.returncode == 0, result.stderr
    assert result.stderr == ""
    assert (f"  clearance: {report.verdict('cm')}\n") in result.stdout
    assert f"minimum clearance {report.min_clearance * 10:.1f} mm (" in report.verdict("cm")


def test_build_warns_and_still_builds_a_self_intersecting_design(tmp_path, colliding):
    out = tmp_path / "out"
    result = run("build", colliding, "-o", out, "--formats", "dxf")
    assert result.returncode == 0, result.stderr
    assert [p.name for p in out.iterdir()] == ["fold_back.dxf"]
    verdict = ("self-intersects, parts closer than the margin 0 mm: minimum clearance -0.10 mm, "
               "between joint 0, StartTip 'base' and link 3, second elbow; 4 pairs of parts")
    assert f"  clearance: {verdict}\n" in result.stdout
    warning = result.stderr.strip().splitlines()
    assert len(warning) == 1
    assert warning[0].startswith(f"kinegami build: warning: {colliding} at its states: {verdict} "
                                 "(the files are written all the same")  # fmt: skip


def test_build_of_a_design_with_nothing_to_test(tmp_path):
    result = run("build", PLANAR, "-o", tmp_path / "out", "--formats", "dxf")
    assert result.returncode == 0
    assert "  clearance: clear with margin 0 mm: no two parts are far enough apart" in result.stdout
