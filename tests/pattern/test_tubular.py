"""The TubularPattern data structure: construction, immutability, derived quantities."""

import numpy as np
import pytest
from numpy.testing import assert_allclose, assert_array_equal

from kinegami.errors import InvalidParameterError, InvalidTypeError, KinegamiError
from kinegami.pattern import (
    ElbowFittingPattern,
    EndTipPattern,
    ModuleRecord,
    TubeFittingPattern,
    TubularPattern,
    TwistFittingPattern,
    WaypointPattern,
)

from .helpers import prism_numbers


def _square_tube(**overrides):
    b, _, W = prism_numbers(4, 1.0)
    x = (np.arange(4) + 0.5) * b
    kwargs = dict(
        numSides=4,
        r=1.0,
        vertices_coords=np.concatenate([np.c_[x, np.zeros(4)], np.c_[x, np.ones(4)]]),
        edges_vertices=np.c_[np.arange(4), 4 + np.arange(4)],
        edges_assignment=["M"] * 4,
        proximalBase=np.arange(4),
        distalBase=4 + np.arange(4),
        proximalMarker=(0.0, 0.0),
        distalMarker=(0.0, 1.0),
        height=1.0,
    )
    kwargs.update(overrides)
    return TubularPattern(**kwargs)


def test_constructor_builds_a_valid_pattern():
    p = _square_tube()
    assert (p.numVertices, p.numEdges, p.numMountains, p.numValleys) == (8, 4, 4, 0)
    assert p.kind == "custom"
    assert p.validate().ok


def test_constructor_copies_its_inputs():
    coords = np.zeros((8, 2))
    b, _, _ = prism_numbers(4, 1.0)
    coords[:4, 0] = coords[4:, 0] = (np.arange(4) + 0.5) * b
    coords[4:, 1] = 1.0
    p = _square_tube(vertices_coords=coords)
    coords[0, 0] = 99.0
    assert p.vertices_coords[0, 0] != 99.0
    assert coords.flags.writeable


def test_arrays_are_read_only():
    p = TubeFittingPattern(6, 1.0, 1.0)
    for array in (p.vertices_coords, p.edges_vertices, p.edges_assignment, p.proximalBase,
                  p.distalBase, p.proximalMarker, p.distalMarker):  # fmt: skip
        with pytest.raises(ValueError):
            array[0] = array[1]


def test_attributes_cannot_be_reassigned():
    p = TubeFittingPattern(6, 1.0, 1.0)
    with pytest.raises(AttributeError):
        p.height = 2.0
    with pytest.raises(AttributeError):
        p.new_attribute = 1


def test_public_attribute_types():
    p = TwistFittingPattern(6, 1.0, 0.5, 0.5)
    assert isinstance(p.numSides, int) and isinstance(p.r, float)
    assert p.vertices_coords.dtype == float and p.vertices_coords.shape == (12, 2)
    assert np.issubdtype(p.edges_vertices.dtype, np.integer) and p.edges_vertices.shape == (24, 2)
    assert set(p.edges_assignment.tolist()) == {"M", "V"}
    assert p.proximalBase.shape == p.distalBase.shape == (6,)
    assert p.proximalMarker.shape == p.distalMarker.shape == (2,)


def test_width_is_n_times_side():
    b, _, W = prism_numbers(8, 2.5)
    p = TubeFittingPattern(8, 2.5, 1.0)
    assert_allclose([p.width, p.sideLength, p.eps], [W, b, 1e-4 * b])


def test_crease_vectors_take_the_shortest_path_across_the_seam():
    b, _, W = prism_numbers(4, 1.0)
    p = _square_tube(
        vertices_coords=[[0.1, 0.0], [W - 0.1, 0.0], [1.0, 0.0], [2.0, 0.0], [0.1, 1.0],
                         [W - 0.1, 1.0], [1.0, 1.0], [2.0, 1.0]],
        edges_vertices=[[0, 1], [1, 0]],
        edges_assignment=["M", "V"],
        proximalBase=None,
        distalBase=None,
    )  # fmt: skip
    assert_allclose(p.crease_vectors(), [[-0.2, 0.0], [0.2, 0.0]], atol=1e-12)
    assert_allclose(p.edge_lengths(), [0.2, 0.2], atol=1e-12)


def test_edge_lengths_of_a_tube_are_its_height():
    assert_allclose(TubeFittingPattern(6, 1.0, 2.5).edge_lengths(), np.full(6, 2.5))


def test_repr_names_kind_and_counts():
    text = repr(ElbowFittingPattern(4, 1.0, np.pi / 2, 0.0))
    assert "elbow" in text and "numVertices=18" in text and "numEdges=28" in text


def test_module_records_carry_parameters():
    p = TubeFittingPattern(6, 1.0, 2.0).append(TwistFittingPattern(6, 1.0, 0.3, 0.4))
    assert [m.kind for m in p.modules] == ["tube", "twist"]
    assert p.modules[1].params == {"twistAngle": 0.3, "moduleHeight": 0.4}
    assert p.kind == "composite"


@pytest.mark.parametrize(
    "overrides, match",
    [
        ({"vertices_coords": np.zeros((8, 3))}, "vertices_coords"),
        ({"vertices_coords": np.full((8, 2), np.nan)}, "finite"),
        ({"edges_vertices": [[0, 8]]}, "edges_vertices"),
        ({"edges_assignment": ["M"] * 3}, "edges_assignment"),
        ({"edges_assignment": ["M", "V", "B", "M"]}, "'M' or 'V'"),
        ({"proximalBase": [0, 1, 2]}, "proximalBase"),
        ({"distalBase": [4, 5, 6, 99]}, "distalBase"),
        ({"proximalMarker": (0.0,)}, "proximalMarker"),
        ({"height": -1.0}, "height"),
        ({"numSides": 5}, "numSides"),
        ({"r": 0.0}, "r must"),
    ],
)
def test_constructor_rejects_bad_data(overrides, match):
    with pytest.raises(InvalidParameterError, match=match):
        _square_tube(**overrides)


def test_constructor_rejects_float_edges():
    with pytest.raises(InvalidTypeError, match="edges_vertices"):
        _square_tube(edges_vertices=np.zeros((4, 2)))


def test_constructor_rejects_foreign_module_records():
    with pytest.raises(InvalidTypeError, match="ModuleRecord"):
        _square_tube(modules=["tube"])


def test_errors_are_kinegami_and_builtin():
    with pytest.raises(KinegamiError):
        _square_tube(height=-1.0)
    with pytest.raises(ValueError):
        _square_tube(height=-1.0)


def test_reversed_maps_y_and_swaps_bases_and_markers():
    p = TwistFittingPattern(6, 1.0, 0.5, 0.5)
    q = p.reversed()
    assert_allclose(q.vertices_coords[:, 1], p.height - p.vertices_coords[:, 1])
    assert_allclose(q.vertices_coords[:, 0], p.vertices_coords[:, 0])
    assert_array_equal(q.proximalBase, p.distalBase)
    assert_array_equal(q.distalBase, p.proximalBase)
    assert_allclose(q.proximalMarker, [p.distalMarker[0], 0.0])
    assert_allclose(q.distalMarker, [p.proximalMarker[0], p.height])
    assert_array_equal(q.edges_assignment, p.edges_assignment)


def test_reversed_twice_is_identity():
    p = ElbowFittingPattern(6, 1.0, 1.0, 0.7)
    q = p.reversed().reversed()
    assert_allclose(q.vertices_coords, p.vertices_coords, atol=1e-12)
    assert_array_equal(q.edges_vertices, p.edges_vertices)
    assert_array_equal(q.distalBase, p.distalBase)


def test_reversed_tip_changes_kind():
    assert EndTipPattern(6, 1.0, 0.5).reversed().kind == "start_tip"


def test_empty_pattern_is_empty():
    p = WaypointPattern(6, 1.0)
    assert p.isEmpty and p.height == 0.0 and p.numVertices == 6 and p.numEdges == 0


def test_module_record_is_frozen():
    record = ModuleRecord("tube", {"height": 1.0})
    with pytest.raises(AttributeError):
        record.kind = "twist"
