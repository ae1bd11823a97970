# robomech: `make run` and `make test` are the whole quick start.
PYTHON ?= python3
VENV   := .venv
BIN    := $(VENV)/bin
STAMP  := $(VENV)/.installed
DOCS_STAMP := $(VENV)/.installed-docs
OUT    ?= out
# `make docs REPORTS=out`: the docs show the reports of that `robomech reproduce --out` folder
# instead of reproducing the studies.
REPORTS ?=
# A second venv with `pip install .` and no extras: what a user without MuJoCo gets.
MINIMAL := .venv-minimal

.PHONY: install install-browser run test test-slow test-all bench verify lint typecheck docs check-minimal clean

# The modules that define numba kernels (robomech._numba.KERNEL_SOURCES): an edit of any of them (a
# pull, a checkout) names a new kernel cache folder (their fingerprint), which the warm-up fills again.
KERNEL_FILES := $(shell grep -rlE '_nj\b|njit' src/robomech --include='*.py')
WARM_STAMP := $(VENV)/.warmed

install: $(STAMP) $(WARM_STAMP)

$(STAMP): pyproject.toml
	$(PYTHON) -m venv $(VENV)
	$(BIN)/python -m pip install --quiet --upgrade pip
	$(BIN)/python -m pip install --quiet -e ".[verify,explore,test]"
	touch $(STAMP)

# compile the multibody kernels into the on-disk cache now, not at the user's first call: two halves
# in two processes at once (numba compiles on one thread); seconds when the cache is already filled
$(WARM_STAMP): $(STAMP) $(KERNEL_FILES)
	$(BIN)/python -c "from robomech.multibody._compiled import warm; warm(0)" & pid=$$!; \
	  $(BIN)/python -c "from robomech.multibody._compiled import warm; warm(1)" && wait $$pid
	touch $(WARM_STAMP)

$(DOCS_STAMP): $(STAMP)
	$(BIN)/python -m pip install --quiet -e ".[verify,explore,test,docs]"
	touch $(DOCS_STAMP)

# Debian's headless Chromium, which the viewer's browser test (tests/viewer) drives with playwright
# (playwright's own browser download is not used); nothing to do where it is installed.
CHROMIUM ?= /usr/bin/chromium-headless-shell
SUDO := $(shell [ "$$(id -u)" = 0 ] || echo sudo)
install-browser:
	@test -x $(CHROMIUM) || { $(SUDO) apt-get update -qq && $(SUDO) apt-get install -y -qq chromium-headless-shell; } \
	  || echo "install-browser: could not install chromium-headless-shell; the browser tests will be skipped"

# verify first: it records the engine results the studies also show (OUT/verification-results/),
# which reproduce then reads instead of computing them again; a failed check still reproduces, and
# make fails with verify's status.
run: install
	$(BIN)/robomech verify --out $(OUT); status=$$?; $(BIN)/robomech reproduce --out $(OUT) && exit $$status

# The fast tier (the README's second command): lint and every test not marked `slow` (a few minutes).
test: install install-browser
	$(BIN)/ruff check src tests benchmarks examples docs/conf.py
	$(BIN)/python -m pytest -q -m "not slow"

# The slow tier: engine simulations, whole-study reproductions, clusters, teeth of the heavy checks.
test-slow: install
	$(BIN)/python -m pytest -q -m slow

# Everything, both tiers (what CI runs).
test-all: test test-slow

verify: install
	$(BIN)/robomech verify

bench: install
	$(BIN)/python benchmarks/run.py

lint: install
	$(BIN)/ruff check src tests benchmarks examples docs/conf.py

# Static types: numpy.typing annotations checked by mypy over src/robomech (pyproject [tool.mypy]; ~1 min cold).
typecheck: install
	$(BIN)/mypy

# The documentation site; -W: a warning is an error, -n: every cross-reference must resolve.
# docs/conf.py writes an API page per public name, runs examples/*.py (sphinx-gallery), draws the
# gallery mechanisms and reproduces every study for its page (about 4 min on this 2-core machine the
# first time, reused until a source file changes).  Math is rendered by MathJax served from
# the site itself: the first build installs it from npm (Node.js) into docs/_build/npm.
# The built site is then checked: a page per public name, every study's report, and the equations
# typeset offline in headless Chromium (tests/test_docs.py, tests/test_docs_browser.py; ~20 s).
docs: $(DOCS_STAMP) install-browser
	ROBOMECH_DOCS_REPORTS=$(REPORTS) $(BIN)/sphinx-build -W --keep-going -n -q -b html docs docs/_build/html
	$(BIN)/python -m pytest -q -p no:cacheprovider tests/test_docs.py tests/test_docs_browser.py
	@echo "docs: open docs/_build/html/index.html"

# No extras installed: list, the engine-free study and the engine-free checks must exit 0.
check-minimal:
	rm -rf $(MINIMAL)
	$(PYTHON) -m venv $(MINIMAL)
	$(MINIMAL)/bin/python -m pip install --quiet .
	! $(MINIMAL)/bin/python -c "import mujoco" 2>/dev/null
	cd $(MINIMAL) && bin/robomech --version && bin/robomech list
	cd $(MINIMAL) && bin/robomech reproduce continuum --out minimal-out --quiet
	cd $(MINIMAL) && bin/robomech verify --quiet
	rm -rf $(MINIMAL)

clean:
	rm -rf $(VENV) $(MINIMAL) $(OUT) .mypy_cache .pytest_cache .benchmarks build src/*.egg-info docs/_build
