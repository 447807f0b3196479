# Two commands do everything on a fresh machine:
#   make demo   — set up .venv, then solve a paper panel and draw its mechanism
#   make test   — set up .venv, then run pytest tests/ verification/
PYTHON ?= python3
VENV   := .venv
BIN    := $(VENV)/bin
STAMP  := $(VENV)/.installed

.PHONY: bench-friction bench-friction-perturb demo test test-latest test-latest-subset explore compare bench bench-compressive bench-assoc bench-accuracy bench-scaling bench-joints bench-nonassociative bench-certify bench-ipopt bench-floor bench-bounded bench-engine bench-crisp bench-crisp-floor bench-first-order bench-push figures html-screenshot venv clean

venv: $(STAMP)

$(STAMP): pyproject.toml constraints.txt
	test -x $(BIN)/python || $(PYTHON) -m venv $(VENV)
	$(BIN)/python -m pip install --quiet --upgrade pip
	$(BIN)/python -m pip install --quiet -c constraints.txt -e ".[test,dask,scip]"
	touch $(STAMP)

demo: $(STAMP)
	mkdir -p demo
	$(BIN)/alma panel --bond english --panel-ratio 1:1 --block-ratio 2:1 --friction 0.6 --plot demo/mechanism.png
	@echo "picture written to demo/mechanism.png"

test: $(STAMP)
	$(BIN)/python -m pytest tests/ verification/ -q

# The whole suite against the newest release of every dependency (no constraints file), in a
# venv of its own: catches the next release of a dependency before a user meets it.
LATEST := .venv-latest
test-latest:
	rm -rf $(LATEST)
	$(PYTHON) -m venv $(LATEST)
	$(LATEST)/bin/python -m pip install --quiet --upgrade pip
	$(LATEST)/bin/python -m pip install --quiet -e ".[test,dask,scip]"
	$(LATEST)/bin/python -m pip list --format=freeze > $(LATEST)/versions.txt
	$(LATEST)/bin/python -m pytest tests/ verification/ -q

# A few minutes of the same against the newest releases, for CI after `make test`: one JSON
# object on stdout from every command (a dependency printing on fd 1 breaks it) and the search's
# determinism. Reuses .venv-latest when it was made today, so a rerun is quick.
LATEST_SUBSET := tests/test_cli_json.py verification/test_search_determinism.py
test-latest-subset:
	test -n "$$(find $(LATEST)/versions.txt -mtime -1 2>/dev/null)" || { \
	  rm -rf $(LATEST) && $(PYTHON) -m venv $(LATEST) && \
	  $(LATEST)/bin/python -m pip install --quiet --upgrade pip && \
	  $(LATEST)/bin/python -m pip install --quiet --upgrade -e ".[test]" && \
	  $(LATEST)/bin/python -m pip list --format=freeze > $(LATEST)/versions.txt; }
	grep -i -E '^(highspy|scipy|numpy|clarabel|casadi|ezdxf)==' $(LATEST)/versions.txt
	$(LATEST)/bin/python -m pytest $(LATEST_SUBSET) -q

# The same suite with fresh random examples for the property tests (make test repeats its own).
explore: $(STAMP)
	$(BIN)/python -m pytest tests/ verification/ -q --hypothesis-profile=explore

# The 108-panel comparison of the two contact models (~10 min on 2 cores; resumable).
COMPARE_OUT ?= compare
compare: $(STAMP)
	$(BIN)/alma compare --out $(COMPARE_OUT) --workers 2

bench: $(STAMP)
	$(BIN)/python benchmarks/bench_lp.py

bench-compressive: $(STAMP)
	$(BIN)/python benchmarks/bench_compressive.py

bench-assoc: $(STAMP)
	$(BIN)/python benchmarks/bench_assoc_speed.py --doe

bench-accuracy: $(STAMP)
	$(BIN)/python benchmarks/bench_accuracy.py

bench-scaling: $(STAMP)
	$(BIN)/python benchmarks/bench_scaling.py

bench-joints: $(STAMP)
	$(BIN)/python benchmarks/bench_joints.py

# A 40-step capacity curve of the 444-block panel against one associative solve (issue 33).
bench-push: $(STAMP)
	$(BIN)/python benchmarks/bench_push.py

bench-nonassociative: $(STAMP)
	$(BIN)/python benchmarks/bench_nonassociative.py

bench-certify: $(STAMP)
	$(BIN)/python benchmarks/bench_certify.py --backends highs,scip

bench-bounded: $(STAMP)
	$(BIN)/python benchmarks/bench_bounded.py --sweep

bench-ipopt: $(STAMP)
	$(BIN)/python benchmarks/bench_ipopt_lp_start.py

# What Clarabel itself costs per iteration on the largest panel and the walls (the speed floor).
bench-floor: $(STAMP)
	$(BIN)/python benchmarks/bench_clarabel_floor.py

# alma's interior point (alma.engine) against the Clarabel path: panel, walls, 108 panels.
bench-engine: $(STAMP)
	$(BIN)/python benchmarks/bench_engine.py --panels

bench-crisp: $(STAMP)
	$(BIN)/python benchmarks/bench_crisp.py

# Why a vertex of the optimal face costs more than 20 % of the solve (issue 19; CLP if cylp is installed).
bench-crisp-floor: $(STAMP)
	$(BIN)/python benchmarks/bench_crisp_floor.py

# HiGHS PDLP (a first-order method) on the largest panel, certified by alma (issue 16).
bench-first-order: $(STAMP)
	$(BIN)/python benchmarks/bench_first_order.py

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
	$(BIN)/python benchmarks/bench_friction.py $(FRICTION_ARGS)

bench-friction-perturb: $(STAMP)
	$(BIN)/python benchmarks/bench_friction.py --perturb $(FRICTION_ARGS)
