# Two commands set everything up on a fresh machine: `make run` and `make test`.
PYTHON ?= python3
VENV   := .venv
BIN    := $(VENV)/bin
STAMP  := $(VENV)/.installed
EXAMPLE ?= resources/examples/helix.svg

.PHONY: run test lint bench fuzz package clean bytecode

$(BIN)/python:
	$(PYTHON) -m venv $(VENV)

$(STAMP): pyproject.toml | $(BIN)/python
	$(BIN)/python -m pip install --quiet --upgrade pip
	$(BIN)/python -m pip install --quiet -e '.[test]'
	@touch $(STAMP)

# What an installed package has: every module compiled once, not again by each process (tests
# and benchmarks start hundreds of `lsys` processes; also where PYTHONDONTWRITEBYTECODE is set).
bytecode: $(STAMP)
	@$(BIN)/python -m compileall -q lsys_core app > /dev/null

run: $(STAMP) bytecode
	@$(BIN)/python -m lsys_editor.syscheck
	$(BIN)/lsys-editor $(EXAMPLE)

lint: $(STAMP)
	$(BIN)/ruff check lsys_core app tests
	$(BIN)/ruff format --check lsys_core app tests
	$(BIN)/lint-imports
	$(BIN)/mypy

test: $(STAMP) lint bytecode
	QT_QPA_PLATFORM=offscreen $(BIN)/python -m pytest -q

bench: $(STAMP) bytecode
	@echo "cores: $$(nproc)"
	@for f in tests/bench/bench_*.py; do echo "== $$f"; QT_QPA_PLATFORM=offscreen $(BIN)/python $$f || exit 1; done

fuzz: $(STAMP)
	$(BIN)/python tests/fuzz/fuzz_svg.py --target all --seconds $${FUZZ_SECONDS:-60}

package: $(STAMP)
	bash packaging/build.sh

clean:
	rm -rf $(VENV) build dist *.egg-info .pytest_cache .ruff_cache
