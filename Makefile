# robomech: `make run` and `make test` are the whole quick start.
PYTHON ?= python3
VENV   := .venv
BIN    := $(VENV)/bin
STAMP  := $(VENV)/.installed
OUT    ?= out

.PHONY: install run test bench verify lint clean

install: $(STAMP)

$(STAMP): pyproject.toml
	$(PYTHON) -m venv $(VENV)
	$(BIN)/python -m pip install --quiet --upgrade pip
	$(BIN)/python -m pip install --quiet -e ".[verify,explore,test]"
	touch $(STAMP)

run: install
	$(BIN)/robomech reproduce --out $(OUT)

test: install
	$(BIN)/ruff check src tests benchmarks
	$(BIN)/python -m pytest -q

verify: install
	$(BIN)/robomech verify

bench: install
	$(BIN)/python benchmarks/run.py

lint: install
	$(BIN)/ruff check src tests benchmarks

clean:
	rm -rf $(VENV) $(OUT) .pytest_cache .benchmarks build src/*.egg-info
