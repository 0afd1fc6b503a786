# Two entry points on a fresh machine: `make demo` and `make test` (see README).
PYTHON ?= python3
VENV   := .venv
BIN    := $(VENV)/bin
STAMP  := $(VENV)/.installed
DEVSTAMP := $(VENV)/.installed-dev
DEMO_OUT ?= demo_output

.PHONY: demo test lint typecheck pytest bench fuzz samples notebooks clean

$(BIN)/python:
	$(PYTHON) -m venv $(VENV)
	$(BIN)/python -m pip install --quiet --upgrade pip

# Byte-compiled on install, as a wheel install would be: where PYTHONDONTWRITEBYTECODE is set,
# every command would otherwise compile the package again at start-up.
$(STAMP): pyproject.toml | $(BIN)/python
	$(BIN)/python -m pip install --quiet -e .
	$(BIN)/python -m compileall -q ertools
	touch $@

$(DEVSTAMP): pyproject.toml | $(BIN)/python
	$(BIN)/python -m pip install --quiet -e '.[dev,dask]'
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

pytest: $(DEVSTAMP)
	$(BIN)/python -m pytest -q

test: lint typecheck pytest

bench: $(STAMP)
	$(BIN)/python -m pip install --quiet -e '.[dask]'  # the season's LocalCluster run
	$(BIN)/python -m compileall -q ertools
	$(BIN)/python bench/run.py

# JupyterLab in the project's venv, then the notebooks open in it.
notebooks: $(STAMP)
	$(BIN)/python -m pip install --quiet -e '.[notebooks]'
	$(BIN)/jupyter lab notebooks/

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
