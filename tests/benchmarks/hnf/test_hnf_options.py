"""HNF's options: a rule option that would undo what ``--rules`` reproduces is one
usage error naming every such option; one that agrees with the script is accepted."""

from __future__ import annotations

import pytest

from ertools.benchmarks.hnf import declare as hnf
from ertools.errors import UsageError


def test_hnf_refuses_what_would_undo_the_script() -> None:
    with pytest.raises(
        UsageError,
        match=r"^--rules 2017 reproduces the script: --divisor, --score-format would undo it; "
        r"give one or the other$",
    ):
        hnf.make_options({"rules": "2017", "divisor": "ertools", "score_format": "ertools"})
    # the script's own values restate it, and ertools' reading takes any
    same = hnf.make_options({"rules": "2019", "divisor": "2019", "gt_gaps": "interpolate"})
    assert same.divisor_2019 and same.gaps_interpolate and same.script == "2bb8a41"
    assert not hnf.make_options({"divisor": "ertools", "gt_gaps": "refuse"}).divisor_2019
