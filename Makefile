# Two commands do all set-up on a fresh machine: `make demo` and `make test`.
# Each creates .venv and installs the pinned dependencies when missing or stale.
PYTHON ?= python3
VENV := .venv
BIN := $(VENV)/bin
STAMP := $(VENV)/.installed

.PHONY: demo test test-fast lint bench clean

$(STAMP): pyproject.toml requirements.lock
	test -x $(BIN)/python || $(PYTHON) -m venv $(VENV)
	$(BIN)/python -m pip install --quiet --upgrade pip
	$(BIN)/python -m pip install --quiet -r requirements.lock
	$(BIN)/python -m pip install --quiet --no-deps -e .
	touch $(STAMP)

demo: $(STAMP)
	$(BIN)/robodyn equations rp_arm --q 0.5,0.1 --v 1.0,0.2 --a 0.5,-0.3

# Everything CI runs: lint, the fast tier, then the slow tier.
test: $(STAMP)
	$(BIN)/ruff check robodyn tests scripts
	$(BIN)/python -m pytest -m "not slow"
	$(BIN)/python -m pytest -m slow

test-fast: $(STAMP)
	$(BIN)/python -m pytest -m "not slow" -x -q

lint: $(STAMP)
	$(BIN)/ruff check robodyn tests scripts
	$(BIN)/ruff format --check robodyn tests scripts

bench: $(STAMP)
	$(BIN)/python scripts/bench.py

clean:
	rm -rf $(VENV) .pytest_cache .ruff_cache
