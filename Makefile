# Two commands do all set-up on a fresh machine: `make demo` and `make test`.
# Each creates .venv and installs the pinned dependencies when missing or stale.
PYTHON ?= python3
VENV := .venv
BIN := $(VENV)/bin
STAMP := $(VENV)/.installed

.PHONY: demo test test-fast lint docs bench mutants corpus clean chromium tex

$(STAMP): pyproject.toml requirements.lock
	test -x $(BIN)/python || $(PYTHON) -m venv $(VENV)
	$(BIN)/python -m pip install --quiet --upgrade pip
	$(BIN)/python -m pip install --quiet -r requirements.lock
	$(BIN)/python -m pip install --quiet --no-deps -e .
	touch $(STAMP)

# Headless Chromium renders recordings (stills, filmstrips, videos, the browser tests).
# Debian's package, installed when missing and we may (root with apt); otherwise those
# steps say so. The flags robodyn runs it with: CHROMIUM_FLAGS in robodyn/viz/stills.py
# (ROBODYN_CHROMIUM picks another browser). Videos encode with imageio-ffmpeg (in the lock).
chromium:
	@command -v chromium >/dev/null 2>&1 || { [ "$$(id -u)" = 0 ] && command -v apt-get >/dev/null 2>&1 && \
		(apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq chromium >/dev/null) || \
		echo "note: no chromium (install Debian's 'chromium' for stills, videos and the browser tests)"; }
	@command -v chromium >/dev/null 2>&1 && chromium --version 2>/dev/null | head -1 || true

# pdflatex compiles the equations' LaTeX (--format pdf, and the slow tier's typesetting
# test). Debian's TeX Live, installed when missing and we may (root with apt).
tex:
	@command -v pdflatex >/dev/null 2>&1 && command -v pdftoppm >/dev/null 2>&1 || { [ "$$(id -u)" = 0 ] && command -v apt-get >/dev/null 2>&1 && \
		(apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends \
			texlive-latex-base texlive-latex-extra poppler-utils >/dev/null) || \
		echo "note: no pdflatex (install Debian's texlive-latex-base for --format pdf and the typesetting test)"; }

# The main job on the built-in robot: the RP arm's equations, then the lecture's control
# story (drive the end effector to a target) as trajectory, plot, animation and still.
demo: $(STAMP) chromium
	mkdir -p out
	$(BIN)/robodyn equations rp_arm --q 0.5,0.1 --v 1.0,0.2 --a 0.5,-0.3
	$(BIN)/robodyn simulate rp_arm --controller task-space --q0 0,0.1 --target 0.7,0.7 --duration 3 \
		--out out/rp_arm.csv --plot out/rp_arm.png --record out/rp_arm.html \
		$$(command -v chromium >/dev/null 2>&1 && echo --png out/rp_arm_poster.png)

# Everything CI runs: lint, the fast tier, then the slow tier. Both tiers run on
# TEST_WORKERS processes (pytest-xdist; default 2, the CI machine's cores; 0 runs in-process).
TEST_WORKERS ?= 2
test: $(STAMP) chromium tex
	$(BIN)/ruff check robodyn tests scripts
	$(BIN)/lint-imports
	$(BIN)/mypy
	$(BIN)/python -m pytest -m "not slow" -n $(TEST_WORKERS) --durations=15
	$(BIN)/python -m pytest -m slow -n $(TEST_WORKERS) --durations=15

test-fast: $(STAMP)
	$(BIN)/python -m pytest -m "not slow" -n $(TEST_WORKERS) -x -q

# The API reference of every public module, from the docstrings (Sphinx autodoc + napoleon;
# sources in docs/api/), warnings as errors. Open build/docs/index.html.
docs: $(STAMP)
	$(BIN)/python -m sphinx -b html -W --keep-going -q docs/api build/docs
	@echo "API reference: build/docs/index.html"

lint: $(STAMP)
	$(BIN)/ruff check robodyn tests scripts
	$(BIN)/ruff format --check robodyn tests scripts
	$(BIN)/lint-imports
	$(BIN)/mypy

# MuJoCo is the simulation reference of the benchmarks only (requirements-bench.lock).
bench: $(STAMP)
	$(BIN)/python -m pip install --quiet -r requirements-bench.lock || echo "note: MuJoCo not installed; its rows are skipped"
	$(BIN)/python scripts/bench.py

# The MJCF reader on the two public model collections as shipped (dm_control's suite, Gymnasium's
# MuJoCo assets), against MuJoCo: needs the network once (pip download into CORPUS_DIR) and
# MuJoCo (requirements-bench.lock); not part of `make test`. Exit status 1 on any mismatch.
CORPUS_DIR ?= $(HOME)/.cache/robodyn-corpus
corpus: $(STAMP)
	$(BIN)/python -m pip install --quiet -r requirements-bench.lock
	$(BIN)/python scripts/corpus_check.py --dir $(CORPUS_DIR)

# Mutation testing of the core modules with the fast tier (slow: not part of `make test` or CI).
# The modules are [tool.mutmut] only_mutate in pyproject.toml; MUTANTS="robodyn.sim.control*"
# restricts a run to one module's mutants; MUTANT_JOBS sets the parallel workers (default 1:
# the machine is shared). Results are cached in mutants/; docs/testing.md says how to read them.
MUTANT_JOBS ?= 1
MUTANTS ?=
mutants: $(STAMP)
	$(BIN)/mutmut run --max-children $(MUTANT_JOBS) $(MUTANTS)
	$(BIN)/mutmut results

clean:
	rm -rf $(VENV) .pytest_cache .ruff_cache mutants build/docs docs/api/generated
