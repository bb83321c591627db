"""JSON paths and numeric-error guards for design files.

:class:`~kinegami.errors.DesignError` (every problem found in a design file, located by a JSON
path) lives in :mod:`kinegami.errors` and is re-exported here; :func:`format_value` (a value in
a message) lives in :mod:`kinegami.validation`.
"""

from __future__ import annotations

import contextlib
import json
import re

import numpy as np

from kinegami.errors import DesignError
from kinegami.validation import format_value

__all__ = ["DesignError", "format_value", "json_path", "numeric_errors"]

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
