"""A least-recently-used memo bounded by the total weight of what it keeps (docs/limits.md).

``functools.lru_cache`` bounds the number of entries only: a memo of capsule rows keyed by link
kept 16,384 links, and a link of 720 one-degree elbows has 1,440 rows, so a long session (the
fuzzer's workers, an editor left open) grew by gigabytes. This one drops the least recently used
entries once the weights of those it keeps pass ``max_weight``.
"""

from __future__ import annotations

import functools
import threading
from collections import OrderedDict
from collections.abc import Callable
from typing import Any, NamedTuple


class MemoInfo(NamedTuple):
    """As ``functools.lru_cache``'s ``cache_info()``, with the weight kept and its bound."""

    hits: int
    misses: int
    maxsize: int
    currsize: int
    weight: int
    max_weight: int


def weighted_lru_cache(maxsize: int, max_weight: int, weight: Callable[[Any], int]):
    """Decorate a function of hashable arguments with a memo of at most ``maxsize`` entries
    whose ``weight(result)`` add up to at most ``max_weight`` (a result heavier than that on
    its own is returned, not kept). ``cache_clear()`` empties it, ``cache_info()`` says how
    full it is. Thread-safe; a call that raises keeps nothing."""

    def decorate(function: Callable) -> Callable:
        kept: OrderedDict = OrderedDict()  # key -> (result, weight), oldest first
        lock = threading.Lock()
        state = {"hits": 0, "misses": 0, "weight": 0}

        @functools.wraps(function)
        def wrapper(*args):
            with lock:
                found = kept.get(args)
                if found is not None:
                    kept.move_to_end(args)
                    state["hits"] += 1
                    return found[0]
                state["misses"] += 1
            result = function(*args)
            w = max(1, int(weight(result)))
            if w > max_weight:
                return result
            with lock:
                if args not in kept:
                    kept[args] = (result, w)
                    state["weight"] += w
                    while len(kept) > maxsize or state["weight"] > max_weight:
                        state["weight"] -= kept.popitem(last=False)[1][1]
            return result

        def cache_clear() -> None:
            with lock:
                kept.clear()
                state.update(hits=0, misses=0, weight=0)

        def cache_info() -> MemoInfo:
            with lock:
                return MemoInfo(state["hits"], state["misses"], maxsize, len(kept),
                                state["weight"], max_weight)  # fmt: skip

        wrapper.cache_clear = cache_clear  # type: ignore[attr-defined]
        wrapper.cache_info = cache_info  # type: ignore[attr-defined]
        return wrapper

    return decorate
