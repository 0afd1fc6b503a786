"""The progress bar (ertools.progress): drawn only on a terminal, after a delay, throttled,
cleared without a trace; and the reporter scope the command line opens."""

from __future__ import annotations

import io

import pytest

from ertools.progress import Bar, clear_current, current, fit, reporting


class Tty(io.StringIO):
    def isatty(self) -> bool:
        return True


class Clock:
    """A clock the test moves by hand."""

    def __init__(self) -> None:
        self.t = 0.0

    def __call__(self) -> float:
        return self.t


def test_bar_line_shows_fraction_amounts_and_rate() -> None:
    clock, out = Clock(), Tty()
    bar = Bar(out, delay_s=0.5, clock=clock)
    bar.task("reading x.bag", 2_000_000, "B")
    clock.t = 1.0
    bar.advance(500_000)
    # a quarter of 24 cells; 0.5 MB read in the 1 s since the task began
    assert out.getvalue().endswith(
        "\rertools: reading x.bag [######------------------] 500.0 kB/2.0 MB  500.0 kB/s\x1b[K"
    )
    clock.t = 2.0
    bar.advance(1_500_000)  # done: 24 cells, 2 MB in 2 s
    assert out.getvalue().endswith("[" + "#" * 24 + "] 2.0 MB/2.0 MB  1.0 MB/s\x1b[K")
    bar.task("scoring runs", 3, "runs")
    bar.advance(1)
    assert out.getvalue().endswith("[########----------------] 1/3 runs\x1b[K")
    bar.close()
    assert out.getvalue().endswith("\r\x1b[K")  # the line is wiped
    bar.advance(1)  # nothing after close
    assert out.getvalue().endswith("\r\x1b[K")


def test_counted_work_says_how_long_is_left_at_its_pace() -> None:
    """A season's executions: after 5 s, the time left at the pace so far (90 executions in
    56 s: 200 more take 124 s), rounded as an estimate deserves; none once done."""
    clock, out = Clock(), Tty()
    bar = Bar(out, delay_s=0.0, clock=clock, columns=120)
    bar.task("scoring", 300, "executions")
    clock.t = 4.0
    bar.advance(10)
    assert out.getvalue().endswith("] 10/300 executions\x1b[K")  # too early to say
    clock.t = 60.0
    bar.advance(90)
    assert out.getvalue().endswith("] 100/300 executions  ~2 min left\x1b[K")
    clock.t = 120.0
    bar.advance(190)  # 280 in 116 s: 10 more take 4.1 s
    assert out.getvalue().endswith("] 290/300 executions  ~4 s left\x1b[K")
    bar.advance(10)
    assert out.getvalue().endswith("] 300/300 executions\x1b[K")
    bar.task("scoring", 3000, "executions")
    bar.advance(0)
    clock.t += 600.0
    bar.advance(600)  # 2,400 more at one a second
    assert out.getvalue().endswith("  ~40 min left\x1b[K")
    bar.task("scoring", 7600, "executions")
    bar.advance(0)
    clock.t += 600.0
    bar.advance(600)  # 7,000 more at one a second
    assert out.getvalue().endswith("  ~1 h 57 min left\x1b[K")


def test_the_pace_leaves_out_what_was_done_before_and_survives_a_new_label() -> None:
    """A rerun finds 200 of 300 executions in the cache at once: the pace is that of the
    executions scored since (10 in 10 s: 90 more take 90 s), also once the label changes."""
    clock, out = Clock(), Tty()
    bar = Bar(out, delay_s=0.0, clock=clock, columns=120)
    bar.task("rescoring", 300, "executions")
    bar.advance(200)
    clock.t = 10.0
    bar.task("rescoring (1 not scored)", 300, "executions")  # as rescore says it
    bar.advance(210)
    assert out.getvalue().endswith(
        "(1 not scored) [################--------] 210/300 executions  ~2 min left\x1b[K"
    )
    bar.task("reading x.bag", 300, "B")  # bytes of the same size: a new task
    clock.t = 11.0
    bar.advance(150)
    assert out.getvalue().endswith("] 150 B/300 B  150 B/s\x1b[K")


def test_bar_silent_before_its_delay_and_off_a_terminal() -> None:
    clock = Clock()
    quick = Tty()
    bar = Bar(quick, delay_s=0.75, clock=clock)
    bar.task("reading", 100, "B")
    clock.t = 0.7
    bar.advance(100)
    bar.close()
    assert quick.getvalue() == ""  # done within the delay: nothing at all
    pipe = io.StringIO()
    bar = Bar(pipe, delay_s=0.0, clock=clock)
    bar.task("reading", 100, "B")
    clock.t = 5.0
    bar.advance(50)
    bar.close()
    assert pipe.getvalue() == ""


def test_bar_redraws_at_most_every_interval() -> None:
    clock, out = Clock(), Tty()
    bar = Bar(out, delay_s=0.0, interval_s=0.1, clock=clock)
    bar.task("reading", 1000, "B")  # one draw
    for i in range(99):  # 99 advances within 0.099 s: none due, none complete
        clock.t = 0.001 * (i + 1)
        bar.advance(1)
    assert out.getvalue().count("\r") == 1
    clock.t = 0.2
    bar.advance(1)  # due again
    assert out.getvalue().count("\r") == 2
    bar.advance(900)  # complete: always drawn, whatever the interval
    assert out.getvalue().count("\r") == 3


def test_clear_then_redraw_after_a_note() -> None:
    clock, out = Clock(), Tty()
    bar = Bar(out, delay_s=0.0, clock=clock)
    with reporting(bar):
        bar.task("reading", 10, "B")
        clear_current()
        assert out.getvalue().endswith("\r\x1b[K")
        out.write("ertools: warning: something\n")
        bar.advance(1)  # back on the fresh line, though within the interval
    assert out.getvalue().endswith("\x1b[K") and "something\n\rertools: reading [" in out.getvalue()


def test_reporting_scope_is_restored_even_on_error() -> None:
    assert current() is None
    bar = Bar(io.StringIO())
    with pytest.raises(RuntimeError), reporting(bar):
        assert current() is bar
        with reporting(None):
            assert current() is None
        assert current() is bar
        raise RuntimeError
    assert current() is None


def test_long_lines_are_cut_to_the_terminal_width() -> None:
    """A line as wide as the terminal wraps, and each redraw would leave a row behind."""
    clock, out = Clock(), Tty()
    bar = Bar(out, delay_s=0.0, clock=clock, columns=60)
    label = "reading /fbm3w/robot_at_work/pose2d from log_fbm3w_mocap_2015-11-20-12-00-00_0.bag"
    bar.task(label, 1000, "B")
    (drawn,) = [s.removesuffix("\x1b[K") for s in out.getvalue().split("\r") if s]
    # too long with the 24-cell bar: 10 cells; then 59 - 9 ("ertools: ") - 2 (" [") - 22
    # ("----------] 0 B/1.0 kB") - 3 ("...") = 23 characters of the label: 11 + 12
    assert len(drawn) == 59
    assert drawn == "ertools: " + label[:11] + "..." + label[-12:] + " [----------] 0 B/1.0 kB"
    assert len(fit("x" * 300, 60)) == 59  # no bar to keep: cut
    assert fit("short", 60) == "short"
