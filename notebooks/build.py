"""Write the audit notebooks of this folder from the cell sources below.

    python notebooks/build.py          # rewrites notebooks/*.ipynb (no outputs)
    python notebooks/build.py --check  # exit 1 if a committed notebook differs from this file

The notebooks call the ertools library only; every number they show comes from it. They read
``sample_bags/`` (``make samples``) or the folder named by the environment variable
``ERTOOLS_SAMPLES``. Cell ids are fixed so that a rebuild is byte-identical.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path
from typing import Any

HERE = Path(__file__).resolve().parent

SETUP = """\
import os
from pathlib import Path

import matplotlib.pyplot as plt
import pandas as pd
import yaml

pd.set_option("display.width", 160)
pd.set_option("display.max_columns", 30)
# The sample logs: `make samples` writes sample_bags/; ERTOOLS_SAMPLES points elsewhere.
SAMPLES = Path(os.environ.get("ERTOOLS_SAMPLES", "../sample_bags")).resolve()
FOLDER = SAMPLES / "{scenario}"
assert FOLDER.is_dir(), f"{{FOLDER}} is missing: run `make samples` first"
# What the sample generator says a correct scorer must find (none for your own logs).
answers = sorted(FOLDER.glob("*.answers.yaml"))
ANSWERS = yaml.safe_load(answers[0].read_text()) if answers else {{}}"""

FIGURES = """\
from ertools.report.figures import figure_specs

for spec in figure_specs(result):
    fig, ax = plt.subplots(figsize=spec.size, layout="constrained")
    spec.draw(ax)
    ax.set_title(spec.title)
plt.show()"""

TIMELINE = """\
from ertools.report.plots_audit import draw_timeline

fig, ax = plt.subplots(figsize=(12, 4), layout="constrained")
draw_timeline(ax, audit)
plt.show()"""

COMPARISON = """\
comparison = pd.DataFrame(audit.comparison.rows())
print("\\n".join(audit.comparison.notes))
comparison[comparison.status != "only recomputed"]"""

NOTEBOOKS: dict[str, list[tuple[str, str]]] = {
    "fbm3w": [
        (
            "md",
            "# FBM3@Work (trajectory following): audit a benchmark log\n\n"
            "Load a log, reconstruct the benchmark from its state topics, recompute the score "
            "(seed 7.3, Eq. 1 with the d_min subsampling), plot the runs, compare with the score "
            "the 2015 node sent live, and see how the score depends on d_min.",
        ),
        ("code", SETUP.format(scenario="fbm3w")),
        (
            "code",
            "from ertools.io import summary\n\n"
            'bag = next(FOLDER.glob("*.bag"))\n'
            "s = summary(bag)\n"
            "pd.DataFrame([(t.name, t.msgtype, t.count) for t in s.topics], "
            'columns=["topic", "type", "messages"])',
        ),
        ("md", "## What happened: the state machines' timeline"),
        (
            "code",
            "from ertools.audit_score import audit_bag\n\n"
            "audit, notes = audit_bag([bag])\n"
            "print(*notes, sep='\\n')\n"
            "print(audit.to_text()[:2500])",
        ),
        ("code", TIMELINE),
        ("md", "## The recomputed score, run by run"),
        (
            "code",
            "from ertools.report.frames import result_to_dataframes\n\n"
            "result = audit.recomputed\n"
            "frames = result_to_dataframes(result)\n"
            "print(result.to_yaml()[:400])\n"
            'frames["runs"]',
        ),
        ("code", FIGURES),
        (
            "md",
            "## Live score vs recomputed score\n\nEach difference comes with its explanation "
            "(d_min, pose source, run windows...).",
        ),
        ("code", COMPARISON),
        (
            "md",
            "## How the score depends on d_min\n\n2015 hard-coded d_min = 0.33 mm; below the "
            "mocap noise the path length (and so the error) picks up jitter.",
        ),
        (
            "code",
            "from ertools.benchmarks.fbm3w import Fbm3wOptions, score_fbm3w\n"
            "from ertools.configs.fbm3w import load_fbm3w_config\n\n"
            "config = load_fbm3w_config(None)\n"
            "rows = []\n"
            "for d_min in (0.00033, 0.0005, 0.001, 0.002, 0.004):\n"
            "    r = score_fbm3w([bag], config, Fbm3wOptions(d_min=d_min)).to_dict()\n"
            "    row = {'d_min': d_min, 'best_distance_error': r['best_distance_error']}\n"
            "    row.update({f'run {k}': v.get('distance_error') "
            "for k, v in r['runs_details'].items()})\n"
            "    rows.append(row)\n"
            "sweep = pd.DataFrame(rows).set_index('d_min')\n"
            "truth = {f'run {k}': v['distance_error'] "
            "for k, v in ANSWERS['expected']['runs_details'].items()}\n"
            "sweep.loc['generator truth'] = pd.Series(truth)\n"
            "sweep",
        ),
        (
            "code",
            "ax = sweep.drop(index='generator truth').drop(columns='best_distance_error')"
            ".plot(marker='o', logx=True, figsize=(8, 4))\n"
            "ax.set_ylabel('distance_error [m]')\n"
            "plt.show()",
        ),
    ],
    "fbm2h": [
        (
            "md",
            "# FBM2@Home (navigation): audit a benchmark log\n\n"
            "Reconstruct the segments from the state topics, recompute the waypoint errors "
            "(seed 7.2, Listing 13), plot them, compare with the live score, and see how the "
            "choice of reached moments and the orientation wrap change the result.",
        ),
        ("code", SETUP.format(scenario="fbm2h")),
        (
            "code",
            "from ertools.audit_score import ScoreInputs, audit_bag\n\n"
            'bag = next(FOLDER.glob("*.bag"))\n'
            "params = ANSWERS['generator']['parameters']\n"
            "goal, transform = FOLDER / params['goal'], FOLDER / params['transform']\n"
            "audit, notes = audit_bag([bag], inputs=ScoreInputs(goal=goal, transform=transform))\n"
            "print(*notes, sep='\\n')\n"
            "print(audit.to_text()[:2000])",
        ),
        ("code", TIMELINE),
        ("md", "## The recomputed segments"),
        (
            "code",
            "from ertools.report.frames import result_to_dataframes\n\n"
            "result = audit.recomputed\n"
            'result_to_dataframes(result)["segments"]',
        ),
        ("code", FIGURES),
        ("md", "## Live score vs recomputed score"),
        ("code", "print(audit.live_score_text)\n" + COMPARISON),
        (
            "md",
            "## When was each waypoint reached? And the orientation wrap\n\n"
            "`states`: the Client's COMPLETED_GOAL; `timing`: the reached-waypoint timing file; "
            "`auto`: stops detected in the ground truth. `orientation_2015` reproduces the "
            "unwrapped 2015 formula.",
        ),
        (
            "code",
            "from ertools.benchmarks.fbm2h import Fbm2hOptions, score_fbm2h\n\n"
            "rows = []\n"
            "for reached, timing in (('states', None), "
            "('timing', FOLDER / params['timing']), ('auto', None)):\n"
            "    for wrap_2015 in (False, True):\n"
            "        options = Fbm2hOptions(goal=goal, transform=transform, reached=reached,\n"
            "                               timing=timing, orientation_2015=wrap_2015)\n"
            "        r = score_fbm2h([bag], options).to_dict()\n"
            "        rows.append({'reached': reached, 'orientation_2015': wrap_2015,\n"
            "                     'position_accuracy': r['position_accuracy'],\n"
            "                     'orientation_accuracy': r['orientation_accuracy'],\n"
            "                     'execution_time': r['execution_time']})\n"
            "choices = pd.DataFrame(rows)\n"
            "expected = ANSWERS['expected']\n"
            "print('generator truth:', expected['position_accuracy'], "
            "expected['orientation_accuracy'], expected['orientation_accuracy_2015'])\n"
            "choices",
        ),
    ],
    "fbm1h": [
        (
            "md",
            "# FBM1@Home (object perception): audit a benchmark log\n\n"
            "Find the runs (which item, the robot's answer) in the state topics, recompute the "
            "ground truth and the score (seed 7.1), compare with the live score, and check "
            "that the 2015 rules reproduce it.",
        ),
        ("code", SETUP.format(scenario="fbm1h")),
        (
            "code",
            "from ertools.audit_score import ScoreInputs, audit_bag\n\n"
            'bag = next(FOLDER.glob("*.bag"))\n'
            'items = next(FOLDER.glob("fbm1h*.yaml"))\n'
            "audit, notes = audit_bag([bag], inputs=ScoreInputs(items=items))\n"
            "print(*notes, sep='\\n')\n"
            "pd.DataFrame(audit.tables()['runs'])"
            "[['run', 'start', 'duration', 'outcome', 'manual_operation', 'result']]",
        ),
        ("code", TIMELINE),
        ("md", "## The recomputed runs"),
        (
            "code",
            "from ertools.report.frames import result_to_dataframes\n\n"
            "result = audit.recomputed\n"
            "frames = result_to_dataframes(result)\n"
            "print(list(frames))\n"
            "frames[next(iter(frames))]",
        ),
        ("code", FIGURES),
        ("md", "## Live score vs recomputed score"),
        ("code", COMPARISON),
        (
            "md",
            "## The 2015 rules reproduce the live score\n\n"
            "`Fbm1Options.as_2015` applies every quirk of the 2015 node; compared with the live "
            "score, nothing should differ.",
        ),
        (
            "code",
            "from ertools.audit_score import compare_scores\n"
            "from ertools.benchmarks.fbm1 import Fbm1Options, score_fbm1_bag\n\n"
            "as_2015 = score_fbm1_bag([bag], items, options=Fbm1Options.as_2015('fbm1h'))\n"
            "# Mocap noise moves a recomputed pose score by ~1e-5: compare within the\n"
            "# tolerance the sample's answers state for it.\n"
            "tol = ANSWERS['tolerance']['pose_score']['abs']\n"
            "check = compare_scores(audit.live_score, as_2015, abs_tol=tol)\n"
            "print(f'{check.same} same, {len(check.differences)} differ')\n"
            "pd.DataFrame(check.rows()).query(\"status != 'only recomputed'\")",
        ),
    ],
    "trajectory": [
        (
            "md",
            "# Robot log vs ground truth\n\n"
            "Compare the pose a robot logged for its marker set with the mocap ground truth, "
            "try the three association choices, and look at the clock-offset audit. This "
            "benchmark was offline in 2015: there is no live score to compare with.",
        ),
        ("code", SETUP.format(scenario="robotlog")),
        (
            "code",
            "from ertools.benchmarks.trajectory import TrajectoryConfig, score\n\n"
            "params = ANSWERS['generator']['parameters']\n"
            "robot_bag = next(FOLDER.glob('FBM2H_*.bag'))\n"
            "kwargs = dict(robot_topic=params['robot_topic'], gt_topic=params['gt_topic'])\n"
            "result = score(robot_bag, [FOLDER], TrajectoryConfig(), **kwargs)\n"
            "print(result.to_yaml()[:800])",
        ),
        ("md", "## Association: hold (2015), nearest, linear"),
        (
            "code",
            "rows = []\n"
            "for association in ('hold', 'nearest', 'linear'):\n"
            "    d = score(robot_bag, [FOLDER], TrajectoryConfig(association=association), "
            "**kwargs).to_dict()\n"
            "    rows.append({k: d[k] for k in ('association', 'position_error', "
            "'orientation_error', 'rmse', 'compared', 'gaps', 'tracking_lost')})\n"
            "pd.DataFrame(rows).set_index('association')",
        ),
        ("md", "## The clock audit\n\nThe robot's clock was set ahead of the GT logger's."),
        (
            "code",
            "audited = score(robot_bag, [FOLDER], "
            "TrajectoryConfig(auto_offset=True, apply_offset=True), **kwargs)\n"
            "print('estimated:', audited.to_dict()['clock_audit'])\n"
            "print('generator truth offset [s]:', ANSWERS['truth']['offset_s'])\n"
            "print('position error with the estimate applied:', "
            "audited.to_dict()['position_error'])",
        ),
        ("md", "## Per-pose errors as a DataFrame (UTC time index)"),
        (
            "code",
            "from ertools.report.frames import result_to_dataframes\n\n"
            "samples = result_to_dataframes(audited)['samples']\n"
            "numeric = samples.select_dtypes('number')\n"
            "numeric.describe().T",
        ),
        ("code", FIGURES.replace("result)", "audited)")),
    ],
    "timeline": [
        (
            "md",
            "# A competition folder: timeline and audits\n\n"
            "Order every bag of a folder by time (which logger, which session, which GT files "
            "cover which benchmark), then audit every benchmark log found there.",
        ),
        ("code", SETUP.format(scenario="timeline")),
        (
            "code",
            "from ertools.timeline_scan import scan\n\n"
            "timeline = scan([FOLDER / 'bags'])\n"
            "bags = pd.DataFrame(timeline.to_dict()['bags'])\n"
            "bags['path'] = bags['path'].map(lambda p: str(Path(p).relative_to(FOLDER)))\n"
            "bags[['path', 'kind', 'start', 'duration', 'problems']]",
        ),
        (
            "code",
            "from ertools.report.plots_timeline import draw_gantt\n\n"
            "fig, ax = plt.subplots(figsize=(12, 4), layout='constrained')\n"
            "draw_gantt(ax, timeline)  # the whole folder on one time axis\n"
            "plt.show()",
        ),
        (
            "code",
            "from ertools.report.plots_timeline import timeline_figure\n\n"
            "# one panel per session (its own time axis), problems numbered and listed\n"
            "# (`ertools timeline FOLDER --plot day.html` writes the zoomable page)\n"
            "timeline_figure(timeline)",
        ),
        ("code", "pd.DataFrame(timeline.to_dict()['problems'])"),
        ("md", "## Every benchmark log of the folder, audited"),
        (
            "code",
            "from ertools.audit_score import audit_bag\n\n"
            "rows = []\n"
            "for b in timeline.bags:\n"
            "    if b.kind != 'benchmark' or not b.readable:\n"
            "        continue\n"
            "    audit, _ = audit_bag([Path(b.path)], recompute=False)\n"
            "    rows.append({'bag': Path(b.path).name, 'benchmark': audit.benchmark,\n"
            "                 'runs': len(audit.runs),\n"
            "                 'illegal transitions': len(audit.illegal_transitions),\n"
            "                 'silences': len(audit.silences),\n"
            "                 'ended by': ', '.join(e.reason for e in audit.early_ends),\n"
            "                 'live score': audit.live_score})\n"
            "pd.DataFrame(rows)",
        ),
        (
            "code",
            "from ertools.report.plots_audit import draw_timeline\n\n"
            "if rows:\n"
            "    last = next(b for b in reversed(timeline.bags) if b.kind == 'benchmark' "
            "and b.readable)\n"
            "    audit, _ = audit_bag([Path(last.path)], recompute=False)\n"
            "    fig, ax = plt.subplots(figsize=(12, 4), layout='constrained')\n"
            "    draw_timeline(ax, audit)\n"
            "    plt.show()",
        ),
    ],
}


def build_notebook(cells: list[tuple[str, str]]) -> Any:
    """A notebook (nbformat v4, no outputs) from (kind, source) pairs, with fixed cell ids."""
    import nbformat

    nb = nbformat.v4.new_notebook()
    nb.metadata = {
        "kernelspec": {"display_name": "Python 3", "language": "python", "name": "python3"},
        "language_info": {"name": "python"},
    }
    for i, (kind, source) in enumerate(cells):
        if kind == "md":
            cell = nbformat.v4.new_markdown_cell(source)
        else:
            cell = nbformat.v4.new_code_cell(source)
        cell["id"] = f"cell-{i:02d}"
        nb.cells.append(cell)
    return nb


def render(name: str) -> str:
    import nbformat

    return str(nbformat.writes(build_notebook(NOTEBOOKS[name]))) + "\n"


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--check", action="store_true", help="compare, do not write")
    parser.add_argument("--out", type=Path, default=HERE, help="folder (default: notebooks/)")
    args = parser.parse_args(argv)
    stale = []
    for name in NOTEBOOKS:
        path = args.out / f"{name}.ipynb"
        text = render(name)
        if args.check:
            if not path.exists() or path.read_text(encoding="utf-8") != text:
                stale.append(path.name)
        else:
            path.write_text(text, encoding="utf-8")
            print(path)
    if stale:
        print("out of date, run python notebooks/build.py:", *stale, file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
