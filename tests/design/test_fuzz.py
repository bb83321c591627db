"""Fuzzing the design loader: mutated gallery designs load or fail with a DesignError.

The gallery designs (examples/designs/*.json) are mutated the way hostile or careless files
are: values replaced by other types, huge or non-finite numbers, long or odd unicode texts,
nesting (a few levels, just past the cap, or a thousand), keys deleted, duplicated or renamed,
items copied, integer literals too long for ``int()`` and 100,000-deep brackets spliced into
the text. Whatever comes out must give a chain or a one-line DesignError (no warning, no other
exception). This is the fuzzing that found the crashes of issue 9, section 3.

A quick run by default (a few seconds); ``KINEGAMI_FUZZ_EXAMPLES=2000`` runs a longer one.
"""

from __future__ import annotations

import copy
import json
import os
import warnings
from pathlib import Path

from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from kinegami.design import DesignError, chain_from_dict, limits, loads_design
from kinegami.design.schema import EDIT_OPS, JOINT_TYPES
from kinegami.errors import ClearanceWarning

from . import located

GALLERY = sorted((Path(__file__).parents[2] / "examples" / "designs").glob("*.json"))
DESIGNS = {path.name: json.loads(path.read_text(encoding="utf-8")) for path in GALLERY}
EXAMPLES = int(os.environ.get("KINEGAMI_FUZZ_EXAMPLES", "40"))

#: Keys and names of the format, so that mutations often hit meaningful places.
WORDS = [
    *JOINT_TYPES, *EDIT_OPS, "format", "version", "units", "angleUnits", "numSides", "r",
    "joints", "dh", "rows", "edits", "states", "pose", "Trans", "Tx", "Rz", "point", "axis",
    "xhat", "length", "joint", "distance", "state", "name", "kinegami-design", "deg", "mm",
    "parent", "structure", "tree", "chain", "placement", "method", "wafr2024",
    "growthDirection", "root", "palm",
]  # fmt: skip
LONG_LITERAL = "-" + "9" * 5000  # too many digits for int()
DEEP_LITERAL = "[" * 100_000 + "]" * 100_000
#: The deepest nesting a mutated document gets (json.dumps writes it; the loader's cap is 32).
DEEPEST = 980

scalars = st.one_of(
    st.none(),
    st.booleans(),
    st.integers(-70, 70),
    st.integers(),
    st.sampled_from([10**400, -(10**400), 2**1024, 2**53 + 1, 64, 65, 200, 201, 1000, 1001]),
    st.floats(),
    st.sampled_from([1e308, -1e308, 5e-324, 1e-7, 1e6, 2e6, 1e12, 1e13, 1e154, -0.0]),
    st.text(max_size=12),
    st.sampled_from(WORDS),
    st.sampled_from(["x" * 10_000, "\u00e9\u2014\U0001f600", "\ud800", "\x00\n\t", "1e999"]),
)
values = st.recursive(
    scalars,
    lambda children: st.lists(children, max_size=5)
    | st.dictionaries(st.sampled_from(WORDS) | st.text(max_size=8), children, max_size=4),
    max_leaves=12,
)


def _places(document):
    """Every (path, value) of a document, the document itself first (no recursion: earlier
    mutations may have nested a value a thousand levels deep)."""
    stack = [((), document)]
    while stack:
        path, node = stack.pop()
        yield path, node
        if isinstance(node, dict):
            items = list(node.items())
        elif isinstance(node, list):
            items = list(enumerate(node))
        else:
            items = []
        stack.extend(((*path, key), value) for key, value in reversed(items))


def _parent(document, path):
    node = document
    for part in path[:-1]:
        node = node[part]
    return node


class _Splice:
    """Text spliced into the JSON where a placeholder string stands."""

    def __init__(self):
        self.texts: dict[str, str] = {}

    def placeholder(self, text: str) -> str:
        key = f"\x00splice{len(self.texts)}\x00"
        self.texts[json.dumps(key)] = text
        return key

    def dumps(self, document) -> str:
        text = json.dumps(document, ensure_ascii=False, allow_nan=True)
        for key, spliced in self.texts.items():
            text = text.replace(key, spliced)
        return text


@st.composite
def mutated_designs(draw, splice: bool = True):
    """(text or document, how it was made) of a mutated gallery design."""
    name = draw(st.sampled_from(sorted(DESIGNS)))
    document = copy.deepcopy(DESIGNS[name])
    splicer = _Splice()
    rng = draw(st.randoms(use_true_random=True))
    done = [name]
    for _ in range(draw(st.integers(1, 3))):
        places = list(_places(document))[1:]  # the document itself is only rarely mutated
        if not places or rng.random() < 0.03:
            path, node, kinds = (), document, ["wrap"]
        else:
            # spread evenly (hypothesis favours the first items of sampled_from and small ints)
            path, node = rng.choice(places)
            kinds = ["replace", "wrap", "copy", "delete", "rename"]
            if splice:
                kinds += ["long literal", "deep literal", "duplicate"]
        kind = draw(st.sampled_from(kinds))
        done.append(f"{kind} {list(path)}")
        parent = _parent(document, path) if path else None
        if kind == "replace":
            parent[path[-1]] = draw(values)
        elif kind == "wrap":
            depth = draw(st.sampled_from([1, 2, limits.MAX_DEPTH - 2, limits.MAX_DEPTH, 980]))
            # at most DEEPEST levels in all: two wraps of a thousand (or one and another of
            # 32) nest past what json.dumps itself can write (a RecursionError in the test's
            # own dumps, before the loader sees anything)
            depth = min(depth, DEEPEST - max(len(place) for place, _ in _places(document)))
            for _ in range(depth):
                node = [node]
            if path:
                parent[path[-1]] = node
            else:
                document = node
        elif kind == "copy" and isinstance(node, list) and node:
            node.extend(node[: draw(st.integers(1, 3))])  # shared items: like JSON copies
        elif kind == "delete":
            del parent[path[-1]]
        elif kind == "rename" and isinstance(parent, dict):
            key = draw(st.sampled_from(WORDS) | st.text(max_size=8))
            parent[key] = parent.pop(path[-1])
        elif kind == "long literal":
            parent[path[-1]] = splicer.placeholder(LONG_LITERAL)
        elif kind == "deep literal":
            parent[path[-1]] = splicer.placeholder(DEEP_LITERAL)
        elif kind == "duplicate" and isinstance(parent, dict):
            key = splicer.placeholder(json.dumps(path[-1], ensure_ascii=False))
            parent[key] = draw(values)  # the same key again, with another value
    if not splice:
        return document, done
    return splicer.dumps(document), done


def _loads_or_design_error(load, design, how) -> None:
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # no warning may escape either, but
        # a ClearanceWarning: a design that passes through itself (the paper's hand does; so
        # may a mutated one) loads with one, as documented
        warnings.simplefilter("ignore", ClearanceWarning)
        try:
            load(design, "fuzz.json")
        except DesignError as error:
            text = str(error)
            assert text.startswith(f"fuzz.json: {located(error)}"), (how, text)
            assert "\n" not in text and len(text) < 1200, (how, text)
            assert error.file == "fuzz.json"


FUZZ = settings(
    max_examples=EXAMPLES,
    deadline=None,
    suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large],
)


@FUZZ
@given(mutated_designs())
def test_mutated_design_texts_load_or_fail_with_a_design_error(case):
    text, how = case
    _loads_or_design_error(loads_design, text, how)


@settings(FUZZ, max_examples=max(10, EXAMPLES // 2))
@given(mutated_designs(splice=False))
def test_mutated_design_dicts_load_or_fail_with_a_design_error(case):
    document, how = case
    _loads_or_design_error(chain_from_dict, document, how)


def test_the_gallery_designs_load():
    for name, document in DESIGNS.items():
        chain_from_dict(document, name)
