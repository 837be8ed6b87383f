# camtool: `make demo` runs the main job on a bundled sample; `make test` runs the checks.
# Both create .venv and install camtool into it when missing.
PYTHON ?= python3
VENV := .venv
BIN := $(VENV)/bin
STAMP := $(VENV)/.installed

.PHONY: demo test lint typecheck unit bench bench-venv docs clean corpus

# Python caches compiled bytecode (__pycache__/, ignored by git) whatever the calling shell
# says: with PYTHONDONTWRITEBYTECODE set, every test worker, every camtool started by a test
# and pytest's assertion rewriting compiled their sources again on each start.
unexport PYTHONDONTWRITEBYTECODE

$(STAMP): pyproject.toml
	test -x $(BIN)/python || $(PYTHON) -m venv $(VENV)
	$(BIN)/python -m pip install --quiet --upgrade pip
	$(BIN)/python -m pip install --quiet -e '.[test,cluster]'
	touch $(STAMP)

demo: $(STAMP)
	mkdir -p out
	$(BIN)/camtool post samples/logo.dxf --target pic-mmh -o out/logo.pic \
		--verify --report out/logo-verify.json --preview out/logo-verify.png
	$(BIN)/camtool post samples/plate.dxf --target grbl --offset outside --tool-diameter 3 \
		--origin lower-left \
		--depth 3 --step-down 1 --tabs 3 --lead-in 2 -o out/plate.gcode --preview out/plate.png
	$(BIN)/camtool post samples/part.dxf --target linuxcnc --job samples/part.toml \
		-o out/part.ngc --report out/part-verify.json --preview out/part.png
	@echo "demo: out/logo.pic (pic-mmh program), out/logo-verify.json and .png (predicted error)"
	@echo "demo: out/plate.gcode (GRBL: outside profile, 3 passes, tabs, lead-ins), out/plate.png"
	@echo "demo: out/part.ngc (LinuxCNC job: drill, engrave, pocket, outline; samples/part.toml)"

lint: $(STAMP)
	$(BIN)/ruff check camtool postprocessors tests samples docs
	$(BIN)/ruff format --check camtool postprocessors tests samples docs
	$(BIN)/lint-imports

typecheck: $(STAMP)
	$(BIN)/mypy

# The suite in one worker process per core, at most 4 (pytest-xdist; each worker loads its
# own OpenCASCADE, numba and matplotlib); `.venv/bin/pytest` alone runs it in
# this process, as for a single file.
unit: $(STAMP)
	$(BIN)/python tests/corpus/fetch_corpus.py
	$(BIN)/pytest -n auto --maxprocesses 4

test: lint typecheck unit

# The benchmarks' peers in their own environment, apart from camtool's: vpype and its
# g-code plugin for tests/benchmarks/bench_svg.py (versions checked: vpype 1.15.0,
# vpype-gcode 0.13.0).
BENCH_VENV := .bench-venv
BENCH_STAMP := $(BENCH_VENV)/.installed

$(BENCH_STAMP):
	test -x $(BENCH_VENV)/bin/python || $(PYTHON) -m venv $(BENCH_VENV)
	$(BENCH_VENV)/bin/python -m pip install --quiet 'vpype>=1.14,<1.16' 'vpype-gcode>=0.13,<0.14'
	touch $(BENCH_STAMP)

bench-venv: $(BENCH_STAMP)

# Every benchmark in tests/benchmarks/, one after the other, then one table of ratios
# against the named peers (run it on an otherwise quiet machine).
bench: $(STAMP) $(BENCH_STAMP)
	$(BIN)/python tests/benchmarks/run_all.py

clean:
	rm -rf $(VENV) $(BENCH_VENV) out .pytest_cache .mypy_cache .ruff_cache

# Fetch the real-drawing corpus and LinuxCNC's rs274 (Debian packages, cached in .corpus/),
# then post every sampled drawing on every target; CAMTOOL_CORPUS=full for all of it.
corpus: $(STAMP)
	$(BIN)/python tests/corpus/fetch_corpus.py
	$(BIN)/pytest tests/corpus -rf

docs: $(STAMP)
	$(BIN)/python docs/make_docs.py
