# Two set-up commands on a fresh machine: `make demo` and `make test`.
PYTHON ?= python3
VENV := .venv
BIN := $(VENV)/bin
STAMP := $(VENV)/.installed
# Compiled kernels go to geardyn's one cache, the same for `make`, `geardyn` and the Python API:
# $GEARDYN_CACHE_DIR (default ~/.cache/geardyn; numba's code in its numba/ unless NUMBA_CACHE_DIR
# is set), see src/geardyn/_cache.py.

# Python keeps its bytecode cache (__pycache__, in the venv and in src/) for these commands even
# where the environment turns it off (PYTHONDONTWRITEBYTECODE=1, set in some container images;
# pip installs with --no-compile to keep the install short): without it every Python process,
# each test worker and each subprocess a test starts, compiles the source of numba, pandas,
# xarray and the rest anew (`import geardyn` 4.7 s CPU instead of 1.5 s, measured on the 2-core
# machine; bench/RESULTS.md).
unexport PYTHONDONTWRITEBYTECODE

.PHONY: venv demo test test-slow bench bench-peers reproduce reproduce-verdicts lint clean clean-cache docs

$(STAMP): pyproject.toml
	$(PYTHON) -m venv $(VENV)
	$(BIN)/python -m pip install --quiet --upgrade pip
	$(BIN)/python -m pip install --quiet --no-compile -e ".[test]"
	touch $(STAMP)

venv: $(STAMP)

# Paper Fig. 3 (consistent interpretation): the full 1000-point bifurcation diagram, and one
# point of it (Omega = 1.1, period 2) in detail: time history, phase portrait, Poincare section,
# labelled amplitude spectrum. The two run side by side (on a fresh cache each compiles its own
# kernels, one core each; the point's report is printed after the diagram's).
demo: $(STAMP)
	mkdir -p out
	$(BIN)/geardyn simulate paper_fig3 --interpretation consistent --omega 1.1 --out out/fig3_omega1.1.nc --plot out/fig3_omega1.1.png > out/demo-point.log 2>&1 & point=$$!; \
	$(BIN)/geardyn bifurcation paper_fig3 --interpretation consistent --out out/fig3.nc --plot out/fig3.png; diagram=$$?; \
	wait $$point; point=$$?; cat out/demo-point.log; test $$diagram -eq 0 -a $$point -eq 0

# warm_kernels compiles the built-in models' kernels once, two models at a time, before the two
# test workers start (else both compile the same kernels side by side); with a warm cache it
# only loads them. The workers take the tests by work stealing: each starts on its half of the
# collection (whole files, in order) and takes half of the other's remaining tests when it runs
# out, so that a file's tests, which share its test models' kernels, mostly run in one worker
# (with --dist load they alternate, and a worker waits, idle, for the kernel the other compiles).
# Both steps keep the two cores busy, so the helper process that compiles a new model's split
# step ahead (GEARDYN_COMPILE_AHEAD, docs/engine.md) is off here: it would only add its start-up
# (an import of geardyn, ~2.7 s CPU) to each new model's compile (the cold warm-up's 10 helpers:
# 348 -> 321 s CPU, measured on the 2-core machine).
test: $(STAMP)
	$(BIN)/ruff check src tests examples bench
	GEARDYN_COMPILE_AHEAD=0 $(BIN)/python tests/warm_kernels.py --jobs 2
	GEARDYN_COMPILE_AHEAD=0 $(BIN)/python -m pytest -n 2 --dist worksteal -q --durations=15

# The long studies only (marked @pytest.mark.slow; pyproject's addopts keep them out of
# `make test`, and this -m replaces that selection): results bitwise the same at 512- and
# 256-bit vectors (compiles the kernels at 256 bits), a real `geardyn map` killed with SIGKILL
# and resumed. CI (.ci/run) runs them after `make test` and `make docs`.
test-slow: $(STAMP)
	$(BIN)/python -m pytest -n 2 -q -m slow --timeout=1800 --durations=5

# Each script's --write replaces its rows of the "Current figures" table at the top of
# bench/RESULTS.md (date and commit stamped); the reproduction's timing is bench/reproduce.py.
bench: $(STAMP)
	$(BIN)/python bench/bifurcation.py --write
	$(BIN)/python bench/lyapunov.py --write
	$(BIN)/python bench/crossing.py --write
	$(BIN)/python bench/map.py --write
	$(BIN)/python bench/continuation.py

# geardyn against plain numba RK4, SciPy LSODA, diffrax and numbalsoda on the gear-pair workload,
# all in one run (about 1-2 min on 2 cores); replaces the "## Peers" section of bench/RESULTS.md.
# numbalsoda has only a source distribution that needs a Fortran compiler: when it does not
# install, its row says "not installed".
bench-peers: $(STAMP)
	$(BIN)/python -m pip install --quiet -e ".[bench]"
	$(BIN)/python -m pip install --quiet numbalsoda || echo "numbalsoda did not install: its row is skipped"
	$(BIN)/python bench/peers.py --write

# The paper's whole study at its resolution (about 1 min on 2 cores): out/reproduce/report.html
reproduce: $(STAMP)
	$(BIN)/geardyn reproduce --all --out out/reproduce

# Every claim under all three interpretations (about 2 min on 2 cores): the report in
# out/reproduce-all and the verdict table committed as docs/reproduction-verdicts.md
reproduce-verdicts: $(STAMP)
	$(BIN)/geardyn reproduce --all --interpretation all --out out/reproduce-all --verdicts docs/reproduction-verdicts.md

# The documentation site (Sphinx, docs/conf.py) into docs/_build/html (open index.html), offline;
# warnings are errors (broken cross-references, docstrings that do not parse, a gallery example
# in examples/ that fails). The examples run at every build: measured 5.8 min CPU with a cold
# numba cache (kernel compiles; after `make test` most kernels are warm), 41 s CPU warm.
DOCS_STAMP := $(VENV)/.docs-installed
$(DOCS_STAMP): $(STAMP) pyproject.toml
	$(BIN)/python -m pip install --quiet -e ".[docs]"
	touch $(DOCS_STAMP)

docs: $(DOCS_STAMP)
	MPLBACKEND=Agg $(BIN)/sphinx-build -W --keep-going -q -b html docs docs/_build/html

lint: $(STAMP)
	$(BIN)/ruff check src tests examples bench

clean:
	rm -rf $(VENV) out docs/_build docs/api/generated docs/auto_examples

# geardyn's kernel cache (every model's kernels compile again on their next use)
clean-cache:
	rm -rf "$${GEARDYN_CACHE_DIR:-$${XDG_CACHE_HOME:-$$HOME/.cache}/geardyn}"
