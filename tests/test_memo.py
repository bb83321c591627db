"""The weighted memo (kinegami._memo): bounded by the weight it keeps, not only by entries."""

from __future__ import annotations

from hypothesis import given
from hypothesis import strategies as st

from kinegami._memo import weighted_lru_cache
from kinegami.chain import bodies


@given(st.lists(st.integers(0, 30), max_size=200), st.integers(1, 8), st.integers(1, 60))
def test_a_memo_keeps_within_its_weight_and_answers_as_the_function(calls, maxsize, bound):
    made = []

    @weighted_lru_cache(maxsize, bound, weight=len)
    def word(n: int) -> str:
        made.append(n)
        return "x" * n

    for n in calls:
        assert word(n) == "x" * n
        info = word.cache_info()
        assert info.currsize <= maxsize and info.weight <= bound
    info = word.cache_info()
    assert info.hits + info.misses == len(calls) and info.misses == len(made)
    word.cache_clear()
    assert word.cache_info()[:4] == (0, 0, maxsize, 0)


def test_the_least_recently_used_go_first():
    @weighted_lru_cache(10, 6, weight=len)
    def word(n: int) -> str:
        return "x" * n

    word(2), word(3), word(2)  # 2 used last
    word(1)  # weight 6: all kept
    assert word.cache_info().currsize == 3
    word(3)  # a hit: 3 now newest, 2 oldest
    word(4)  # drops the oldest until within 6: 2 then 1 (4 + 3 > 6 drops 3 as well)
    hits = word.cache_info().hits
    word(4)
    assert word.cache_info().hits == hits + 1
    assert word.cache_info().weight <= 6


def test_the_capsule_memos_are_bounded_by_rows():
    for memo in (bodies.link_capsule_arrays, bodies.joint_capsule_arrays, bodies._link_rows,
                 bodies._joint_rows):  # fmt: skip
        assert memo.cache_info().max_weight == bodies.MEMO_CAPSULE_ROWS
