# visuomotor_gym developer commands. Everything runs inside .venv, created on first use.
#   make demo   set up, then run the main demo (writes outputs/demo/)
#   make test   set up, then ruff (pyproject.toml [tool.ruff.lint]) and the whole test suite
#   make bench  set up, then run the benchmarks in benchmarks/
#   make leaderboard-check   set up, then run the leaderboard check CI runs (leaderboard/)
#   make docs   set up, then generate the family pages and build the documentation site (mkdocs --strict)
#               into build/site; `make docs-pages` only regenerates docs/families/*.md
#   make test-ray   a second venv (.venv-ray) with Ray and RLlib (which pins its own gymnasium), then the
#                   Ray-backend and RLlib tests

PYTHON ?= python3
VENV ?= .venv
# The CPU build of PyTorch must be installed before stable-baselines3, or pip pulls a multi-GB CUDA build.
# It comes from PyTorch's CPU index (PyPI's Linux wheel depends on the nvidia-* CUDA wheels); pip falls back
# to the other indexes it knows when that one cannot be reached. TORCH_INDEX= (empty) skips it.
TORCH_SPEC ?= torch==2.13.0
TORCH_INDEX ?= https://download.pytorch.org/whl/cpu
TORCH_PIP_ARGS := $(if $(TORCH_INDEX),--extra-index-url $(TORCH_INDEX) --retries 1 --timeout 15)
PY := $(VENV)/bin/python
PIP := $(PY) -m pip
STAMP := $(VENV)/.installed
export MUJOCO_GL ?= egl
# One OpenBLAS kernel family on every x86 CPU, so episodes are bit-identical across machines (golden
# digests, leaderboard replays): see visuomotor_gym/_blas.py.
export OPENBLAS_CORETYPE ?= Haswell
# ... and one MKL code path for PyTorch (the ppo-npz policies' layers), the one an AMD CPU takes: visuomotor_gym/_blas.py.
export MKL_ENABLE_INSTRUCTIONS ?= SSE4_2

RAY_VENV ?= .venv-ray
RAY_STAMP := $(RAY_VENV)/.installed

DOCS_STAMP := $(VENV)/.installed-docs

.PHONY: setup demo test test-fast test-ray bench leaderboard-check docs docs-pages clean

$(STAMP): pyproject.toml Makefile
	$(PYTHON) -m venv $(VENV)
	$(PIP) install --quiet --upgrade pip
	$(PIP) install --quiet $(TORCH_PIP_ARGS) "$(TORCH_SPEC)"
	$(PIP) install --quiet -e ".[rl,viz,dev]"
	touch $(STAMP)

setup: $(STAMP)

demo: setup
	$(VENV)/bin/vmgym demo

test: setup
	$(VENV)/bin/ruff check .
	$(PY) -m pytest -n 2 --durations=15

test-fast: setup
	$(PY) -m pytest -n 2 -m "not slow"

# Ray pins its own dependencies; a separate venv (no torch) keeps the main one as users install it.
$(RAY_STAMP): pyproject.toml Makefile
	$(PYTHON) -m venv $(RAY_VENV)
	$(RAY_VENV)/bin/python -m pip install --quiet --upgrade pip
	$(RAY_VENV)/bin/python -m pip install --quiet $(TORCH_PIP_ARGS) "$(TORCH_SPEC)"
	$(RAY_VENV)/bin/python -m pip install --quiet -e ".[distributed,dev]" "ray[rllib]"
	touch $(RAY_STAMP)

test-ray: $(RAY_STAMP)
	VMGYM_REQUIRE_RAY=1 $(RAY_VENV)/bin/python -m pytest -q -m ray tests/test_ray_backend.py tests/test_rllib.py

bench: setup
	$(PY) benchmarks/env_throughput.py

leaderboard-check: setup
	$(VENV)/bin/vmgym leaderboard check

# The docs extra (mkdocs-material) in the same venv: the family pages import the package.
$(DOCS_STAMP): $(STAMP)
	$(PIP) install --quiet -e ".[docs]"
	touch $(DOCS_STAMP)

docs-pages: setup
	$(PY) docs/gen_family_pages.py

docs: $(DOCS_STAMP)
	$(PY) docs/gen_family_pages.py
	NO_MKDOCS_2_WARNING=1 $(VENV)/bin/mkdocs build --strict

clean:
	rm -rf $(VENV) $(RAY_VENV) build dist *.egg-info outputs .pytest_cache
