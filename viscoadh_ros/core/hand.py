"""Several contacts stepped as one sample, all or nothing (the node's hand command).

:func:`step_contacts` is the one place a sample of many contacts is stepped: today a loop over
the contacts' simulators, later a compiled multi-contact step with the same contract. Either
every contact takes its step, or none changes (bit for bit) and :class:`ContactStepError` names
the contact that could not.
"""

from __future__ import annotations

from collections.abc import Sequence

from .errors import InputError
from .simulator import ContactSimulator, StepOutput

#: Control modes of :func:`step_contacts` (the values of HandCommand.DEPTH / FORCE).
DEPTH = 0
FORCE = 1


class ContactStepError(InputError):
    """One contact of a sample could not take its step; ``index`` is its position in the sample.
    No contact of the sample changed."""

    def __init__(self, index: int, message: str) -> None:
        super().__init__(message)
        self.index = index


def step_contacts(
    simulators: Sequence[ContactSimulator],
    times: Sequence[float],
    mode: int,
    values: Sequence[float],
) -> list[StepOutput]:
    """Step ``simulators[i]`` to ``times[i]`` (s) under depth (``mode`` DEPTH, ``values[i]`` m)
    or force control (FORCE, N), for every i; returns the outputs in the same order.

    All or nothing: if any step fails (bad value, time going back, a contact the domain cannot
    represent, an unreachable force), every simulator already stepped is restored to its state
    before the call and :class:`ContactStepError` (an InputError) carries the failing index and
    the core's reason. Each simulator must appear once.
    """
    count = len(simulators)
    if len(times) != count or len(values) != count:
        raise InputError(
            f"step_contacts needs one time and one value per simulator (got {count} simulators, "
            f"{len(times)} times, {len(values)} values)"
        )
    if mode not in (DEPTH, FORCE):
        raise InputError(f"mode must be DEPTH ({DEPTH}) or FORCE ({FORCE}) (got {mode})")
    if len({id(simulator) for simulator in simulators}) != count:
        raise InputError("step_contacts needs each simulator once (a simulator is listed twice)")
    # Each simulator's transaction token, not a snapshot: a contact that stepped is undone from
    # the journal its step wrote (no copies of the memory on the way through).
    tokens = [simulator._undo_token() for simulator in simulators]
    outputs: list[StepOutput] = []
    index = 0
    try:
        if mode == DEPTH:
            for index in range(count):
                outputs.append(simulators[index].step(times[index], depth=values[index]))
        else:
            for index in range(count):
                outputs.append(simulators[index].step(times[index], force=values[index]))
    except ValueError as error:
        # The failing simulator restored itself (step is a transaction); undo the ones before.
        for done in range(index):
            simulators[done]._undo(tokens[done])
        raise ContactStepError(index, str(error)) from None
    except BaseException:
        for done in range(index):
            simulators[done]._undo(tokens[done])
        raise
    return outputs
