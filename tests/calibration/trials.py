"""The calibration trials of bench/calibration/ run from the tests (a small number of them)."""

from __future__ import annotations

import importlib


def coverage(module_name: str, trials: int, draws: int) -> tuple[int, int, list[str]]:
    """(scores, covered, the misses described) over seeds 0..trials-1."""

    module = importlib.import_module(f"calibration.{module_name}")
    scores = covered = 0
    misses = []
    for seed in range(trials):
        for key, true, low, high in module.trial(seed, draws):
            scores += 1
            if low <= true <= high:
                covered += 1
            else:
                misses.append(f"seed {seed} {key}: {true:.6g} not in [{low:.6g}, {high:.6g}]")
    return scores, covered, misses
