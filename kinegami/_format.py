"""Rendering user values in messages: one line, bounded length, whatever the value.

A leaf module (no kinegami imports), so that the error classes (kinegami/errors.py) and the
parameter checks (kinegami/validation.py) can both use it.
"""

from __future__ import annotations

import json
import math

import numpy as np

__all__ = ["SHOWN_LIMIT", "format_value", "shorten", "shown", "shown_path"]

#: Longest rendering of a value in a message, in characters (longer ones end in "...").
SHOWN_LIMIT = 80


def _digits(value: int) -> str:
    """How many decimal digits the int ``value`` has ("about N" when too long to print)."""
    try:
        return str(len(str(abs(value))))
    except ValueError:  # more digits than sys.get_int_max_str_digits()
        return f"about {int(abs(value).bit_length() * math.log10(2)) + 1}"


def shorten(text: str, limit: int = SHOWN_LIMIT) -> str:
    """``text`` on one line, cut to ``limit`` characters (ending in "...") if longer."""
    text = " ".join(str(text).split())
    return text if len(text) <= limit else text[: limit - 3] + "..."


def shown_path(path, limit: int = SHOWN_LIMIT) -> str:
    """A file path for messages, at most ``limit`` characters: a long one keeps its start and
    its end (the name that usually matters) with "..." between them."""
    text = repr(" ".join(str(path).split()))
    if len(text) <= limit:
        return text
    tail = (limit - 3) * 2 // 3
    return text[: limit - 3 - tail] + "..." + text[-tail:]


def shown(value, limit: int = SHOWN_LIMIT) -> str:
    """A one-line ``repr`` of a user value for messages, at most ``limit`` characters.

    Integers too long to be useful (more than 30 digits) are described by their number of
    digits, so that even ints beyond ``sys.get_int_max_str_digits()`` can be named.
    """
    if isinstance(value, int) and not isinstance(value, bool) and value.bit_length() > 100:
        sign = "a negative" if value < 0 else "an"
        return f"<{sign} integer of {_digits(value)} digits>"
    if isinstance(value, str | list | tuple) and len(value) > limit:
        value = value[: limit + 1]  # the repr of the rest would be cut anyway
    try:
        text = repr(value)
    except Exception:  # a repr that fails (recursion, huge ints inside a container)
        text = f"<{type(value).__name__}>"
    return shorten(text, limit)


def _one_line(text: str) -> str:
    return " ".join(str(text).split())


def format_value(value, limit: int = 100) -> str:
    """A short one-line JSON-like rendering of ``value`` for messages (at most ``limit``
    characters, ending in "..." when cut).

    Only the first ``limit`` characters are ever produced: a list of a million joints, a value
    nested a thousand levels deep or an integer of 5000 digits costs no more than a number.
    """
    pieces = []
    size = 0
    for piece in _pieces(value, limit):
        pieces.append(piece)
        size += len(piece)
        if size > limit:
            break
    text = _one_line("".join(pieces))
    if len(text) > limit:
        text = text[: limit - 3] + "..."
    return text


class _Text(str):
    """A piece of punctuation in :func:`_pieces` (not a value to render)."""


def _pieces(value, limit: int):
    """The rendering of ``value`` piece by piece, without recursion (lazily)."""
    stack = [iter((value,))]
    while stack:
        item = next(stack[-1], _END)
        if item is _END:
            stack.pop()
        elif type(item) is _Text:
            yield item
        elif isinstance(item, dict):
            stack.append(_object_pieces(item))
        elif isinstance(item, list | tuple) or (
            isinstance(item, np.ndarray) and item.ndim > 0
        ):
            stack.append(_array_pieces(item))
        else:
            yield _scalar(item, limit)


_END = object()


def _object_pieces(obj: dict):
    yield _Text("{")
    for k, (key, value) in enumerate(obj.items()):
        key = key if isinstance(key, str) else str(key)
        yield _Text((", " if k else "") + _string(key, 100) + ": ")
        yield value
    yield _Text("}")


def _array_pieces(items):
    yield _Text("[")
    for k, value in enumerate(items):
        if k:
            yield _Text(", ")
        yield value
    yield _Text("]")


def _string(text: str, limit: int) -> str:
    return json.dumps(text[: limit + 1], ensure_ascii=False)


def _scalar(value, limit: int) -> str:
    if value is None:
        return "null"
    if isinstance(value, bool | np.bool_):
        return "true" if value else "false"
    if isinstance(value, str):
        return _string(value, limit)
    if isinstance(value, int | np.integer):
        return shown(int(value))  # digits counted, not printed, for huge ints
    if isinstance(value, float | np.floating):
        value = float(value)
        if math.isnan(value):
            return "NaN"
        if math.isinf(value):
            return "Infinity" if value > 0 else "-Infinity"
        return repr(value)
    return shown(value, limit)


# --- values ---------------------------------------------------------------------------------
