# camtool: `make demo` runs the main job on a bundled sample; `make test` runs the checks.
# Both create .venv and install camtool into it when missing.
PYTHON ?= python3
VENV := .venv
BIN := $(VENV)/bin
STAMP := $(VENV)/.installed

.PHONY: demo test lint typecheck unit bench docs clean

$(STAMP): pyproject.toml
	test -x $(BIN)/python || $(PYTHON) -m venv $(VENV)
	$(BIN)/python -m pip install --quiet --upgrade pip
	$(BIN)/python -m pip install --quiet -e '.[test]'
	touch $(STAMP)

demo: $(STAMP)
	mkdir -p out
	$(BIN)/camtool post samples/logo.dxf --target pic-mmh -o out/logo.pic \
		--verify --report out/logo-verify.json --preview out/logo-verify.png
	@echo "demo: out/logo.pic (pic-mmh program), out/logo-verify.json and .png (predicted error)"

lint: $(STAMP)
	$(BIN)/ruff check camtool tests samples docs
	$(BIN)/ruff format --check camtool tests samples docs

typecheck: $(STAMP)
	$(BIN)/mypy

unit: $(STAMP)
	$(BIN)/pytest

test: lint typecheck unit

bench: $(STAMP)
	for b in tests/benchmarks/bench_*.py; do $(BIN)/python $$b || exit 1; done

clean:
	rm -rf $(VENV) out .pytest_cache .mypy_cache .ruff_cache

docs: $(STAMP)
	$(BIN)/python docs/make_docs.py
