"""Every commit after c569e4b (issue 37's habits) has a subject of 72 characters or fewer, merges
included: the details go in the body. The history before it keeps its long subjects.

In a fresh clone the whole history is there; in a shallow one that stops after c569e4b every
commit it holds is checked, since all of them came after. Outside a git checkout (an
unpacked sdist) there is no history to check.
"""

from __future__ import annotations

import shutil
import subprocess
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
SINCE = "c569e4b"
LIMIT = 72


def git(*args: str, root: Path = ROOT) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        ["git", "-C", str(root), *args], capture_output=True, text=True, check=False
    )


def long_subjects(root: Path = ROOT, since: str = SINCE) -> list[str]:
    """``hash (N chars): subject`` of every commit after ``since`` whose subject is too long
    (every commit of the history when ``since`` is not in it: a shallow clone)."""
    known = git("cat-file", "-e", f"{since}^{{commit}}", root=root).returncode == 0
    log = git("log", "--format=%h%x00%s", *([f"{since}..HEAD"] if known else ["HEAD"]), root=root)
    assert log.returncode == 0, log.stderr
    out = []
    for line in log.stdout.splitlines():
        commit, subject = line.split("\0", 1)
        if len(subject) > LIMIT:
            out.append(f"{commit} ({len(subject)} chars): {subject}")
    return out


def test_subjects_after_issue_37_are_short() -> None:
    if shutil.which("git") is None or git("rev-parse", "--git-dir").returncode != 0:
        pytest.skip("n/a: not a git checkout, no history to check")
    bad = long_subjects()
    assert not bad, "commit subjects over 72 characters (details go in the body):\n" + "\n".join(
        bad
    )


def test_a_long_subject_and_a_long_merge_are_found(tmp_path: Path) -> None:
    if shutil.which("git") is None:
        pytest.skip("n/a: git is not installed")
    env = ["-c", "user.name=t", "-c", "user.email=t@t", "-c", "commit.gpgsign=false"]
    assert git("init", "-q", "-b", "main", root=tmp_path).returncode == 0

    def commit(subject: str) -> None:
        done = git(*env, "commit", "-q", "--allow-empty", "-m", subject, root=tmp_path)
        assert done.returncode == 0, done.stderr

    commit("x" * 200)  # before the tag standing for c569e4b: not checked
    git("tag", "since", root=tmp_path)
    commit("y" * 72)
    commit("z" * 73)
    git("checkout", "-q", "-b", "side", root=tmp_path)
    commit("side")
    git("checkout", "-q", "main", root=tmp_path)
    merge = git(*env, "merge", "-q", "--no-ff", "-m", "m" * 80, "side", root=tmp_path)
    assert merge.returncode == 0, merge.stderr
    found = long_subjects(tmp_path, "since")
    assert [f.split(" ", 1)[1] for f in found] == [
        f"(80 chars): {'m' * 80}",
        f"(73 chars): {'z' * 73}",
    ]
