"""Write the audit notebooks of this folder from the cell sources below.

    python notebooks/build.py          # rewrites notebooks/*.ipynb (no outputs)
    python notebooks/build.py --check  # exit 1 if a committed notebook differs from this file

The notebooks call ertools' public API only (``import ertools``, docs/api.md: a test refuses
any other import from ertools); every number they show comes from it. Every input
is in one cell tagged ``parameters`` (papermill's convention: ``papermill -p NAME VALUE``
overrides it in a cell tagged ``injected-parameters`` inserted after it); its defaults are the
sample logs of ``make samples`` (``sample_bags/``, relative to ``notebooks/``). ``answers`` is
the sample generator's truth; it is None for a real log, and the cells that compare with it
then say so and skip. Cell ids are fixed so that a rebuild is byte-identical.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path
from typing import Any

HERE = Path(__file__).resolve().parent
# The folder the parameters' defaults point into, as seen from notebooks/ (the kernel's cwd).
SAMPLES = "../sample_bags"

SETUP = """\
%matplotlib inline
from pathlib import Path

import matplotlib.pyplot as plt
import pandas as pd
import yaml

import ertools

pd.set_option("display.width", 160)
pd.set_option("display.max_columns", 30)"""

PARAMETERS_HEADER = """\
# Parameters: edit them here, or run the notebook with papermill
#   papermill notebooks/NAME.ipynb out.ipynb --cwd notebooks -p NAME VALUE ...
# (`papermill --help-notebook notebooks/NAME.ipynb` lists them; docs/notebooks.md). Relative
# paths are from notebooks/; the defaults are the sample logs of `make samples`.
"""

# Turns the parameters into paths and reads the answers (None: a real log).
LOAD_ANSWERS = """\
# What the sample generator says a correct scorer must find: only samples have it.
ANSWERS = yaml.safe_load(Path(answers).read_text()) if answers else None
if ANSWERS is None:
    print("no answers file (a real log): the comparisons with the generator's truth are skipped")"""

LOAD_BAGS = (
    """\
paths = [Path(bags)] if isinstance(bags, str) else [Path(b) for b in bags]
missing = [str(p) for p in paths if not p.exists()]
assert not missing, f"missing: {missing} (the sample logs: run `make samples`)"
"""
    + LOAD_ANSWERS
)

# The benchmark state topics of the log (none in a ground-truth-only log such as the real 2015
# FBM2@Home test run): the audit, the timeline and the live score need them.
TOPICS = """\
# the 2015 state machines' topics: /<benchmark>/bmbox_state, refbox_state, client_state
STATE_SUFFIXES = ("bmbox_state", "bbbox_state", "refbox_state", "client_state")
summaries = [ertools.info(p) for p in paths]
names = sorted({t.name for s in summaries for t in s.topics})
state_topics = [t for t in names if t.rsplit("/", 1)[-1] in STATE_SUFFIXES]
print("benchmark state topics:", ", ".join(state_topics) or "none")
pd.DataFrame([(t.name, t.msgtype, t.count) for t in summaries[0].topics],
             columns=["topic", "type", "messages"])"""

FIGURES = """\
for fig in ertools.figures(result):
    display(fig)"""

TIMELINE = """\
if audit is not None:
    for fig in ertools.figures(audit):  # the state machines' timeline
        display(fig)"""

COMPARISON = """\
if audit is None:
    print("no live score: the log has no benchmark state topics")
else:
    print(audit.live_score_text)
    comparison = pd.DataFrame(audit.comparison.rows())
    print("\\n".join(audit.comparison.notes))
    display(comparison[comparison.status != "only recomputed"])"""


def parameters(**values: tuple[Any, str]) -> str:
    """The parameters cell: one ``name = literal  # help`` line per input (the line comment is
    the help `papermill --help-notebook` shows)."""
    lines = [f"{name} = {value!r}  # {comment}" for name, (value, comment) in values.items()]
    return PARAMETERS_HEADER + "\n".join(lines)


def sample(path: str) -> str:
    return f"{SAMPLES}/{path}"


FBM2H_LOG = "fbm2h/log_fbm2h_mocap_2015-11-20-12-00-00_0"
FBM3W_LOG = "fbm3w/log_fbm3w_mocap_2015-11-20-12-00-00_0"
FBM1H_LOG = "fbm1h/log_fbm1h_2015-11-20-12-00-00_0"

NOTEBOOKS: dict[str, list[tuple[str, str]]] = {
    "fbm3w": [
        (
            "md",
            "# FBM3@Work (trajectory following): audit a benchmark log\n\n"
            "Load a log, reconstruct the benchmark from its state topics, recompute the score "
            "(seed 7.3, Eq. 1 with the d_min subsampling), plot the runs, compare with the score "
            "the 2015 node sent live, and see how the score depends on d_min. The runs' windows "
            "come from the state topics: a log without them cannot be scored.",
        ),
        ("code", SETUP),
        (
            "params",
            parameters(
                bags=([sample(f"{FBM3W_LOG}.bag")], "the log (a split log: its parts in order)"),
                config=(
                    sample("fbm3w/fbm3w.yaml"),
                    "runs' specifications and d_min (seed Listing 14); None: the seed's",
                ),
                d_mins=([0.00033, 0.0005, 0.001, 0.002, 0.004], "the d_min sweep [m]"),
                answers=(
                    sample(f"{FBM3W_LOG}.answers.yaml"),
                    "the sample generator's truth; None for a real log",
                ),
            ),
        ),
        ("code", LOAD_BAGS + "\nconfig_path = Path(config) if config else None"),
        ("code", TOPICS),
        ("md", "## What happened: the state machines' timeline"),
        (
            "code",
            "audit = ertools.audit(paths, config=config_path)\n"
            "print(*audit.warnings, sep='\\n')\n"
            "print(audit.to_text()[:2500])",
        ),
        ("code", TIMELINE),
        ("md", "## The recomputed score, run by run"),
        (
            "code",
            "result = audit.recomputed\n"
            "frames = result.to_frames()\n"
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
            "mocap noise the path length (and so the error) picks up jitter. On a sample log "
            "the generator's noiseless truth is the last row.",
        ),
        (
            "code",
            "# the sweep compares scores, not their intervals: draws=0 skips the Monte Carlo\n"
            "rows = []\n"
            "for d_min in d_mins:\n"
            "    r = ertools.score('fbm3w', paths, config=config_path, d_min=d_min, draws=0)\n"
            "    r = r.to_dict()\n"
            "    row = {'d_min': d_min, 'best_distance_error': r['best_distance_error']}\n"
            "    row.update({f'run {k}': v.get('distance_error') "
            "for k, v in r['runs_details'].items()})\n"
            "    rows.append(row)\n"
            "sweep = pd.DataFrame(rows).set_index('d_min')\n"
            "if ANSWERS is not None:\n"
            "    truth = {f'run {k}': v['distance_error'] "
            "for k, v in ANSWERS['expected']['runs_details'].items()}\n"
            "    sweep.loc['generator truth'] = pd.Series(truth)\n"
            "sweep",
        ),
        (
            "code",
            "ax = sweep.drop(index='generator truth', errors='ignore')"
            ".drop(columns='best_distance_error').plot(marker='o', logx=True, figsize=(8, 4))\n"
            "ax.set_ylabel('distance_error [m]')\n"
            "plt.show()",
        ),
    ],
    "fbm2h": [
        (
            "md",
            "# FBM2@Home (navigation): audit a benchmark log\n\n"
            "Recompute the waypoint errors (seed 7.2, Listing 13), plot them, compare with the "
            "live score, and see how the choice of reached moments and the orientation wrap "
            "change the result. A log without benchmark state topics (the real 2015 test run "
            "holds only the mocap ground truth) is scored from a reached-waypoint timing file "
            "(`reached = 'timing'`) or from the stops in the ground truth (`'auto'`); it has no "
            "timeline and no live score.",
        ),
        ("code", SETUP),
        (
            "params",
            parameters(
                bags=([sample(f"{FBM2H_LOG}.bag")], "the log (a split log: its parts in order)"),
                goal=(sample("fbm2h/fbm2h_goal.yaml"), "the waypoints (seed Listing 10)"),
                transform=(
                    sample("fbm2h/transform-simbot.yaml"),
                    "marker-to-robot (Listing 12); None: identity",
                ),
                timing=(
                    sample(f"{FBM2H_LOG}_reached_waypoint_timing.yaml"),
                    "reached-waypoint timing file; None: none",
                ),
                reached=("states", "the reached moments: 'states', 'timing' or 'auto'"),
                answers=(
                    sample(f"{FBM2H_LOG}.answers.yaml"),
                    "the sample generator's truth; None for a real log",
                ),
            ),
        ),
        (
            "code",
            LOAD_BAGS + "\n"
            "goal_path = Path(goal)\n"
            "transform_path = Path(transform) if transform else None\n"
            "timing_path = Path(timing) if timing else None",
        ),
        ("code", TOPICS),
        ("md", "## What happened: the state machines' timeline"),
        (
            "code",
            "audit = None\n"
            "if state_topics:\n"
            "    audit = ertools.audit(paths, goal=goal_path, transform=transform_path)\n"
            "    print(*audit.warnings, sep='\\n')\n"
            "    print(audit.to_text()[:2000])\n"
            "else:\n"
            "    print('no benchmark state topics: no timeline and no live score in this log')",
        ),
        ("code", TIMELINE),
        ("md", "## The recomputed segments"),
        (
            "code",
            "def reached_at(source, timing_file):\n"
            "    # `--reached timing FILE`: the mode and its file; the others: the mode alone\n"
            "    return (source, timing_file) if source == 'timing' else source\n\n"
            "result = ertools.score('fbm2h', paths, goal=goal_path, transform=transform_path,\n"
            "                       reached=reached_at(reached, timing_path))\n"
            "score = result.to_dict()\n"
            "print(f'reached moments: {reached}')\n"
            "for key in ('position_accuracy', 'orientation_accuracy', 'execution_time'):\n"
            "    print(f'{key}: {score[key]!r}')\n"
            "print(*result.warnings, *result.deviations, sep='\\n')\n"
            'result.to_frames()["segments"]',
        ),
        ("code", FIGURES),
        ("md", "## Live score vs recomputed score"),
        ("code", COMPARISON),
        (
            "md",
            "## When was each waypoint reached? And the orientation wrap\n\n"
            "`states`: the Client's COMPLETED_GOAL (only in a log with state topics); "
            "`timing`: the reached-waypoint timing file (when given); `auto`: stops detected "
            "in the ground truth. `orientation_2015` reproduces the unwrapped 2015 formula.",
        ),
        (
            "code",
            "sources = [('states', None)] if state_topics else []\n"
            "if timing_path is not None:\n"
            "    sources.append(('timing', timing_path))\n"
            "sources.append(('auto', None))\n"
            "# the choices' scores side by side, without intervals (draws=0: no Monte Carlo)\n"
            "rows = []\n"
            "for source, timing_file in sources:\n"
            "    for wrap_2015 in (False, True):\n"
            "        r = ertools.score('fbm2h', paths, goal=goal_path, transform=transform_path,\n"
            "                          reached=reached_at(source, timing_file),\n"
            "                          orientation_2015=wrap_2015, draws=0).to_dict()\n"
            "        rows.append({'reached': source, 'orientation_2015': wrap_2015,\n"
            "                     'position_accuracy': r['position_accuracy'],\n"
            "                     'orientation_accuracy': r['orientation_accuracy'],\n"
            "                     'execution_time': r['execution_time']})\n"
            "choices = pd.DataFrame(rows)\n"
            "if ANSWERS is not None:\n"
            "    expected = ANSWERS['expected']\n"
            "    print('generator truth:', expected['position_accuracy'], "
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
            "that the 2015 rules reproduce it. The runs come from the state topics: a log "
            "without them cannot be scored.",
        ),
        ("code", SETUP),
        (
            "params",
            parameters(
                bags=([sample(f"{FBM1H_LOG}.bag")], "the log (a split log: its parts in order)"),
                items=(sample("fbm1h/fbm1h.yaml"), "the item list"),
                results=(None, "the robot's results file; None: from the log"),
                abs_tol=(
                    None,
                    "live vs 2015 rules tolerance; None: the answers' pose-score one, or 1e-6",
                ),
                answers=(
                    sample(f"{FBM1H_LOG}.answers.yaml"),
                    "the sample generator's truth; None for a real log",
                ),
            ),
        ),
        (
            "code",
            LOAD_BAGS + "\n"
            "items_path = Path(items)\n"
            "results_path = Path(results) if results else None",
        ),
        (
            "code",
            "audit = ertools.audit(paths, items=items_path, results=results_path)\n"
            "print(*audit.warnings, sep='\\n')\n"
            "pd.DataFrame(audit.tables()['runs'])"
            "[['run', 'start', 'duration', 'outcome', 'manual_operation', 'result']]",
        ),
        ("code", TIMELINE),
        ("md", "## The recomputed runs"),
        (
            "code",
            "result = audit.recomputed\n"
            "frames = result.to_frames()\n"
            "print(list(frames))\n"
            "frames[next(iter(frames))]",
        ),
        ("code", FIGURES),
        ("md", "## Live score vs recomputed score"),
        ("code", COMPARISON),
        (
            "md",
            "## The 2015 rules reproduce the live score\n\n"
            "`rules='2015'` (`--rules 2015`) applies every quirk of the 2015 node; compared with "
            "the live score, nothing should differ.",
        ),
        (
            "code",
            "as_2015 = ertools.audit(paths, items=items_path, results=results_path, rules='2015')\n"
            "# Mocap noise moves a recomputed pose score by ~1e-5: a sample's answers state the\n"
            "# tolerance for it.\n"
            "tol = abs_tol\n"
            "if tol is None:\n"
            "    tol = ANSWERS['tolerance']['pose_score']['abs'] if ANSWERS else 1e-6\n"
            "check = pd.DataFrame(as_2015.comparison.rows())\n"
            "check = check[check.status != 'only recomputed']\n"
            "numbers = check.difference.notna()\n"
            "within = check.difference.abs() <= tol\n"
            "same = numbers & within | ~numbers & (check.status == 'same')\n"
            "print(f'{same.sum()} same, {(~same).sum()} differ (tolerance {tol})')\n"
            "check[~same]",
        ),
    ],
    "trajectory": [
        (
            "md",
            "# Robot log vs ground truth\n\n"
            "Compare the pose a robot logged for its marker set with the mocap ground truth, "
            "try the three association choices, and look at the clock-offset audit. This "
            "benchmark was offline in 2015: there is no live score to compare with. It needs "
            "a robot's own log beside the ground truth.",
        ),
        ("code", SETUP),
        (
            "params",
            parameters(
                robot_bag=(sample("robotlog/FBM2H_201511201200_homer.bag"), "the robot's log"),
                gt=([sample("robotlog")], "the GT bags, or folders of them, that cover it"),
                robot_topic=("/rockin/homer/marker_pose", "the robot's pose topic"),
                gt_topic=("/fbm2h/robot_at_home/pose", "the GT pose topic"),
                answers=(
                    sample("robotlog/FBM2H_201511201200_homer.answers.yaml"),
                    "the sample generator's truth; None for a real log",
                ),
            ),
        ),
        (
            "code",
            "robot_path = Path(robot_bag)\n"
            "gt_paths = [Path(gt)] if isinstance(gt, str) else [Path(g) for g in gt]\n"
            + LOAD_ANSWERS
            + "\n"
            "bags = [robot_path, *gt_paths]\n"
            "kwargs = dict(robot_topic=robot_topic, gt_topic=gt_topic)\n"
            "result = ertools.score('trajectory', bags, **kwargs)\n"
            "print(result.to_yaml()[:800])",
        ),
        ("md", "## Association: hold (2015), nearest, linear"),
        (
            "code",
            "# the three rules' scores side by side, without intervals (draws=0: no Monte Carlo)\n"
            "rows = []\n"
            "for association in ('hold', 'nearest', 'linear'):\n"
            "    r = ertools.score('trajectory', bags, association=association, draws=0, **kwargs)\n"
            "    d = r.to_dict()\n"
            "    rows.append({k: d[k] for k in ('association', 'position_error', "
            "'orientation_error', 'rmse', 'compared', 'gaps', 'tracking_lost')})\n"
            "pd.DataFrame(rows).set_index('association')",
        ),
        ("md", "## The clock audit\n\nThe sample robot's clock was set ahead of the GT logger's."),
        (
            "code",
            "audited = ertools.score('trajectory', bags, offset='auto', apply_offset=True, "
            "**kwargs)\n"
            "print('estimated:', audited.to_dict()['clock_audit'])\n"
            "if ANSWERS is not None:\n"
            "    print('generator truth offset [s]:', ANSWERS['truth']['offset_s'])\n"
            "print('position error with the estimate applied:', "
            "audited.to_dict()['position_error'])",
        ),
        ("md", "## Per-pose errors as a DataFrame (UTC time index)"),
        (
            "code",
            "samples = audited.to_frames()['samples']\n"
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
            "cover which benchmark), then audit every benchmark log found there (a folder of "
            "ground-truth logs only has none).",
        ),
        ("code", SETUP),
        (
            "params",
            parameters(
                folder=(sample("timeline/bags"), "the folder of bags (searched recursively)"),
                answers=(
                    sample("timeline/timeline.answers.yaml"),
                    "the sample generator's truth; None for a real log",
                ),
            ),
        ),
        (
            "code",
            "root = Path(folder)\n"
            "assert root.is_dir(), f'{root}: no such folder (the samples: run `make samples`)'\n"
            + LOAD_ANSWERS
            + "\n"
            "timeline = ertools.timeline(root)\n"
            "bags = pd.DataFrame(timeline.to_dict()['bags'])\n"
            "bags['path'] = bags['path'].map(lambda p: str(Path(p).relative_to(root)))\n"
            "print(f'{len(bags)} bags, {len(timeline.to_dict()[\"sessions\"])} sessions')\n"
            "bags[['path', 'kind', 'start', 'duration', 'problems']]",
        ),
        (
            "code",
            "# the whole folder on one time axis, then one panel per session (its own time\n"
            "# axis), problems numbered and listed\n"
            "# (`ertools timeline FOLDER --plot day.html` writes the zoomable page)\n"
            "for fig in ertools.figures(timeline):\n"
            "    display(fig)",
        ),
        ("code", "pd.DataFrame(timeline.to_dict()['problems'])"),
        (
            "code",
            "if ANSWERS is not None:\n"
            "    # Each bag's kind against the generator's truth.\n"
            "    truth = {p: t['kind'] for p, t in ANSWERS['truth']['bags'].items()}\n"
            "    kinds = bags.set_index('path')['kind']\n"
            "    check = pd.DataFrame({'found': kinds, 'truth': pd.Series(truth)})\n"
            "    print(f'{(check.found == check.truth).sum()} of {len(truth)} kinds as the "
            "generator made them')\n"
            "    display(check)",
        ),
        ("md", "## Every benchmark log of the folder, audited"),
        (
            "code",
            "benchmark_logs = [b for b in timeline.bags if b.kind == 'benchmark' and b.readable]\n"
            "rows = []\n"
            "for b in benchmark_logs:\n"
            "    audit = ertools.audit(b.path, recompute=False)\n"
            "    rows.append({'bag': Path(b.path).name, 'benchmark': audit.benchmark,\n"
            "                 'runs': len(audit.runs),\n"
            "                 'illegal transitions': len(audit.illegal_transitions),\n"
            "                 'silences': len(audit.silences),\n"
            "                 'ended by': ', '.join(e.reason for e in audit.early_ends),\n"
            "                 'live score': audit.live_score})\n"
            "if not rows:\n"
            "    print('no benchmark log (state topics) in this folder: nothing to audit')\n"
            "pd.DataFrame(rows)",
        ),
        (
            "code",
            "if benchmark_logs:\n"
            "    audit = ertools.audit(benchmark_logs[-1].path, recompute=False)\n"
            "    for fig in ertools.figures(audit):\n"
            "        display(fig)",
        ),
    ],
}


def build_notebook(cells: list[tuple[str, str]]) -> Any:
    """A notebook (nbformat v4, no outputs) from (kind, source) pairs, with fixed cell ids.

    Kind ``params`` is the code cell tagged ``parameters`` (papermill's convention).
    """
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
        if kind == "params":
            cell.metadata["tags"] = ["parameters"]
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
