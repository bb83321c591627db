"""Shared helpers of the editor tests: example documents and an exact document snapshot."""

from __future__ import annotations

from pathlib import Path

from kinegami.editor import Document, EditorModel

ROOT = Path(__file__).resolve().parents[2]
EXAMPLE1 = ROOT / "examples" / "designs" / "example1.json"


def example_model() -> EditorModel:
    """A model editing a copy-free load of examples/designs/example1.json (7 joints, named)."""
    return EditorModel.open(EXAMPLE1)


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
        tuple(type(j).__name__ for j in chain.Joints),
        tuple(j.pose_matrix.tobytes() for j in chain.Joints),
        tuple(float(j.state) for j in chain.Joints),
        tuple(k.start_frame.tobytes() + k.end_frame.tobytes() for k in chain.Links),
        chain.boundingBall.c.tobytes(),
        document.names,
        (document.name, document.description, document.units, document.twistPortion),
        (chain.requireClearance, chain.maxAnglePerElbow),
    )
