"""An arm designed for a pick-and-place task from its task file (docs/design-for-a-task.md).

``examples/tasks/pick_and_place.json`` names what the arm must do, not what it is: four points
(millimetres) above a table where a part is picked up and set down (above the part, down onto
it, above the place, down onto it), four revolute joints on a hexagonal tube of radius 10 mm
whose root stands 20 mm above the table, the table as a keep-out box, and ``"path": true``: each
move from one point to the next, a straight line in joint space, must be clear too.
``kinegami.optimize.design_for`` fits a Denavit-Hartenberg table and one configuration per point,
builds it with kinegami's placement, checks every point again with the inverse kinematics and
the clearance engine, certifies the three moves and compacts the tube while keeping the task.
The design depends only on the task file and its seed: ``kinegami design
examples/tasks/pick_and_place.json -o out/`` writes the same chain, kept as
``examples/designs/pick_and_place.json`` (with its task).

Run: ``python examples/pick_and_place.py [output-folder]`` (about ten seconds). It prints each
point's joint states and clearance, writes the 3D view, the crease pattern drawing and the DXF
into ``examples/output/pick_and_place/`` (or the folder given) and prints their paths.
"""

import sys

from _common import EXAMPLES, output_folder, report, save_outputs

from kinegami import *
from kinegami.design.task import read_task
from kinegami.optimize import design_for

NAME = "pick_and_place"
TASK = EXAMPLES / "tasks" / "pick_and_place.json"


def build(return_answers: bool = False):
    """The arm the task file asks for; with ``return_answers``, also one reach answer per
    target (its states reach the point exactly and clear) and the certified moves."""
    task = read_task(TASK)
    found = design_for(list(task.targets), task.joints, return_answers=True, **task.options())
    return found if return_answers else found[0]


if __name__ == "__main__":
    arm, answers, moves = build(return_answers=True)
    task = read_task(TASK)
    for spec, answer in zip(task.document["targets"], answers, strict=True):
        states = ", ".join(f"{np.degrees(q):.1f}" for q in answer.states[:4])
        print(f"{spec['name']:>12} at {spec['position']}: states ({states}) deg, clearance "
              f"{answer.clearance:.2f} mm")  # fmt: skip
    for k, move in enumerate(moves):
        print(f"move {k} -> {k + 1}: clear, {len(move)} configurations measured along it")
    written = save_outputs(arm, NAME, output_folder(NAME, sys.argv))
    report(arm, NAME, written)
