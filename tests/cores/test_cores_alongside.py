"""``alongside``: a task on a second core beside a with-block. Its result or its error reaches
the caller, its thread never outlives the block nor prints, and on a single core (or without
``parallel``) it runs first on the calling thread."""

from __future__ import annotations

import threading
import time

import pytest

from ertools import cores as cores_module
from ertools.cores import alongside
from ertools.errors import ClockError, ScoringError


def helpers() -> list[threading.Thread]:
    return [t for t in threading.enumerate() if t.name == "ertools-alongside"]


@pytest.fixture
def two_cores(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(cores_module, "workers", lambda: 2)


@pytest.mark.usefixtures("two_cores")
def test_the_task_runs_on_another_thread_while_the_block_goes_on() -> None:
    started = threading.Event()
    go_on = threading.Event()
    ran_on: list[int] = []

    def task() -> int:
        ran_on.append(threading.get_ident())
        started.set()
        # waits for the block: a task run before or after the block would time out here
        assert go_on.wait(30)
        return 6 * 7

    with alongside(task) as result:
        assert started.wait(30)
        go_on.set()
        assert result() == 42
        assert result() == 42  # asked again: the same
    assert ran_on != [threading.get_ident()]
    assert helpers() == []


@pytest.mark.usefixtures("two_cores")
def test_the_tasks_error_reaches_the_caller_as_itself_and_nothing_is_printed(
    capfd: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    hooked: list[object] = []
    monkeypatch.setattr(threading, "excepthook", hooked.append)
    raised = ClockError("the audit failed")

    def task() -> int:
        raise raised

    with alongside(task) as result, pytest.raises(ClockError) as caught:
        result()
    assert caught.value is raised
    assert hooked == []
    assert capfd.readouterr() == ("", "")
    assert helpers() == []


@pytest.mark.usefixtures("two_cores")
def test_an_error_of_the_block_waits_for_the_task() -> None:
    finished: list[bool] = []
    release = threading.Event()

    def task() -> int:
        assert release.wait(30)
        time.sleep(0.05)  # still running when the block's error is raised
        finished.append(True)
        return 1

    with pytest.raises(ScoringError, match="the block's"), alongside(task):
        release.set()
        raise ScoringError("the block's")
    assert finished == [True]
    assert helpers() == []


@pytest.mark.usefixtures("two_cores")
def test_the_tasks_error_wins_over_the_blocks() -> None:
    """A serial run meets the task's error first (the task runs before the block)."""

    def task() -> int:
        raise ClockError("the task's")

    with pytest.raises(ClockError, match="the task's"), alongside(task):
        raise ScoringError("the block's")
    assert helpers() == []


@pytest.mark.usefixtures("two_cores")
def test_an_interrupt_in_the_block_is_not_replaced() -> None:
    def task() -> int:
        raise ClockError("the task's")

    with pytest.raises(KeyboardInterrupt), alongside(task):
        raise KeyboardInterrupt
    assert helpers() == []


@pytest.mark.parametrize("cores, parallel", [(1, True), (2, False)])
def test_one_core_or_serial_runs_the_task_first_on_the_calling_thread(
    monkeypatch: pytest.MonkeyPatch, cores: int, parallel: bool
) -> None:
    monkeypatch.setattr(cores_module, "workers", lambda: cores)
    events: list[tuple[str, int]] = []

    def task() -> str:
        events.append(("task", threading.get_ident()))
        return "done"

    with alongside(task, parallel=parallel) as result:
        events.append(("block", threading.get_ident()))
        assert helpers() == []
        assert result() == "done"
    me = threading.get_ident()
    assert events == [("task", me), ("block", me)]


def test_one_core_raises_the_tasks_error_before_the_block(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    monkeypatch.setattr(cores_module, "workers", lambda: 1)
    entered: list[bool] = []

    def task() -> int:
        raise ClockError("the task's")

    with pytest.raises(ClockError, match="the task's"), alongside(task):
        entered.append(True)
    assert entered == []
