# Two commands do everything on a fresh machine:
#   make demo   — set up .venv, then solve a paper panel and draw its mechanism
#   make test   — set up .venv, then run pytest tests/ verification/ on every core, slow tests aside
# make test-slow runs the tests marked slow, make test-all everything; CI (.ci/run) runs both parts.
PYTHON ?= python3
VENV   := .venv
BIN    := $(VENV)/bin
STAMP  := $(VENV)/.installed

# (The bench-* names are not .PHONY: make applies no pattern rule to a phony target.)
.PHONY: demo test test-slow test-all test-latest test-latest-subset test-next-highs explore lint compare bench bench-assoc bench-floor bench-ipopt figures html-screenshot venv clean

venv: $(STAMP)

$(STAMP): pyproject.toml constraints.txt
	test -x $(BIN)/python || $(PYTHON) -m venv $(VENV)
	$(BIN)/python -m pip install --quiet --upgrade pip
	$(BIN)/python -m pip install --quiet -c constraints.txt -e ".[test,dask,scip,lint]"
	touch $(STAMP)

demo: $(STAMP)
	mkdir -p demo
	$(BIN)/alma panel --bond english --panel-ratio 1:1 --block-ratio 2:1 --friction 0.6 --plot demo/mechanism.png
	@echo "picture written to demo/mechanism.png"

# pytest-xdist on every core (-n auto: 2 here), each test file on one worker (its module fixtures
# built once); `slow` marks the tests of minutes (pyproject.toml), which test-slow runs.
PYTEST := $(BIN)/python -m pytest tests/ verification/ -q -n auto --dist loadfile
test: $(STAMP)
	$(PYTEST) -m "not slow"

test-slow: $(STAMP)
	$(PYTEST) -m slow

test-all: $(STAMP)
	$(PYTEST)

# ruff (check and format --check) and mypy as configured in pyproject.toml (.pre-commit-config.yaml
# runs the same): all three run, and any finding of one fails; no file is left out (no baseline).
LINT_PATHS := alma tests verification benchmarks studies tools
lint: $(STAMP)
	status=0; $(BIN)/ruff check $(LINT_PATHS) || status=1; \
	$(BIN)/ruff format --check $(LINT_PATHS) || status=1; \
	$(BIN)/mypy || status=1; exit $$status

# The whole suite against the newest release of every dependency (no constraints file), in a
# venv of its own: catches the next release of a dependency before a user meets it.
LATEST := .venv-latest
test-latest:
	rm -rf $(LATEST)
	$(PYTHON) -m venv $(LATEST)
	$(LATEST)/bin/python -m pip install --quiet --upgrade pip
	$(LATEST)/bin/python -m pip install --quiet -e ".[test,dask,scip,lint]"
	$(LATEST)/bin/python -m pip list --format=freeze > $(LATEST)/versions.txt
	$(LATEST)/bin/python -m pytest tests/ verification/ -q -n auto --dist loadfile

# A few minutes of the same against the newest releases, for CI after `make test`: one JSON
# object on stdout from every command (a dependency printing on fd 1 breaks it) and the search's
# determinism. Reuses .venv-latest when it was made today, so a rerun is quick.
LATEST_SUBSET := tests/test_cli_json.py verification/test_search_determinism.py tests/test_canonical.py \
                 verification/test_friction_invariance.py
test-latest-subset:
	test -n "$$(find $(LATEST)/versions.txt -mtime -1 2>/dev/null)" || { \
	  rm -rf $(LATEST) && $(PYTHON) -m venv $(LATEST) && \
	  $(LATEST)/bin/python -m pip install --quiet --upgrade pip && \
	  $(LATEST)/bin/python -m pip install --quiet --upgrade -e ".[test]" && \
	  $(LATEST)/bin/python -m pip list --format=freeze > $(LATEST)/versions.txt; }
	grep -i -E '^(highspy|scipy|numpy|clarabel|casadi|ezdxf)==' $(LATEST)/versions.txt
	$(LATEST)/bin/python -m pytest $(LATEST_SUBSET) -q -m "not slow"

# The same suite with fresh random examples for the property tests (make test repeats its own).
explore: $(STAMP)
	$(PYTEST) --hypothesis-profile=explore

# The 108-panel comparison of the two contact models (~10 min on 2 cores; resumable).
COMPARE_OUT ?= compare
compare: $(STAMP)
	$(BIN)/alma compare --out $(COMPARE_OUT) --workers 2

# Benchmarks: `make bench-NAME` runs benchmarks/bench_NAME.py (dashes as underscores), or the
# one-off experiment studies/bench_NAME.py, as a module with the arguments BENCH_ARGS_NAME.
# The names of the list below are kept as aliases.
BENCH_ARGS_assoc_speed := --doe
BENCH_ARGS_bounded     := --sweep
BENCH_ARGS_engine      := --panels
bench_module = $(if $(wildcard benchmarks/bench_$(1).py),benchmarks,studies).bench_$(1)
bench-%: $(STAMP)
	$(BIN)/python -m $(call bench_module,$(subst -,_,$*)) $(BENCH_ARGS_$(subst -,_,$*))

# bench: joints, build, solve and certification of the largest panels; bench-assoc: the
# associative speed targets against plain Clarabel; bench-floor: what Clarabel itself costs per
# iteration; bench-ipopt: the multi-start against IPOPT from the LP solution (a study).
bench: bench-lp ;
bench-assoc: bench-assoc-speed ;
bench-floor: bench-clarabel-floor ;
bench-ipopt: bench-ipopt-lp-start ;
# Also: bench-accuracy, bench-scaling, bench-joints, bench-nonassociative, bench-certify,
# bench-bounded, bench-engine, bench-crisp; the studies bench-crisp-floor, bench-first-order.
BENCH_ARGS_certify     := --backends highs,scip
# Also: bench-compressive (the cone program against the LP), bench-push (a capacity curve against
# one associative solve), bench-friction (the friction search per scene, below).

# Every picture of the README and docs/ again (the last step needs Debian's chromium; ~2 min).
figures: $(STAMP)
	$(BIN)/python tools/figures.py
	$(BIN)/python tools/structures_figure.py
	$(BIN)/python tools/cohesion_figure.py
	$(BIN)/python tools/html_screenshot.py

# The HTML reports of the examples in headless Chromium: docs/screenshots/ (not part of CI).
html-screenshot: $(STAMP)
	$(BIN)/python tools/html_screenshot.py

clean:
	rm -rf $(VENV) $(LATEST) demo .pytest_cache .hypothesis

# The friction search per scene against the associative solve (time ratio, the start kept, α_NL):
# the Ferris & Tin-Loi walls and a cohesive stack; PANELS=1 adds the 108 panels, LACT3=FOLDER
# LACT³'s drawings.  bench-friction-perturb solves each scene again perturbed by 1e-12.
FRICTION_ARGS = $(if $(PANELS),--panels) $(if $(LACT3),--lact3 $(LACT3))
bench-friction: $(STAMP)
	$(BIN)/python -m benchmarks.bench_friction $(FRICTION_ARGS)

bench-friction-perturb: $(STAMP)
	$(BIN)/python -m benchmarks.bench_friction --perturb $(FRICTION_ARGS)

# Whether the next HiGHS release gives the friction search's answers of the pinned one (pyproject
# admits one minor series): the friction benchmark's scenes with each, exit 1 on a difference.
NEXT_HIGHS := .venv-next-highs
test-next-highs: $(STAMP)
	test -x $(NEXT_HIGHS)/bin/python || { $(PYTHON) -m venv $(NEXT_HIGHS) && \
	  $(NEXT_HIGHS)/bin/python -m pip install --quiet -c constraints.txt -e . && \
	  $(NEXT_HIGHS)/bin/python -m pip install --quiet --upgrade --no-deps highspy; }
	$(BIN)/python -m benchmarks.bench_friction --out $(NEXT_HIGHS)/pinned.csv $(FRICTION_ARGS)
	$(NEXT_HIGHS)/bin/python -m pip list --format=freeze | grep -i '^highspy=='
	$(NEXT_HIGHS)/bin/python -m benchmarks.bench_friction --against $(NEXT_HIGHS)/pinned.csv $(FRICTION_ARGS)
