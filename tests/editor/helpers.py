"""Shared helpers of the editor tests: example documents, the trees' reference numbers and an
exact document snapshot."""

from __future__ import annotations

import time
from pathlib import Path

from kinegami.editor import Document, EditorModel

ROOT = Path(__file__).resolve().parents[2]
EXAMPLE1 = ROOT / "examples" / "designs" / "example1.json"
#: The paper's hand as published (12 joints, 3 leaves; the fingers leave the root waypoint; the
#: gallery's examples/designs/hand.json has the palm slid so that its socket fits) and a
#: two-finger gripper (10 joints, 2 leaves; the fingers leave the palm, joint 3).
HAND = ROOT / "tests" / "design" / "data" / "papers_hand.json"
GRIPPER = ROOT / "examples" / "designs" / "gripper.json"

#: What the editor shows of the paper's hand: its parents, its sheets (one per leaf: the middle
#: finger's continues the root's, then the pointer's and the thumb's), the one junction at the
#: root, and the slide kinegami build makes so that the palm's socket fits (joint 1 by -3 r).
HAND_PARENTS = (-1, 0, 1, 2, 3, 0, 5, 6, 0, 8, 9, 10)
HAND_SHEET_JOINTS = ((0, 8, 9, 10, 11), (5, 6, 7), (1, 2, 3, 4))
HAND_SLIDES = ((1, -3.0),)
HAND_JUNCTION = (0, (1, 5, 8), 8)  # (joint, children, trunk)


def example_model() -> EditorModel:
    """A model editing a copy-free load of examples/designs/example1.json (7 joints, named)."""
    return EditorModel.open(EXAMPLE1)


def hand_model() -> EditorModel:
    """A model editing the paper's hand as published (every joint named)."""
    return EditorModel.open(HAND)


def snapshot(document: Document) -> tuple:
    """Everything of a document, exactly: design text (or why there is none), the bits of
    every joint pose, state and link frame, the names and the options."""
    try:
        text = document.design_text
    except ValueError as error:
        text = f"unsaveable: {error}"
    chain = document.chain
    return (
        text,
        type(chain).__name__,
        tuple(chain.Parents),
        tuple(type(j).__name__ for j in chain.Joints),
        tuple(j.pose_matrix.tobytes() for j in chain.Joints),
        tuple(float(j.state) for j in chain.Joints),
        tuple(k.start_frame.tobytes() + k.end_frame.tobytes() for k in chain.Links),
        chain.boundingBall.c.tobytes(),
        document.names,
        (document.name, document.description, document.units, document.twistPortion),
        (chain.requireClearance, chain.maxAnglePerElbow),
    )


def wait_for(condition, what: str, timeout: float = 60.0, step: float = 0.1):
    """``condition()``'s first true value, polled every ``step`` s; an AssertionError naming
    ``what`` after ``timeout`` s (a liveness bound for the browser tests, not a timing test)."""
    end = time.monotonic() + timeout
    while time.monotonic() < end:
        value = condition()
        if value:
            return value
        time.sleep(step)
    raise AssertionError(f"timed out after {timeout} s waiting for {what}")


def choose(page, combobox: str, option: str, attempts: int = 5, timeout: float = 15.0) -> None:
    """Pick ``option`` in the page's ``combobox`` (a Mantine select): click the box, then the
    option. A panel the server draws again (a message, a design just opened) can close the
    drop-down between the two clicks; then Escape and open it again, ``attempts`` times."""
    from playwright.sync_api import TimeoutError as PlaywrightTimeout

    for _ in range(attempts):
        page.get_by_role("combobox", name=combobox, exact=True).click()
        try:
            page.get_by_role("option", name=option, exact=True).click(timeout=timeout * 1000)
            return
        except PlaywrightTimeout:
            page.keyboard.press("Escape")
    raise AssertionError(f"the {combobox!r} list never offered {option!r} ({attempts} tries)")
