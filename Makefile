# LanEvil Studio: `make run` and `make test` set up .venv on first use (and again when pyproject.toml changes).

PYTHON ?= python3
VENV ?= .venv
PY := $(VENV)/bin/python
STAMP := $(VENV)/.lanevil-installed
# The CPU build of PyTorch (a plain `torch` from the index is a multi-GB CUDA build); only `lanevil train` needs it.
TORCH ?= torch==2.13.0

.PHONY: run preview test test-fast test-slow test-browser bench clean

$(STAMP): pyproject.toml
	test -x $(PY) || $(PYTHON) -m venv $(VENV)
	$(PY) -m pip install --quiet $(TORCH)
	$(PY) -m pip install --quiet -e '.[test,learn]'
	touch $(STAMP)

# The web backend, demo website, study and viser editor, on the stock library (Ctrl+C stops both servers).
run: $(STAMP)
	$(PY) -m app.cli serve

# Frame 0 of every stock case (and a labelled copy) under out/.
preview: $(STAMP)
	$(PY) -m app.cli preview --out out

test: test-fast test-slow test-browser

test-fast: $(STAMP)
	$(PY) -m pytest -q -n auto

# pytest exits 5 when no test carries the mark; that is not a failure.
test-slow: $(STAMP)
	$(PY) -m pytest -q -n auto -m "slow and not browser" || test $$? -eq 5

# Headless Debian Chromium driven by Playwright; scripts/install-chromium installs it when missing.
test-browser: $(STAMP)
	scripts/install-chromium
	$(PY) -m pytest -q -m browser || test $$? -eq 5

bench: $(STAMP)
	$(PY) -m lanevil_core.cli bench

clean:
	rm -rf out .pytest_cache
