"""kinegami._record.Record: the light named tuple the pattern modules declare their records with."""

from __future__ import annotations

import copy
import pickle

import pytest

from kinegami._record import Record


class Pair(Record):
    first: int
    second: float = 2.5

    @property
    def total(self) -> float:
        return self.first + self.second


def test_fields_defaults_and_keywords():
    assert Pair(1) == (1, 2.5)
    assert Pair(1, 3.0) == (1, 3.0)
    assert Pair(second=4.0, first=2) == (2, 4.0)
    assert Pair(1).total == 3.5
    assert Pair._fields == ("first", "second")
    assert Pair._field_defaults == {"second": 2.5}
    first, second = Pair(7, 8.0)
    assert (first, second) == (7, 8.0)


def test_repr_replace_asdict():
    p = Pair(1)
    assert repr(p) == "Pair(first=1, second=2.5)"
    assert p._replace(second=0.0) == Pair(1, 0.0)
    assert p._asdict() == {"first": 1, "second": 2.5}


@pytest.mark.parametrize(
    "args, kwargs, words",
    [((), {}, "missing the field 'first'"), ((1, 2, 3), {}, "takes 2 fields, got 3"),
     ((1,), {"third": 0}, "unexpected or repeated fields ['third']"),
     ((1,), {"first": 0}, "unexpected or repeated fields ['first']")],
)  # fmt: skip
def test_bad_fields_are_refused(args, kwargs, words):
    with pytest.raises(TypeError) as caught:
        Pair(*args, **kwargs)
    assert words in str(caught.value)


def test_read_only_and_without_dict():
    p = Pair(1)
    with pytest.raises(AttributeError):
        p.first = 2
    with pytest.raises(AttributeError):
        p.other = 2
    assert not hasattr(p, "__dict__")


def test_pickle_and_copy():
    p = Pair(3, 1.0)
    for clone in (pickle.loads(pickle.dumps(p)), copy.deepcopy(p), copy.copy(p)):
        assert clone == p and type(clone) is Pair


def test_a_field_without_default_after_one_with_is_an_error():
    with pytest.raises(TypeError, match="needs a default"):

        class Bad(Record):
            a: int = 0
            b: int


def test_subclass_of_a_record_keeps_its_fields():
    class Named(Pair):
        def label(self) -> str:
            return f"{self.first}/{self.second}"

    assert Named(1).label() == "1/2.5" and Named._fields == Pair._fields
