# Two entry points on a fresh machine: `make demo` and `make test` (see README).
PYTHON ?= python3
VENV   := .venv
BIN    := $(VENV)/bin
STAMP  := $(VENV)/.installed
DEVSTAMP := $(VENV)/.installed-dev
DEMO_OUT ?= demo_output

.PHONY: demo test check lint typecheck pytest pytest-simd-off bench bench-score calibrate fuzz samples notebooks clean

# pip -qq: errors only. pip 25+ passes on setuptools' notice about every editable install
# (a "BuildBackendWarning: Editable installation" box), which a first `make demo` need not show.
PIP := $(BIN)/python -m pip install -qq

$(BIN)/python:
	$(PYTHON) -m venv $(VENV)
	$(BIN)/python -m pip install --quiet --upgrade pip

# Byte-compiled on install, as a wheel install would be: where PYTHONDONTWRITEBYTECODE is set,
# every command would otherwise compile the package again at start-up.
$(STAMP): pyproject.toml | $(BIN)/python
	$(PIP) -e .
	$(BIN)/python -m compileall -q ertools
	touch $@

$(DEVSTAMP): pyproject.toml | $(BIN)/python
	$(PIP) -e '.[dev,dask]'
	$(BIN)/python -m compileall -q ertools
	touch $@ $(STAMP)

demo: $(STAMP)
	$(BIN)/python -m ertools.demo $(DEMO_OUT)

lint: $(DEVSTAMP)
	$(BIN)/ruff check ertools tests bench fuzz
	$(BIN)/ruff format --check ertools tests bench fuzz
	$(BIN)/lint-imports --no-cache

typecheck: $(DEVSTAMP)
	$(BIN)/mypy ertools

# The suite on every core (pytest-xdist): tests that share a resource or measure time carry an
# xdist_group mark and run on one worker (tests/conftest.py); the 15 slowest are listed.
# pytest keeps its rewritten test modules as bytecode (tests/**/__pycache__, ignored by git):
# where PYTHONDONTWRITEBYTECODE is set it would rewrite all of them in every worker of every
# run (6 s of CPU each here).
PYTEST_JOBS ?= auto
PYTEST := PYTHONDONTWRITEBYTECODE= $(BIN)/python -m pytest
pytest: $(DEVSTAMP)
	$(PYTEST) -q -n $(PYTEST_JOBS) --dist loadgroup --durations=15

# The numeric tests once more on other code paths: every NumPy SIMD target this CPU has off
# (`python -m ertools.samples.simd` lists them: NumPy's baseline code, the C library's maths)
# and OpenBLAS's Nehalem kernels (x86-64-v2; a name other CPUs ignore). A result that depends
# on the CPU's code path then differs from the recording and fails, on an AVX2 machine as on an
# AVX-512 one (docs/qa.md, "Results on every CPU"). Only the tests whose subject is numbers:
# the golden outputs, the sample bags' scores against their answers, the sample competition's
# answers, the samples regenerated against sample_bags/ (~40 s of CPU). The byte-identity test
# of the competition is left out: it already compares a generation with SIMD off.
SIMD_OFF_TESTS := tests/e2e/test_outputs_unchanged.py tests/benchmarks/fbm3w/test_fbm3w_golden.py \
	tests/benchmarks/fbm1/test_fbm1_sample.py tests/benchmarks/fbm2h/test_fbm2h_sample.py \
	tests/benchmarks/fbm3w/test_fbm3w_sample.py tests/benchmarks/trajectory/test_trajectory_sample.py \
	tests/samples/test_competition.py tests/samples/test_samples_scenarios.py
SIMD_OFF_SKIP := tests/samples/test_competition.py::test_two_generations_are_byte_identical
pytest-simd-off: $(DEVSTAMP)
	@targets="$$(env -u NPY_DISABLE_CPU_FEATURES $(BIN)/python -m ertools.samples.simd)"; \
	echo "== the numeric tests again: NPY_DISABLE_CPU_FEATURES=\"$$targets\" OPENBLAS_CORETYPE=Nehalem"; \
	NPY_DISABLE_CPU_FEATURES="$$targets" OPENBLAS_CORETYPE=Nehalem \
		$(PYTEST) -q -n $(PYTEST_JOBS) --dist loadgroup $(SIMD_OFF_TESTS) --deselect $(SIMD_OFF_SKIP)

test: lint typecheck pytest pytest-simd-off

# The edit-test loop: lint and the tests that take under a second (the slow ones are marked
# `slow` on the test: docs/qa.md).
check: $(DEVSTAMP)
	$(BIN)/ruff check ertools tests bench fuzz
	$(BIN)/ruff format --check ertools tests bench fuzz
	$(BIN)/lint-imports --no-cache
	$(PYTEST) -q -n $(PYTEST_JOBS) --dist loadgroup -m "not slow"

bench: $(STAMP)
	$(PIP) -e '.[dask,bench]'  # the season's LocalCluster run; evo, the baseline
	$(BIN)/python -m compileall -q ertools
	$(BIN)/python bench/run.py

# Issue 39's table alone: `score trajectory` against `evo_ape bag`, and the 8-hour GT (~3 min).
bench-score: $(STAMP)
	$(PIP) -e '.[bench]'
	$(BIN)/python -m compileall -q ertools
	$(BIN)/python bench/run.py --score-only

# Do the 95% score intervals cover the truth 95% of the time? 1,000 seeded simulated executions
# per benchmark (bench/calibration/), the table written into docs/uncertainty.md.
# `make calibrate TRIALS=200`; one benchmark: `$(BIN)/python bench/calibrate.py --only fbm3w`.
TRIALS ?= 1000
CAL_JOBS ?= 2
calibrate: $(STAMP)
	$(BIN)/python bench/calibrate.py --trials $(TRIALS) --jobs $(CAL_JOBS)

# JupyterLab in the project's venv, then the notebooks open in it. As root (a container),
# Jupyter refuses to start without --allow-root: given then, with the reason said.
notebooks: $(STAMP)
	$(PIP) -e '.[notebooks]'
	@if [ "$$(id -u)" = 0 ]; then \
		echo "make notebooks: running as root (a container?): jupyter lab --allow-root"; \
		$(BIN)/jupyter lab --allow-root notebooks/; \
	else \
		$(BIN)/jupyter lab notebooks/; \
	fi

# Mutation fuzzing of the ROS1 and MCAP readers against rosbags / mcap (docs/qa.md).
# `make fuzz N=500 SEED=7 JOBS=1`; one case in full: `$(BIN)/python fuzz/run.py --seed S --case K`.
N ?= 10000
SEED ?= 1
JOBS ?= 2
fuzz: $(STAMP)
	$(BIN)/python fuzz/run.py --cases $(N) --seed $(SEED) --jobs $(JOBS)

samples: $(STAMP)
	$(BIN)/python -m ertools.samples sample_bags

clean:
	rm -rf $(VENV) build $(DEMO_OUT) .mypy_cache .ruff_cache .pytest_cache
