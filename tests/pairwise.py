"""Pairwise-covering sets of runs: every pair of values of every two options appears in a run.

Options tested only all together hide a crossed wire (one flag writing another's output);
all combinations are too many. A pairwise-covering set is the usual middle: each option
alone is one more test, and every two options' values meet in some run. One generator for
every test that crosses options (the CLI's commands, the constrained dynamics' options).
"""

from __future__ import annotations

import itertools
from collections.abc import Callable, Mapping, Sequence

#: Whether a partial run (some options chosen) can be completed; True when it cannot tell.
Valid = Callable[[dict], bool]


def pairwise(factors: Mapping[str, Sequence], valid: Valid | None = None) -> list[dict]:
    """A small deterministic set of runs covering every valid pair of option values.

    Greedy: each run starts from the first uncovered pair and fills in, option by option,
    the value that covers the most pairs still uncovered (among values ``valid`` accepts).

    Args:
        factors: Each option's values, the first its default.
        valid: Accepts a partial run (a dict of the options chosen so far); a pair it
            refuses on its own is not required.

    Returns:
        The runs, each a dict of every option's value.
    """
    valid = valid or (lambda run: True)
    names = list(factors)
    uncovered = {
        frozenset([(a, i), (b, j)])
        for a, b in itertools.combinations(names, 2)
        for i in range(len(factors[a]))
        for j in range(len(factors[b]))
        if valid({a: factors[a][i], b: factors[b][j]})
    }
    runs: list[dict] = []
    while uncovered:
        (a, i), (b, j) = sorted(min(uncovered, key=sorted))
        chosen = {a: i, b: j}
        for name in names:
            if name in chosen:
                continue
            fits = [k for k in range(len(factors[name])) if valid(_values(factors, chosen | {name: k}))]
            if not fits:
                raise ValueError(f"no value of {name!r} completes the run {_values(factors, chosen)}")
            chosen[name] = max(fits, key=lambda k: (_gain(uncovered, chosen, name, k), -k))
        uncovered -= {frozenset(pair) for pair in itertools.combinations(chosen.items(), 2)}
        runs.append(_values(factors, chosen))
    return runs


def uncovered_pairs(runs: list[dict], factors: Mapping[str, Sequence], valid: Valid | None = None) -> list[tuple]:
    """The valid pairs of option values no run holds (empty for a covering set): the check
    a test of a pairwise set asserts, independent of how the set was made."""
    valid = valid or (lambda run: True)
    missing = []
    for a, b in itertools.combinations(factors, 2):
        for x, y in itertools.product(factors[a], factors[b]):
            if valid({a: x, b: y}) and not any(run[a] == x and run[b] == y for run in runs):
                missing.append((a, x, b, y))
    return missing


def _values(factors: Mapping[str, Sequence], chosen: dict) -> dict:
    return {name: factors[name][k] for name, k in chosen.items()}


def _gain(uncovered: set, chosen: dict, name: str, k: int) -> int:
    """How many uncovered pairs value ``k`` of ``name`` covers beside the values chosen."""
    return sum(frozenset([(name, k), (other, chosen[other])]) in uncovered for other in chosen)
