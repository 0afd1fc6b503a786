"""Transform and goal files of later ERL seasons (issue 26) give the 2015 layout's FBM2H score.

The ERL 2016-19 RSBB acquirer wrote ``yaml.dump({... 'markerset_to_robot_transform':
tf_listener.lookupTransform(...)})``: tf's (translation, rotation) tuple dumped by PyYAML as
``!!python/tuple``. The files here are written the same way, by PyYAML's own dumper from the
numbers of the sample's Listing 11 file, so the test does not depend on ertools' reading of
the layout it checks. A rosparam ``pose:`` dump carries the same transform as a Pose.
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import pytest
import yaml

from ertools.cli.main import main
from ertools.configs.items import load_items
from ertools.errors import ConfigError


def _score(capsys: pytest.CaptureFixture[str], sample: Any, transform: Path, *extra: str) -> Any:
    """The JSON score, and the text output (stdout and stderr) of the same command."""
    argv = ["score", "fbm2h", str(sample.bag), "--transform", str(transform), *extra]
    assert main([*argv, "--format", "json"]) == 0
    out = capsys.readouterr()
    assert main(argv) == 0
    text = capsys.readouterr()
    return json.loads(out.out), text.out + text.err


def _listing_11(sample: Any) -> dict[str, Any]:
    data: dict[str, Any] = yaml.safe_load(sample.transform.read_text())
    return data


def _same_score(a: dict[str, Any], b: dict[str, Any]) -> None:
    for key in ("position_accuracy", "orientation_accuracy", "execution_time"):
        assert a[key] == b[key], key
    assert a["details"] == b["details"]


@pytest.mark.slow
def test_erl_rsbb_transform(
    fbm2h_sample: Any, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    seed = _listing_11(fbm2h_sample)
    (t, q), (ti, qi) = seed["marker_to_robot_transform"], seed["robot_to_marker_transform"]
    erl = {
        "team_name": seed["robot_info"],
        "transform_timestamp": "2016-11-20_12:00:00_CET(+0100)",
        "markerset_to_robot_transform": (tuple(t), tuple(q)),
        "robot_to_markerset_transform": (list(ti), list(qi)),
    }
    path = tmp_path / "transform-erl.yaml"
    path.write_text(yaml.dump(erl))  # PyYAML's full dumper, as the RSBB acquirer used it
    assert "!!python/tuple" in path.read_text()
    want, _ = _score(capsys, fbm2h_sample, fbm2h_sample.transform)
    got, err = _score(capsys, fbm2h_sample, path)
    _same_score(want, got)
    assert "erl-rsbb layout" in err


@pytest.mark.slow
def test_pose_dump_transform(
    fbm2h_sample: Any, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    seed = _listing_11(fbm2h_sample)
    t, q = seed["marker_to_robot_transform"]
    dump = {
        "pose": {
            "position": dict(zip("xyz", t, strict=True)),
            "orientation": dict(zip("xyzw", q, strict=True)),
        }
    }
    path = tmp_path / "transform-homer.yaml"
    path.write_text(yaml.safe_dump(dump))
    want, _ = _score(capsys, fbm2h_sample, fbm2h_sample.transform)
    got, err = _score(capsys, fbm2h_sample, path)
    _same_score(want, got)
    assert "pose-dump layout" in err


def test_python_objects_are_never_built(
    fbm2h_sample: Any, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """Only the tuple tag is read (as a list): any other Python tag is refused, unrun."""
    marker = tmp_path / "ran"
    path = tmp_path / "transform-evil.yaml"
    path.write_text(
        "markerset_to_robot_transform: !!python/tuple [[0, 0, 0], [0, 0, 0, 1]]\n"
        f"team_name: !!python/object/apply:os.system ['touch {marker}']\n"
    )
    argv = ["score", "fbm2h", str(fbm2h_sample.bag), "--transform", str(path)]
    assert main(argv) == 1
    err = capsys.readouterr().err
    assert "could not determine a constructor" in err and "Traceback" not in err
    assert not marker.exists()


@pytest.mark.slow
def test_erl_rsbb_goal_config(
    fbm2h_sample: Any, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """The RSBB's benchmark_configs/HNF.yaml layout: the same waypoints, the same score."""
    seed = yaml.safe_load(fbm2h_sample.goal.read_text())
    goal = seed.get("goal", seed)
    hnf = {
        "starting_pose": goal["starting_pose"],
        "waypoints": goal["waypoints"],
        "goal_timeout": 120.0,
    }
    path = tmp_path / "HNF.yaml"
    path.write_text(yaml.safe_dump(hnf))
    t = str(fbm2h_sample.transform)
    want, _ = _score(capsys, fbm2h_sample, Path(t), "--goal", str(fbm2h_sample.goal))
    got, err = _score(capsys, fbm2h_sample, Path(t), "--goal", str(path))
    _same_score(want, got)
    assert "erl-rsbb" in json.dumps(got) + err


def test_erl_rsbb_items_list_reads_as_a_vanilla_list(tmp_path: Path) -> None:
    """The RSBB's objects_informations/items_list.yaml (id, class, instance, description):
    the items named, no poses yet (what `ertools acquire items` fills in)."""

    path = tmp_path / "items_list.yaml"
    path.write_text(
        '\nitems:\n- class: a\n  id: 1\n  instance: a1\n  description: "Grey mug"\n  \n'
        '- class: b\n  id: 5\n  instance: b1\n  description: "Knife"\n'
    )
    items = load_items(path, require_transforms=False)
    assert [(i.id, i.item_class, i.instance) for i in items.items] == [
        (1, "a", "a1"),
        (5, "b", "b1"),
    ]
    assert items.is_vanilla
    with pytest.raises(ConfigError, match="acquire items"):
        load_items(path)
