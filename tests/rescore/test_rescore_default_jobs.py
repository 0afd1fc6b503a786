"""`rescore` without ``--jobs`` starts one worker per core the process may run on: under
``taskset`` or a container's cpuset that is the cpuset's count, not the machine's."""

from __future__ import annotations

import os

import pytest

from ertools.competition.parallel import default_jobs


@pytest.mark.skipif(not hasattr(os, "sched_getaffinity"), reason="n/a: no CPU affinity here")
def test_default_jobs_count_the_cores_the_process_may_use(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(os, "cpu_count", lambda: 16)
    monkeypatch.setattr(os, "sched_getaffinity", lambda pid: {2})
    assert default_jobs() == 1
    monkeypatch.setattr(os, "sched_getaffinity", lambda pid: {0, 1, 7})
    assert default_jobs() == 3


def test_default_jobs_elsewhere_the_machines_count(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.delattr(os, "sched_getaffinity", raising=False)
    monkeypatch.setattr(os, "cpu_count", lambda: 6)
    assert default_jobs() == 6
    monkeypatch.setattr(os, "cpu_count", lambda: None)  # unknown: one, in this process
    assert default_jobs() == 1
