# `make demo` and `make test` each build the virtual environment on first use
# (or when pyproject.toml changes), so a fresh clone needs nothing else.
PYTHON ?= python3
VENV ?= .venv
BIN := $(VENV)/bin
STAMP := $(VENV)/.installed
# The documentation tools (the `docs` extra) have a stamp of their own: `make test` needs none.
DOCS_STAMP := $(VENV)/.installed-docs
DEMO_OUT ?= demo-output
# torch is installed first and pinned: magnum.np (the `micromagnetics` extra) accepts any torch,
# and pip's default on Linux is a CUDA build of several GB. Here 2.13.0 is a CPU build. On a
# GPU machine: `make venv TORCH="torch==2.13.0 --index-url https://download.pytorch.org/whl/cu128"`
# (or any CUDA build); elsewhere a CPU build: `--index-url https://download.pytorch.org/whl/cpu`.
TORCH ?= torch==2.13.0

.PHONY: demo test lint format bench docs clean venv

venv: $(STAMP)

$(STAMP): pyproject.toml
	test -x $(BIN)/python || $(PYTHON) -m venv $(VENV)
	$(BIN)/python -m pip install --quiet --upgrade pip
	$(BIN)/python -m pip install --quiet $(TORCH)
	$(BIN)/python -m pip install --quiet -e '.[test,micromagnetics]'
	touch $(STAMP)

$(DOCS_STAMP): $(STAMP) pyproject.toml
	$(BIN)/python -m pip install --quiet -e '.[docs]'
	touch $(DOCS_STAMP)

demo: $(STAMP)
	$(BIN)/skygas demo --out $(DEMO_OUT) --overwrite

# Two workers; each test module stays on one (--dist loadscope), so that a module's shared
# fixture (calibrate's, minutes of micromagnetics) is built once, not once per worker.
test: $(STAMP)
	$(BIN)/python -m pytest -n 2 --dist loadscope -q

# The quality gate (.ci/run runs it before the tests): lint rules and layout (pyproject.toml,
# [tool.ruff]) and types (mypy with the pydantic plugin, [tool.mypy]). `make format` applies
# the layout and the safe fixes.
lint: $(STAMP)
	$(BIN)/ruff check src tests benchmarks examples
	$(BIN)/ruff format --check src tests benchmarks examples
	$(BIN)/mypy

format: $(STAMP)
	$(BIN)/ruff check --fix src tests benchmarks examples
	$(BIN)/ruff format src tests benchmarks examples

# The documentation site (mkdocs.yml) into site/: the pages of docs/, the API reference from the
# docstrings and the tutorials, whose code runs during the build. Any warning is an error.
docs: $(DOCS_STAMP)
	NO_MKDOCS_2_WARNING=1 $(BIN)/mkdocs build --strict

bench: $(STAMP)
	$(BIN)/python benchmarks/bench_engine.py

clean:
	rm -rf $(VENV) $(DEMO_OUT) .pytest_cache site
