"""YAML floats: 9 decimal places, no binary noise, never more than 5e-10 from the float."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
import yaml
from hypothesis import given
from hypothesis import strategies as st

from ertools.cli.main import main
from ertools.serialize import dump_yaml

ROOT = Path(__file__).resolve().parents[2]
FBM2H = ROOT / "sample_bags" / "fbm2h"


def test_binary_noise_is_gone_and_epoch_times_keep_every_bit() -> None:
    # the sample's five segment times summed as float seconds (the old execution_time)
    noisy = 7.4 + 8.6 + 7.0 + 9.3 + 8.9
    assert repr(noisy) == "41.199999999999996"
    epoch = 1_448_020_810_103_000_200 / 1e9  # a record time: float64 holds 0.24 us here
    text = dump_yaml({"t": noisy, "e": epoch, "n": np.float64(0.1) + np.float64(0.2)})
    assert text == f"t: 41.2\ne: {epoch!r}\nn: 0.3\n"
    assert yaml.safe_load(text)["e"] == epoch  # unchanged to the last bit
    # an error of 0.1 um survives with two more digits: 9 decimals are nanometres
    assert dump_yaml([1.234567891234e-4, -0.43000000000000016]) == "- 0.000123457\n- -0.43\n"
    special = yaml.safe_load(dump_yaml([math.nan, math.inf, -math.inf, 3, True, None]))
    assert math.isnan(special[0]) and special[1:] == [math.inf, -math.inf, 3, True, None]


@pytest.mark.slow
@given(st.floats(min_value=-1e6, max_value=1e6, allow_nan=False))
def test_written_value_within_half_a_nano(x: float) -> None:
    back = yaml.safe_load(dump_yaml({"x": x}))["x"]
    # rounding to 1e-9 moves a value by <= 5e-10; the float of that decimal adds <= 1 ulp
    assert abs(back - x) <= 5e-10 + math.ulp(x)


def test_fbm2h_execution_time_summed_in_ns(capsys: pytest.CaptureFixture[str]) -> None:
    bag = FBM2H / "log_fbm2h_mocap_2015-11-20-12-00-00_0.bag"
    answers = yaml.safe_load(bag.with_suffix(".answers.yaml").read_text(encoding="utf-8"))
    # segment ends and starts are whole 100 ms steps in the sample (10 Hz state times)
    ns = sum(round(s["end"] * 10) - round(s["start"] * 10) for s in answers["expected"]["segments"])
    expected = ns / 10  # tenths of a second, exact in decimal
    argv = ["score", "fbm2h", str(bag), "--goal", str(FBM2H / "fbm2h_goal.yaml")]
    assert main([*argv, "--transform", str(FBM2H / "transform-simbot.yaml")]) == 0
    out = capsys.readouterr().out
    assert f"\nexecution_time: {expected!r}\n" in out
    assert expected == 41.2
    assert main([*argv, "--format", "json"]) == 0
    assert '"execution_time": 41.2,' in capsys.readouterr().out  # from int64 ns in JSON too
