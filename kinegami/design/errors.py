"""DesignError: every problem found in a design file, located by a JSON path."""

from __future__ import annotations

import contextlib
import json
import math
import os
import re

import numpy as np

from kinegami.errors import KinegamiError
from kinegami.validation import shown

__all__ = ["DesignError", "json_path", "numeric_errors"]

#: Marker for "no offending value" (``None`` is a valid JSON value: ``null``).
_NO_VALUE = object()

_IDENTIFIER = re.compile(r"[A-Za-z_][A-Za-z0-9_]*\Z")


#: Longest key shown in a JSON path (longer ones end in "...").
_KEY_LIMIT = 40


def json_path(parts) -> str:
    """``("joints", 2, "pose")`` -> ``"joints[2].pose"``; the empty path is ``"$"``.

    Keys longer than 40 characters are shortened (ending in "...").
    """
    text = ""
    for part in parts:
        if isinstance(part, int):
            text += f"[{part}]"
            continue
        part = str(part)
        if len(part) > _KEY_LIMIT:
            part = part[: _KEY_LIMIT - 3] + "..."
        if _IDENTIFIER.match(part):
            text += f".{part}" if text else part
        else:
            text += f"[{json.dumps(part, ensure_ascii=False)}]"
    return text or "$"


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


class DesignError(KinegamiError, ValueError):
    """A design file cannot be read, is invalid, or describes an infeasible chain.

    Attributes
    ----------
    file : str or None
        The design file (None for a design given as text or as a dict without a file name).
    field : str
        JSON path of the problem, e.g. ``joints[2].totalBendingAngle``; ``$`` is the document.
    value : object
        The offending value (None if there is none; see ``has_value``).
    reason : str
        What is wrong and what is allowed.

    ``str(error)`` is one line: ``<file>: <field>: <reason> (got <value>)``.
    """

    def __init__(
        self,
        reason: str,
        *,
        field: str = "$",
        value=_NO_VALUE,
        file: str | os.PathLike | None = None,
    ):
        self.reason = _one_line(reason)
        self.field = field
        self.has_value = value is not _NO_VALUE
        self.value = value if self.has_value else None
        self.file = None if file is None else os.fspath(file)
        super().__init__(str(self))

    def with_file(self, file) -> DesignError:
        """The same error attributed to ``file`` (used when a file name becomes known)."""
        value = self.value if self.has_value else _NO_VALUE
        return DesignError(self.reason, field=self.field, value=value, file=file)

    def __str__(self) -> str:
        text = f"{self.field}: {self.reason}"
        if self.has_value:
            text += f" (got {format_value(self.value)})"
        if self.file is not None:
            text = f"{self.file}: {text}"
        return text

    def __reduce__(self):
        return (_rebuild, (self.reason, self.field, self.has_value, self.value, self.file))


def _rebuild(reason, field, has_value, value, file):
    return DesignError(reason, field=field, value=value if has_value else _NO_VALUE, file=file)


#: Numeric problems a design's numbers could cause (overflow, NaN, division by zero).
NUMERIC_ERRORS = (FloatingPointError, OverflowError, ZeroDivisionError)


@contextlib.contextmanager
def numeric_errors(field: str, file=None, what: str = "numeric error"):
    """Run the block with numpy overflow, invalid and divide errors raised, not warned about.

    A FloatingPointError (or a Python OverflowError / ZeroDivisionError) becomes a DesignError
    at ``field``; nothing is printed. Underflow (a result rounding to 0) is ignored: it is
    harmless and happens in ordinary geometry.
    """
    try:
        with np.errstate(over="raise", invalid="raise", divide="raise", under="ignore"):
            yield
    except NUMERIC_ERRORS as error:
        raise DesignError(
            f"{what} ({type(error).__name__}: {error}); lengths, coordinates and angles "
            "this large or small cannot be computed",
            field=field,
            file=file,
        ) from None
