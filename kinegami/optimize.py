"""Making placed chains more compact without changing their kinematics.

Sliding a joint along its axis of motion keeps every axis line, so the robot's kinematics are
unchanged; only the tube between the joints gets shorter or longer (chain.md 5.2).
"""

from __future__ import annotations

import warnings

from kinegami.chain import KinematicChain, PlacementWarning
from kinegami.errors import InvalidTypeError
from kinegami.validation import check_int, check_positive

__all__ = ["shorten_by_axis_translations"]


def shorten_by_axis_translations(
    chain: KinematicChain,
    step: float | None = None,
    rounds: int = 6,
    minStep: float | None = None,
) -> list[tuple[int, float]]:
    """Shorten the chain's tube by sliding joints along their axes (greedy, in place).

    Each round tries, for every joint after the root, the slides +step and -step (only that
    joint moves; ``propagate=False``) and keeps a slide when the chain accepts it and the total
    path length drops. The step halves after a round that improves nothing, down to
    ``minStep``. Failed trial edits leave the chain unchanged and are not reported.

    Parameters
    ----------
    chain : the chain, edited in place.
    step : first slide length (chain units; default 4 r).
    rounds : number of halvings of the step (>= 0).
    minStep : stop below this step (default r / 8).

    Returns the accepted edits as (joint index, distance) pairs, in order; replaying them with
    ``translateJointAlongAxisOfMotion(j, d, propagate=False)`` rebuilds the result.
    """
    if not isinstance(chain, KinematicChain):
        raise InvalidTypeError(f"chain must be a KinematicChain, got {type(chain).__name__}")
    step = 4.0 * chain.r if step is None else check_positive("step", step)
    minStep = chain.r / 8.0 if minStep is None else check_positive("minStep", minStep)
    rounds = check_int("rounds", rounds, minimum=0)
    accepted: list[tuple[int, float]] = []
    halvings = 0
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", PlacementWarning)
        while step >= minStep:
            improved = False
            for j in range(1, len(chain.Joints)):
                for distance in (step, -step):
                    before = chain.totalPathLength()
                    saved = (list(chain._joints), list(chain._links), chain._ball)
                    if not chain.translateJointAlongAxisOfMotion(j, distance, propagate=False):
                        continue
                    if chain.totalPathLength() < before - 1e-9 * chain.r:
                        accepted.append((j, distance))
                        improved = True
                        break
                    chain._commit(*saved)  # exactly as before the trial
            if not improved:
                if halvings >= rounds:
                    break
                halvings += 1
                step /= 2.0
    return accepted
