"""HPFF's options: a rule option that would undo what ``--rules 2019`` reproduces is one usage
error naming it; one that agrees with the script is accepted."""

from __future__ import annotations

import pytest

from ertools.benchmarks.hpff import declare as hpff
from ertools.errors import UsageError


def test_hpff_refuses_what_would_undo_the_script() -> None:
    with pytest.raises(
        UsageError,
        match=r"^--rules 2019 reproduces the script: --distance-plane would undo it; "
        r"give one or the other$",
    ):
        hpff.make_options({"rules": "2019", "distance_plane": "testbed"})
    same = hpff.make_options({"rules": "2019", "sampling": "script"})
    assert same.sampling_script and same.plane_actor and same.clock_script
