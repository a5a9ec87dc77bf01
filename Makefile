# Two commands do all the set-up on a fresh machine (Python >= 3.11 and make present):
#   make demo   -> virtual environment + install + default scenario
#   make test   -> virtual environment + install + test suite
PYTHON ?= python3
VENV ?= .venv
PY := $(VENV)/bin/python
STAMP := $(VENV)/.installed
DEMO_OUT ?= results/demo

.PHONY: demo test install warm bench clean

$(STAMP): pyproject.toml
	@echo "install: a virtual environment in $(VENV) with this project (editable) and its dependencies from pyproject.toml (numpy, scipy, numba, pint, xarray, dask, matplotlib, pyvista, pytest ...); a few minutes the first time"
	$(PYTHON) -m venv $(VENV)
	$(PY) -m pip install --quiet --upgrade pip
	$(PY) -m pip install --quiet -e ".[test]"
	@$(PY) -m pip list --format=freeze 2>/dev/null | wc -l | xargs -I{} echo "install: done, {} packages in $(VENV)"
	touch $(STAMP)

install: $(STAMP)

# the engine's kernels compile once per machine (about a minute), in their own step, then load in a second
warm: $(STAMP)
	$(PY) -m scenarios.warm

demo: warm
	$(PY) -m scenarios.demo --out $(DEMO_OUT)

# one pytest worker per core (pytest-xdist); a test file stays on one worker, so its module fixtures run once
test: warm
	$(PY) -m pytest -q -n auto --dist loadfile

bench: $(STAMP)
	$(PY) -m scenarios.bench_engine

clean:
	rm -rf $(VENV) results .pytest_cache .hypothesis
