"""The cores this process may use, and a task run on a second one beside other work.

Below the layers that use them: the bulk reader's loading threads and lanes
(:mod:`ertools.io.pipeline`), the trajectory score's clock audit and offset grid
(:mod:`ertools.benchmarks.trajectory`) and ``rescore``'s default ``--jobs``.
"""

from __future__ import annotations

import contextlib
import os
import threading
from collections.abc import Callable, Iterator
from typing import TypeVar

T = TypeVar("T")


def workers() -> int:
    """The cores this process may run on, not the machine's: pinned to one core
    (``taskset``, a container's cpuset) a second thread only competes with the first."""
    if hasattr(os, "sched_getaffinity"):  # Linux; elsewhere the machine's count
        return len(os.sched_getaffinity(0)) or 1
    return os.cpu_count() or 1


@contextlib.contextmanager
def alongside(task: Callable[[], T], *, parallel: bool = True) -> Iterator[Callable[[], T]]:
    """``task()`` on a second core while the with-block goes on: the block is given a function
    that waits for the task and returns its result, or raises its error.

    For a task that spends its time in NumPy loops (they release the GIL) beside other such
    work. Without ``parallel``, or on a single core (:func:`workers`: a thread would only
    compete), the task runs at once on the calling thread, before the block, as a serial
    program would run it. Otherwise on a daemon thread that never outlives the block (it is
    joined when the block is left, however) and never prints: its error is raised on the
    caller, and wins over an error of the block's, which a serial run would not have reached.
    """
    if not parallel or workers() < 2:
        done = task()
        yield lambda: done
        return
    got: list[T] = []
    failed: list[BaseException] = []

    def run() -> None:
        try:
            got.append(task())
        except BaseException as err:  # raised on the caller (the thread's hook would print it)
            failed.append(err)

    thread = threading.Thread(target=run, daemon=True, name="ertools-alongside")
    thread.start()

    def outcome() -> T:
        thread.join()
        if failed:
            raise failed[0]
        return got[0]

    try:
        yield outcome
    except Exception as err:
        thread.join()
        if failed and failed[0] is not err:
            raise failed[0] from None
        raise
    finally:
        thread.join()
