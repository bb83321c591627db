"""Every limit that keeps kinegami's work bounded, in one place (docs/limits.md).

Each input is answered in bounded time and memory: what it may ask for is capped here, and the
cap is enforced where the input enters (design files: :mod:`kinegami.design.limits`; the API:
:mod:`kinegami.validation`; the command line: :mod:`kinegami.cli`; the editor: the design
loader and its commands). A value beyond a cap is a one-line
:class:`~kinegami.errors.InvalidParameterError` (or a DesignError for a file) naming the value,
the limit and why. This module holds numbers only and imports nothing, so every layer may use
it.
"""

from __future__ import annotations

import math

__all__ = [
    "R_MIN",
    "R_MAX",
    "LENGTH_FACTOR",
    "NUM_SIDES_MAX",
    "FILE_NUM_SIDES_MAX",
    "NUM_SINK_LAYERS_MAX",
    "NUM_LAYERS_MAX",
    "MIN_ANGLE_PER_ELBOW",
    "MAX_FILE_BYTES",
    "MAX_JOINTS",
    "MAX_DH_ROWS",
    "MAX_EDITS",
    "MAX_STATES",
    "MAX_POSE_STEPS",
    "MAX_DEPTH",
    "MAX_SAMPLES",
    "MAX_SAMPLED_STATES",
    "MAX_WORKSPACE_SAMPLES",
    "MAX_REACHABILITY_DIRECTIONS",
    "MAX_REPORTED_PAIRS",
    "MEMO_CAPSULE_ROWS",
    "MAX_STARTS",
    "MAX_PDF_PAGES",
    "MAX_INTEGER_DIGITS",
    "TAKEOFF_WORK",
    "MAX_PATTERN_VERTICES",
    "MAX_API_JOINTS",
]

# --- sizes and lengths (the API and design files) -----------------------------------------
#: Smallest and largest tube radius r (in the chain's length unit).
R_MIN = 1e-6
R_MAX = 1e6
#: Every length, distance and translation coordinate given to the API or written in a design
#: file satisfies ``|value| <= LENGTH_FACTOR * r``: squares and products of such values stay far
#: from the float range, and r stays well above their rounding error.
LENGTH_FACTOR = 1e6
#: Most polygon sides of a tube given to the API: at 256 sides already, elbows and joints are
#: too fine to resolve and say so; a prismatic joint of 1024 sides and 200 layers has 6e5
#: pattern vertices (2.6 s).
NUM_SIDES_MAX = 1024
#: Most polygon sides in a design or joint-specification file.
FILE_NUM_SIDES_MAX = 64
#: Most sink layers of a revolute joint: its pattern grows with their number (1e7 layers ran
#: past a minute and 2 GB before any answer).
NUM_SINK_LAYERS_MAX = 32
#: Most REBO layers of a prismatic joint: its pattern has about 3 numSides vertices per layer.
NUM_LAYERS_MAX = 200
#: Smallest maxAnglePerElbow (radians; one degree): a link turning by theta has
#: ceil(theta / maxAnglePerElbow) elbows, at most 360 per link; 1e-9 asked numpy for 167 GiB.
MIN_ANGLE_PER_ELBOW = math.pi / 180.0

# --- design files ------------------------------------------------------------------------------
#: Largest design file, in bytes (16 MiB).
MAX_FILE_BYTES = 16 * 1024 * 1024
#: Most entries of "joints" of a design (loading takes about 15 ms per joint with safe
#: placement; 1000 placed joints take about a minute).
MAX_JOINTS = 1000
#: Most rows of a DH table.
MAX_DH_ROWS = 1000
#: Most edits of a design (each re-solves links and the bounding ball).
MAX_EDITS = 1000
#: Most states: one per joint of the built chain (safe placement adds up to four waypoints per
#: joint).
MAX_STATES = 5 * MAX_JOINTS
#: Most steps of a pose written as a list of steps.
MAX_POSE_STEPS = 100
#: Deepest nesting of lists and objects in a design (the document is level 1; designs need 6).
MAX_DEPTH = 32

# --- work asked for by options ---------------------------------------------------------------
#: Most configurations one motion check samples (``check --motion N``, ``sweep(samples=)``,
#: ``compact(samples=)``). Measured on a loaded 2-core machine: Example 1 (a chain) tests about
#: 10,000 configurations a second, the quadruped (a tree) about 16.
MAX_SAMPLES = 100_000
#: Most sampled joint states held at once: configurations times the joints of the chain (the
#: sampled configurations are one array, 8 bytes a state: 80 MB).
MAX_SAMPLED_STATES = 10_000_000
#: Most configurations one workspace draws (kinegami.reach.workspace keeps every clear one and
#: its tip: 2,000,000 samples of a 7-joint design hold about 160 MB; drawn and tested in
#: batches of 20,000).
MAX_WORKSPACE_SAMPLES = 2_000_000
#: Most approach directions per voxel of a workspace's reachability index (one inverse
#: kinematics per voxel and direction, in batches of 4,096 targets).
MAX_REACHABILITY_DIRECTIONS = 256
#: Most pairs of parts one clearance report lists (closest first); it counts the others
#: (``ClearanceReport.unlisted``). A chain folded onto itself out of one-degree elbows can have
#: 600,000 overlapping pairs of parts.
MAX_REPORTED_PAIRS = 1_000
#: Capsule rows each memo of capsules by link or joint keeps (kinegami.chain.bodies; about
#: 400 bytes a row: 100 MiB). Counted by entries alone, 16,384 links of 720 one-degree elbows
#: could keep gigabytes: a fuzzer's worker grew past its 2 GiB over 600 cases.
MEMO_CAPSULE_ROWS = 262_144
#: Most starts of one compaction (``compact(starts=)``): each is a whole search.
MAX_STARTS = 64
#: Default most pages of a PDF (``max_pages``; the user may raise it per export).
MAX_PDF_PAGES = 200
#: Most digits of an integer option on the command line (``--seed``, ``--motion``, ``--port``).
MAX_INTEGER_DIGITS = 30

# --- work inside one operation -------------------------------------------------------------
#: Most capsule tests of one tree's take-off search (kinegami.fabrication.takeoffs, every joint's
#: and every attempt of fabricate's together; each joint gets what is left over the joints still
#: to place): each candidate placement is a clearance test of the whole folded body, so a body of
#: S capsules (about two per elbow and two per joint) measures at most TAKEOFF_WORK / S
#: candidates. Ordinary trees (a few hundred capsules: every face at 5 heights and 48 sets)
#: stay within it; a 22-joint tree of one-degree elbows (3,820 capsules, four take-off joints)
#: measures 26 candidates at about 0.2 s each.
TAKEOFF_WORK = 100_000
#: Most crease-pattern vertices of one chain's pattern or one tree's sheets, estimated from
#: the counts before anything is built (kinegami.pattern.catalog.check_pattern_size): each count
#: is within its own limit, but their product is not (1,000 joints, up to 720 elbows a link,
#: numSides up to 1024, 200 layers). A vertex costs about 250 bytes with its edges; 2,000,000
#: vertices is over three 1024-sided prismatic joints of 200 layers (0.6 M vertices each,
#: 160 MB).
MAX_PATTERN_VERTICES = 2_000_000
#: Most joints of a chain or tree built through the Python API (append, addJoint, from_dh...):
#: as MAX_JOINTS for design files plus what safe placement adds (up to four waypoints a joint).
MAX_API_JOINTS = 5 * MAX_JOINTS
