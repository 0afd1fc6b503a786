"""Each benchmark's simulated scenario is reached through the registry (issue 37): the
``sample`` module beside its declaration, once per package, in its ``sample_folder``."""

from __future__ import annotations

import textwrap
from pathlib import Path

import pytest

from ertools.benchmarks import registry

ROOT = Path(__file__).resolve().parents[3]


def test_every_sample_module_is_a_scenario_once() -> None:
    """The packages holding a ``sample.py``, read from the tree, are the scenarios' modules
    and the parts a scenario composes (the referee's, in ``season2019``); each folder is one
    of ``sample_bags/`` (the trajectory's: ``robotlog``)."""
    on_disk = sorted(
        f"ertools.benchmarks.{p.parent.name}.sample"
        for p in (ROOT / "ertools" / "benchmarks").glob("*/sample.py")
        if p.parent.name != "common"
    )
    found = registry.scenarios()
    parts = [m.__name__ for m in registry.sample_parts()]
    assert parts == ["ertools.benchmarks.referee.sample"]
    assert sorted([s.module for s in found] + parts) == on_disk
    folders = [s.folder for s in found]
    assert len(set(folders)) == len(folders)
    assert {"fbm1h", "robotlog"} <= set(folders) and "fbm1w" not in folders
    for folder in folders:
        assert (ROOT / "sample_bags" / folder).is_dir(), folder


def test_a_new_package_brings_its_scenario(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """A package with a declaration, a sample module and one registry line: its scenario is
    found, named by its ``sample_folder``, seeded by its ``sample_seed``, and writes what its
    ``generate`` writes; a package without a sample module has none."""
    package = tmp_path / "pkg" / "simbench"
    package.mkdir(parents=True)
    (package / "__init__.py").write_text("")
    (package / "declare.py").write_text(
        textwrap.dedent(
            """
            class Sim:
                sample_folder = "simfolder"
                sample_seed = 7
                sample_part = False

                def sample_args(self, samples):
                    return None


            BENCHMARK = Sim()
            """
        )
    )
    (package / "sample.py").write_text(
        textwrap.dedent(
            """
            def generate(outdir, *, seed):
                path = outdir / "seed.txt"
                path.write_text(str(seed * 2))
                return [path]
            """
        )
    )
    bare = tmp_path / "pkg" / "bare"
    bare.mkdir()
    (bare / "__init__.py").write_text("")
    (bare / "declare.py").write_text("BENCHMARK = object()\n")
    monkeypatch.syspath_prepend(str(tmp_path / "pkg"))
    lines = (
        registry.Entry("sim", "simbench.declare", "a simulated toy"),
        registry.Entry("bare", "bare.declare", "no simulator"),
    )
    monkeypatch.setattr(registry, "ENTRIES", (*registry.ENTRIES, *lines))
    found = [s for s in registry.scenarios() if not s.module.startswith("ertools.")]
    assert found == [registry.Scenario("simfolder", "simbench.sample", 7)]
    out = tmp_path / "out"
    out.mkdir()
    assert found[0].generate(out, seed=21) == [out / "seed.txt"]
    assert (out / "seed.txt").read_text() == "42"
