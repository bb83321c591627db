"""The module catalog: registration, lookups, read-only records and stored module vertices."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from kinegami.errors import InvalidTypeError, ReadOnlyError
from kinegami.pattern import (
    ElbowFittingPattern,
    ModuleRecord,
    PrismaticJointPattern,
    RevoluteJointPattern,
    StartTipPattern,
    TubeFittingPattern,
    TubularPattern,
    TwistFittingPattern,
    WaypointPattern,
    catalog,
)
from kinegami.pattern._build import assemble, crease_block
from kinegami.pattern._fold import polygon_point, translation
from kinegami.pattern._prism import make_prism
from kinegami.pattern.catalog import ModuleCounts, expected_counts
from kinegami.pattern.elbow import _build_elbow_reference, elbow_geometry
from kinegami.pattern.folded import folded_form, unsnapped_form

KINDS = ("tube", "twist", "elbow", "revolute", "rebo", "prismatic", "start_tip", "end_tip",
         "waypoint")  # fmt: skip


def test_every_kind_is_registered_with_build_fold_and_counts():
    assert set(KINDS) <= set(catalog.kinds())
    for name in catalog.kinds():
        entry = catalog.module_kind(name)
        assert entry.name == name
        assert callable(entry.build) and callable(entry.fold) and callable(entry.counts)
        assert callable(entry.unsnapped)


def test_unknown_kind_names_the_known_ones():
    with pytest.raises(catalog.UnknownModuleKindError, match="tube"):
        catalog.module_kind("no such kind")
    assert catalog.find_kind("no such kind") is None


def test_tips_mirror_each_other():
    assert catalog.module_kind("end_tip").mirror == "start_tip"
    assert catalog.module_kind("start_tip").mirror == "end_tip"
    assert catalog.module_kind("tube").mirror is None


# --- a toy kind: registering it touches only the registry ------------------------------------


def _ring_pattern(numSides, r, height):
    """A tube with a valley ring on its distal base (a kind the catalog does not have)."""
    prism = make_prism(numSides, r)
    n = prism.numSides
    x = prism.columns
    vertices = np.concatenate([np.stack([x, np.zeros(n)], 1), np.stack([x, np.full(n, height)], 1)])
    k = np.arange(n)
    blocks = [crease_block(k, n + k, "M"), crease_block(n + k, n + (k + 1) % n, "V")]
    record = ModuleRecord("toy_ring", {"height": float(height)})
    return assemble(prism, vertices, blocks, k, n + k, float(height), record)


def _ring_fold(prism, pattern, params):
    xy = pattern.vertices_coords
    X = polygon_point(prism, xy[:, 0])
    X[:, 2] = xy[:, 1]
    return X, translation(params["height"])


@pytest.fixture
def toy_kind():
    entry = catalog.register(
        catalog.ModuleKind(
            "toy_ring", _ring_pattern, ("height",),
            lambda prism, p: ModuleCounts(2 * prism.numSides, 2 * prism.numSides),
            _ring_fold,
        )
    )  # fmt: skip
    yield entry
    catalog.unregister("toy_ring")


def test_a_registered_toy_kind_validates_composes_and_folds(toy_kind):
    ring = _ring_pattern(4, 1.0, 0.5)
    assert expected_counts(ring.modules[0], make_prism(4, 1.0)) == ModuleCounts(8, 8)
    assert ring.validate().ok
    p = TubularPattern.concatenate([TubeFittingPattern(4, 1.0, 1.0), ring,
                                    ElbowFittingPattern(4, 1.0, 1.0, 0.2)])  # fmt: skip
    assert p.validate().ok
    form = folded_form(p)
    assert form.maxLengthError < 1e-9
    assert [m.kind for m in form.modules] == ["tube", "toy_ring", "elbow"]
    assert unsnapped_form(p).maxLengthError < 1e-9


def test_unregistered_kinds_are_not_counted_and_not_folded(toy_kind):
    ring = _ring_pattern(4, 1.0, 0.75)  # never folded before (folds are cached)
    catalog.unregister("toy_ring")
    assert expected_counts(ring.modules[0], make_prism(4, 1.0)) is None
    with pytest.raises(Exception, match="toy_ring"):
        folded_form(ring)


# --- read-only records -------------------------------------------------------------------------


def test_record_params_are_read_only_and_say_what_to_do():
    p = TubeFittingPattern(4, 1.0, 1.25)
    params = p.modules[0].params
    with pytest.raises(InvalidTypeError, match="read-only.*new record"):
        params["height"] = 2.0
    with pytest.raises(TypeError):
        del params["height"]
    with pytest.raises(ReadOnlyError, match="ModuleRecord.params is read-only.*new one"):
        p.modules[0].params = {"height": 2.0}
    with pytest.raises(ReadOnlyError, match="ModuleRecord.kind is read-only"):
        del p.modules[0].kind
    assert params["height"] == 1.25
    assert params == {"height": 1.25}
    assert dict(params) == {"height": 1.25}
    assert repr(params) == repr({"height": 1.25})


def test_records_freeze_a_given_dict_and_stay_hashable():
    source = {"height": 1.0}
    record = ModuleRecord("tube", source)
    source["height"] = 5.0
    assert record.params["height"] == 1.0
    assert hash(record) == hash(ModuleRecord("tube", {"height": 1.0}))
    assert record == ModuleRecord("tube", {"height": 1.0})


def test_shared_cached_patterns_cannot_be_changed_through_their_records():
    a = RevoluteJointPattern(4, 1.0, np.pi, 1)
    b = RevoluteJointPattern(4, 1.0, np.pi, 1)
    with pytest.raises(InvalidTypeError):
        a.modules[0].params["numSinkLayers"] = 3
    assert b.modules[0].params["numSinkLayers"] == 1


# --- where each module's vertices went -----------------------------------------------------------


def _modules():
    return [
        StartTipPattern(6, 1.0, 1.0), TubeFittingPattern(6, 1.0, 1.0),
        TwistFittingPattern(6, 1.0, 0.4, 0.3), TwistFittingPattern(6, 1.0, 2 * np.pi / 6, 0.0),
        ElbowFittingPattern(6, 1.0, np.pi / 2, 0.0), WaypointPattern(6, 1.0),
        RevoluteJointPattern(6, 1.0, np.pi, 2), PrismaticJointPattern(6, 1.0, 2.0, 3, 0.7),
    ]  # fmt: skip


def test_module_vertices_place_every_module_translated_as_a_whole():
    mods = _modules()
    p = TubularPattern.concatenate(mods)
    placed = p.module_vertices
    assert len(placed) == len(p.modules)
    built = [m for m in mods if not m.isEmpty]
    assert len(built) == len(placed)
    seen = np.zeros(p.numVertices, dtype=bool)
    for module, index in zip(built, placed, strict=True):
        assert index.shape == (module.numVertices,)
        assert not index.flags.writeable
        d = p.vertices_coords[index] - module.vertices_coords
        dx = (d[:, 0] - d[0, 0] + p.width / 2) % p.width - p.width / 2
        assert np.abs(dx).max() < 1e-3 and np.abs(d[:, 1] - d[0, 1]).max() < 1e-3
        seen[index] = True
    assert seen.all()


def test_append_and_concatenate_store_the_same_module_vertices():
    mods = _modules()
    p = TubularPattern.concatenate(mods)
    q = mods[0]
    for m in mods[1:]:
        q = q.append(m)
    assert len(p.module_vertices) == len(q.module_vertices)
    for a, b in zip(p.module_vertices, q.module_vertices, strict=True):
        np.testing.assert_array_equal(a, b)


def test_single_modules_own_their_vertices_and_reversed_composites_do_not():
    tube = TubeFittingPattern(4, 1.0, 1.0)
    np.testing.assert_array_equal(tube.module_vertices[0], np.arange(tube.numVertices))
    composite = TubularPattern.concatenate([tube, ElbowFittingPattern(4, 1.0, 1.0, 0.0)])
    assert composite.reversed().module_vertices is None


# --- the fast elbow layout equals the column-by-column build ---------------------------------


@pytest.mark.parametrize("n", [4, 6, 8, 12])
@pytest.mark.parametrize("theta, phi", [(np.pi / 2, 0.0), (1.0, 0.3), (2.9, 4.0), (0.4, np.pi / 8)])
def test_elbow_layout_matches_the_reference_build(n, theta, phi):
    prism = make_prism(n, 1.0)
    geo = elbow_geometry(prism, theta, phi)
    record = ModuleRecord("elbow", {"bendingAngle": theta, "rotationalAxisAngle": phi})
    fast = ElbowFittingPattern(n, 1.0, theta, phi)
    slow = _build_elbow_reference(prism, geo, record)
    assert fast.modules == (record,)
    for name in ("vertices_coords", "edges_vertices", "edges_assignment", "proximalBase",
                 "distalBase", "distalMarker"):  # fmt: skip
        np.testing.assert_array_equal(getattr(fast, name), getattr(slow, name))
    assert fast.height == slow.height


def _elbow_phi(n: int, mode: str, column: int, free: float) -> float:
    """A free axis angle, or one where columns ``column`` and ``column + 1`` both collapse
    ("pair": midway between them) or where ``column`` is low ("low": a quarter turn from it)."""
    beta = (column + 0.5) * 2.0 * np.pi / n
    return {"free": free, "pair": beta + np.pi / n, "low": beta + np.pi / 2}[mode]


@settings(deadline=None, max_examples=40)
@given(
    n=st.sampled_from([4, 6, 8, 12]),
    elbows=st.lists(
        st.tuples(
            st.floats(0.05, 3.0) | st.sampled_from([np.pi / 2, 3.1]),
            st.sampled_from(["free", "pair", "low"]),
            st.integers(0, 11),
            st.floats(-7.0, 7.0),
        ),
        min_size=1,
        max_size=10,
    ),
)
def test_elbows_built_together_match_the_reference_build(n, elbows):
    """A batch with several layouts (plain, collapsed pairs, low columns) computes them
    together; each elbow equals the column-by-column build of its own angles."""
    angles = [(theta, _elbow_phi(n, mode, j % n, free)) for theta, mode, j, free in elbows]
    prism = make_prism(n, 1.0)
    ElbowFittingPattern.cache_clear()
    prism._cache.clear()  # the layouts too: the batch computes them
    together = ElbowFittingPattern.many([(n, 1.0, theta, phi) for theta, phi in angles])
    for (theta, phi), fast in zip(angles, together, strict=True):
        geo = elbow_geometry(prism, theta, phi)
        slow = _build_elbow_reference(prism, geo, fast.modules[0])
        for name in ("vertices_coords", "edges_vertices", "edges_assignment", "proximalBase",
                     "distalBase", "proximalMarker", "distalMarker"):  # fmt: skip
            np.testing.assert_array_equal(getattr(fast, name), getattr(slow, name), err_msg=name)
            assert not getattr(fast, name).flags.writeable
        assert fast.height == slow.height


def test_constructors_share_patterns_for_equal_arguments_only():
    assert ElbowFittingPattern(4, 1.0, 1.0, 0.0) is ElbowFittingPattern(4, 1.0, 1.0, 0.0)
    assert ElbowFittingPattern(4, 1.0, 1.0, 0.0) is not ElbowFittingPattern(4, 1.0, 1.0, 0.1)
    with pytest.raises(InvalidTypeError):
        catalog.module_kind("rebo").build(4, 1.0, 1.0, 2, 0.7, 1)  # 1 is not a bool
