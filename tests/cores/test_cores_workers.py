"""``workers``: the cores this process may run on."""

from __future__ import annotations

import os

import pytest

from ertools import cores


@pytest.mark.skipif(not hasattr(os, "sched_getaffinity"), reason="n/a: no CPU affinity here")
def test_workers_count_the_cores_the_process_may_use(monkeypatch: pytest.MonkeyPatch) -> None:
    # pinned to one core of many (taskset, a container's cpuset): no thread to compete
    monkeypatch.setattr(os, "cpu_count", lambda: 8)
    monkeypatch.setattr(os, "sched_getaffinity", lambda pid: {3})
    assert cores.workers() == 1
    monkeypatch.setattr(os, "sched_getaffinity", lambda pid: {0, 5})
    assert cores.workers() == 2
