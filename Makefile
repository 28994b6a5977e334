# LanEvil Studio: `make run` and `make test` set up .venv on first use (and again when pyproject.toml changes).

PYTHON ?= python3
VENV ?= .venv
PY := $(VENV)/bin/python
STAMP := $(VENV)/.lanevil-installed

.PHONY: run test test-fast test-slow bench clean

$(STAMP): pyproject.toml
	test -x $(PY) || $(PYTHON) -m venv $(VENV)
	$(PY) -m pip install --quiet -e '.[test]'
	touch $(STAMP)

run: $(STAMP)
	$(PY) -m lanevil_core.cli preview --out out

test: test-fast test-slow

test-fast: $(STAMP)
	$(PY) -m pytest -q -n auto

# pytest exits 5 when no test carries the mark; that is not a failure.
test-slow: $(STAMP)
	$(PY) -m pytest -q -n auto -m slow || test $$? -eq 5

bench: $(STAMP)
	$(PY) -m lanevil_core.cli bench

clean:
	rm -rf out .pytest_cache
