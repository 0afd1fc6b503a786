"""The simulated FBM3@Work sample, generated once per session (noisy and noiseless)."""

from __future__ import annotations

import pytest

from tests.benchmarks.fbm3w.fbm3w_kit import Sample, generate_sample


@pytest.fixture(scope="session")
def fbm3w_sample(tmp_path_factory: pytest.TempPathFactory) -> Sample:
    return generate_sample(tmp_path_factory.mktemp("fbm3w_sample"), 2015)


@pytest.fixture(scope="session")
def fbm3w_noiseless(tmp_path_factory: pytest.TempPathFactory) -> Sample:
    """The same benchmark with sigma = 0: the bag holds the truth (plus one tracking loss)."""
    return generate_sample(tmp_path_factory.mktemp("fbm3w_noiseless"), 2015, sigma=0.0)
