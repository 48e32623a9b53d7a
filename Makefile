# visuomotor_gym developer commands. Everything runs inside .venv, created on first use.
#   make demo   set up, then run the main demo (writes outputs/demo/)
#   make test   set up, then run the whole test suite
#   make bench  set up, then run the benchmarks in benchmarks/
#   make leaderboard-check   set up, then run the leaderboard check CI runs (leaderboard/)
#   make test-ray   a second venv (.venv-ray) with Ray and RLlib (which pins its own gymnasium), then the
#                   Ray-backend and RLlib tests

PYTHON ?= python3
VENV ?= .venv
# The CPU build of PyTorch must be installed before stable-baselines3, or pip pulls a multi-GB CUDA build.
TORCH_SPEC ?= torch==2.13.0
PY := $(VENV)/bin/python
PIP := $(PY) -m pip
STAMP := $(VENV)/.installed
export MUJOCO_GL ?= egl

RAY_VENV ?= .venv-ray
RAY_STAMP := $(RAY_VENV)/.installed

.PHONY: setup demo test test-fast test-ray bench leaderboard-check clean

$(STAMP): pyproject.toml Makefile
	$(PYTHON) -m venv $(VENV)
	$(PIP) install --quiet --upgrade pip
	$(PIP) install --quiet "$(TORCH_SPEC)"
	$(PIP) install --quiet -e ".[rl,viz,dev]"
	touch $(STAMP)

setup: $(STAMP)

demo: setup
	$(VENV)/bin/vmgym demo

test: setup
	$(PY) -m pytest -n 2 --durations=15

test-fast: setup
	$(PY) -m pytest -n 2 -m "not slow"

# Ray pins its own dependencies; a separate venv (no torch) keeps the main one as users install it.
$(RAY_STAMP): pyproject.toml Makefile
	$(PYTHON) -m venv $(RAY_VENV)
	$(RAY_VENV)/bin/python -m pip install --quiet --upgrade pip
	$(RAY_VENV)/bin/python -m pip install --quiet "$(TORCH_SPEC)"
	$(RAY_VENV)/bin/python -m pip install --quiet -e ".[distributed,dev]" "ray[rllib]"
	touch $(RAY_STAMP)

test-ray: $(RAY_STAMP)
	VMGYM_REQUIRE_RAY=1 $(RAY_VENV)/bin/python -m pytest -q -m ray tests/test_ray_backend.py tests/test_rllib.py

bench: setup
	$(PY) benchmarks/env_throughput.py

leaderboard-check: setup
	$(VENV)/bin/vmgym leaderboard check

clean:
	rm -rf $(VENV) $(RAY_VENV) build dist *.egg-info outputs .pytest_cache
