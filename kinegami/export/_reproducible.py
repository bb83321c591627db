"""Reproducible files: ``SOURCE_DATE_EPOCH`` (https://reproducible-builds.org/specs/source-date-epoch/).

Two files are the only outputs that change from one write to the next: a DXF file records when
it was written and carries two new GUIDs (as ezdxf and CAD programs do), and a 3MF file gives
its objects new UUIDs (trimesh's writer). With the environment variable ``SOURCE_DATE_EPOCH``
set to a time (whole seconds since 1970-01-01 UTC), they record that time instead and take
their identifiers from their content, so building the same design twice gives the same bytes in
every format (matplotlib's PDF already honours the variable; the other formats never depend on
the time). docs/fabrication.md, "Reproducible builds".
"""

from __future__ import annotations

import os
import re

from kinegami.errors import InvalidParameterError

__all__ = ["content_uuid", "reproducible_3mf", "source_date_epoch"]

#: The environment variable of the reproducible-builds convention.
VARIABLE = "SOURCE_DATE_EPOCH"

_UUID = re.compile(rb"[0-9a-fA-F]{8}-[0-9a-fA-F]{4}-[0-9a-fA-F]{4}-[0-9a-fA-F]{4}-[0-9a-fA-F]{12}")


def source_date_epoch() -> int | None:
    """The time of ``SOURCE_DATE_EPOCH`` (seconds since 1970-01-01 UTC), or None when it is
    unset or empty.

    Raises
    ------
    InvalidParameterError
        If it is set to anything but a whole number of seconds >= 0.
    """
    text = os.environ.get(VARIABLE, "").strip()
    if not text:
        return None
    if not text.isascii() or not text.isdigit() or len(text) > 12:
        shown = text if len(text) <= 40 else text[:37] + "..."
        raise InvalidParameterError(
            f"{VARIABLE} must be a whole number of seconds since 1970-01-01 UTC (an integer from "
            f"0 to 999999999999), got {shown!r}; unset it to write the current time"
        )
    return int(text)


def content_uuid(content: bytes, tag: str) -> str:
    """A UUID (RFC 9562 version 8, lower-case hex with dashes) determined by ``content`` and
    ``tag``: equal inputs give equal UUIDs, different tags different ones."""
    import hashlib

    raw = bytearray(hashlib.blake2b(tag.encode() + b"\0" + content, digest_size=16).digest())
    raw[6] = raw[6] & 0x0F | 0x80  # version 8: custom
    raw[8] = raw[8] & 0x3F | 0x80  # RFC 9562 variant
    h = raw.hex()
    return f"{h[:8]}-{h[8:12]}-{h[12:16]}-{h[16:20]}-{h[20:]}"


def reproducible_3mf(data: bytes) -> bytes:
    """``data`` (a 3MF file) unchanged, or, when ``SOURCE_DATE_EPOCH`` is set, with every UUID
    of its parts replaced by one made from the part's content and the UUID's place in it (the
    k-th UUID of a part), and its zip entries dated at that time (at the earliest 1980, the
    first date a zip file can hold)."""
    epoch = source_date_epoch()
    if epoch is None:
        return data
    import io
    import time
    import zipfile

    date = max(time.gmtime(epoch)[:6], (1980, 1, 1, 0, 0, 0))
    source = zipfile.ZipFile(io.BytesIO(data))
    out = io.BytesIO()
    with zipfile.ZipFile(out, "w", zipfile.ZIP_DEFLATED) as target:
        for entry in source.infolist():
            info = zipfile.ZipInfo(entry.filename, date_time=date)
            info.compress_type = entry.compress_type
            info.external_attr = entry.external_attr
            target.writestr(info, _with_content_uuids(source.read(entry), entry.filename))
    return out.getvalue()


def _with_content_uuids(content: bytes, name: str) -> bytes:
    """``content`` (the part ``name`` of a file) with its k-th UUID made from the part without
    its UUIDs, its name and k."""
    import itertools

    blank = _UUID.sub(b"0" * 36, content)
    k = itertools.count()
    return _UUID.sub(lambda _: content_uuid(blank, f"{name} #{next(k)}").encode(), content)
