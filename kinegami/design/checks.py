"""Checks and tables on a chain built from a design: its crease pattern and its joint table.

* :func:`check_pattern` builds the chain's crease pattern and reports a pattern that cannot be
  built (e.g. elbows too small to resolve) as a DesignError naming the joint or link.
* :func:`joint_table` lists the joints of the built chain (index, type, name), the indices that
  ``edits`` and ``states`` use; safe placement inserts waypoints, so they differ from the
  positions in the file's ``joints`` list.
"""

from __future__ import annotations

import os

from kinegami.chain.model import KinematicChain
from kinegami.design.errors import NUMERIC_ERRORS, DesignError, json_path, numeric_errors
from kinegami.design.reader import (
    DEFAULT_TWIST_PORTION,
    DesignInfo,
    DesignOrigin,
    build_plan,
    check_document,
    origin_of,
)
from kinegami.errors import InvalidTypeError, KinegamiError
from kinegami.pattern import TubularPattern
from kinegami.tree import KinematicTree
from kinegami.validation import shorten

__all__ = ["check_pattern", "joint_table"]


def _check_chain(chain) -> None:
    if not isinstance(chain, KinematicChain | KinematicTree):
        raise InvalidTypeError(
            f"chain must be a KinematicChain or a KinematicTree, got {type(chain).__name__}"
        )


def _field_of(origin: DesignOrigin | None, index: int) -> str:
    """The design field a joint of the built chain comes from ("$" when unknown)."""
    if origin is None:
        return "$"
    if origin.kind == "dh":
        return "dh"
    entry = origin.sources[index]
    return "$" if entry is None else json_path(["joints", entry])


def _joint_text(chain: KinematicChain, origin: DesignOrigin | None, index: int) -> str:
    joint = chain.Joints[index]
    text = f"chain joint {index} ({type(joint).__name__}"
    if origin is not None and origin.names[index] is not None:
        text += f" '{shorten(origin.names[index])}'"
    elif origin is not None and origin.kind == "joints" and origin.sources[index] is None:
        text += ", added by safe placement"
    return text + ")"


def _first_failure(chain: KinematicChain, twistPortion: float):
    """(kind, index, error) of the first joint or link whose pattern cannot be built."""
    checks = [("joint", 0, lambda: chain.Joints[0].pattern)]
    for i in range(1, len(chain)):
        link = chain.Links[i]
        checks.append(("link", i, lambda k=link: k.pattern_modules(chain.numSides, twistPortion)))
        checks.append(("joint", i, lambda k=i: chain.Joints[k].pattern))
    for kind, index, build in checks:
        try:
            with numeric_errors("$"):
                build()
        except (KinegamiError, *NUMERIC_ERRORS) as error:
            return kind, index, error
    return None


def _reason(error: Exception) -> str:
    return error.reason if isinstance(error, DesignError) else str(error)


def check_pattern(
    chain: KinematicChain | KinematicTree,
    info: DesignInfo | None = None,
    file: str | os.PathLike | None = None,
) -> TubularPattern:
    """The crease pattern of ``chain`` (``chain.creasePattern(info.twistPortion)``), checked.

    Parameters
    ----------
    chain : a chain, usually from :func:`kinegami.design.load_design_with_info`. A tree has
        no single crease pattern: a DesignError points to its sheets.
    info : the design's info; gives ``twistPortion`` (default 0.2 without it) and the file.
    file : the design file named in errors (default ``info.file``, else the file the chain
        was loaded from, if known).

    Returns
    -------
    TubularPattern
        The chain's crease pattern (lengths in the design's units), so a caller need not
        build it twice.

    Raises
    ------
    DesignError
        When the pattern cannot be built (any KinegamiError or numeric error of the pattern
        code). The error names the first joint or link whose pattern fails: its reason says
        ``chain joint i`` or ``link i`` (indices of ``chain.Joints`` / ``chain.Links``), and its
        field is the design entry the joint came from (``joints[k]``; ``dh`` for a DH design;
        ``$`` when unknown, e.g. a waypoint added by safe placement or a chain not loaded from a
        design).
    """
    _check_chain(chain)
    if info is not None and not isinstance(info, DesignInfo):
        raise InvalidTypeError(f"info must be a DesignInfo or None, got {type(info).__name__}")
    twistPortion = DEFAULT_TWIST_PORTION if info is None else info.twistPortion
    origin = origin_of(chain)
    if file is None and info is not None:
        file = info.file
    if file is None and origin is not None:
        file = origin.file
    if not hasattr(chain, "creasePattern"):  # a tree: one pattern per sheet
        raise DesignError(
            f"the design loads as a KinematicTree of {len(chain.Joints)} joints, which has no "
            "single crease pattern but one per sheet: kinegami.fabrication.sheets.fabricate(tree) "
            "builds them ('kinegami build' writes them)",
            file=file,
        )
    try:
        with numeric_errors("$", file):
            return chain.creasePattern(twistPortion=twistPortion)
    except (KinegamiError, *NUMERIC_ERRORS) as error:
        failure = _first_failure(chain, twistPortion)
        if failure is None:  # every module builds; joining them failed
            raise DesignError(
                f"the crease pattern cannot be built: {_reason(error)}", file=file
            ) from None
        kind, index, cause = failure
        where = _joint_text(chain, origin, index)
        what = where if kind == "joint" else f"link {index} (into {where})"
        hint = ""
        if kind == "link" and "too small to resolve" in _reason(cause):
            hint = (
                f" (an elbow of this link turns too little for numSides = {chain.numSides}: "
                "fewer numSides, a larger maxAnglePerElbow, or moving a joint so that the link "
                "turns more or not at all may help)"
            )
        raise DesignError(
            f"the crease pattern of {what} cannot be built: {_reason(cause)}{hint}",
            field=_field_of(origin, index),
            file=file,
        ) from None


def _consistent(origin: DesignOrigin | None, entries: list, types: tuple) -> bool:
    """Whether ``origin`` maps the chain's joints onto ``entries`` of the same types."""
    if origin is None or origin.kind != "joints":
        return False
    for k, kind in zip(origin.sources, types, strict=True):
        if k is not None and (k >= len(entries) or entries[k].get("type") != kind):
            return False
    return True


def joint_table(
    chain: KinematicChain | KinematicTree, document: dict
) -> list[tuple[int, str, str | None]]:
    """The joints of ``chain`` as ``(index, type name, name or None)``, in chain order.

    ``index`` is the joint's index in ``chain.Joints`` (what ``edits`` and ``states`` use),
    ``name`` the ``"name"`` of the ``joints`` entry it came from (None for waypoints added by
    safe placement, unnamed entries and DH designs).

    Parameters
    ----------
    chain : the chain built from ``document`` (e.g. by ``load_design``); later Python edits
        that keep its joints (moves, states) are fine.
    document : the design document (a dict, e.g. from :func:`kinegami.design.read_design`).

    The loader remembers which entry each joint came from; for a chain it did not build (or
    whose joints were deleted or appended since), the document is built again to find out.

    Raises
    ------
    DesignError
        If the document is invalid, or describes a chain with other joints than ``chain``.
    """
    _check_chain(chain)
    if not isinstance(document, dict):
        raise InvalidTypeError(f"document must be a dict, got {type(document).__name__}")
    types = tuple(type(joint).__name__ for joint in chain.Joints)
    entries = document.get("joints")
    if not isinstance(entries, list) or all(
        not isinstance(e, dict) or e.get("name") is None for e in entries
    ):
        return [(i, kind, None) for i, kind in enumerate(types)]
    origin = origin_of(chain)
    if not _consistent(origin, entries, types):
        built, origin = build_plan(check_document(document))
        if origin.types != types:
            raise DesignError(
                f"the chain does not come from this design: the design builds {len(built)} "
                f"joints ({', '.join(origin.types)}), the chain has {len(types)} "
                f"({', '.join(types)})"
            )
    names = [None if k is None else entries[k].get("name") for k in origin.sources]
    return [(i, kind, name) for i, (kind, name) in enumerate(zip(types, names, strict=True))]
