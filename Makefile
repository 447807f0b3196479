# Two commands do everything on a fresh machine:
#   make demo   — set up .venv, then solve a paper panel and draw its mechanism
#   make test   — set up .venv, then run pytest tests/ verification/
PYTHON ?= python3
VENV   := .venv
BIN    := $(VENV)/bin
STAMP  := $(VENV)/.installed

.PHONY: demo test test-latest explore compare bench bench-assoc bench-accuracy bench-scaling bench-joints bench-nonassociative bench-certify bench-ipopt bench-floor bench-bounded bench-engine bench-crisp bench-crisp-floor bench-first-order html-screenshot venv clean

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

# The same suite with fresh random examples for the property tests (make test repeats its own).
explore: $(STAMP)
	$(BIN)/python -m pytest tests/ verification/ -q --hypothesis-profile=explore

# The 108-panel comparison of the two contact models (~10 min on 2 cores; resumable).
COMPARE_OUT ?= compare
compare: $(STAMP)
	$(BIN)/alma compare --out $(COMPARE_OUT) --workers 2

bench: $(STAMP)
	$(BIN)/python benchmarks/bench_lp.py

bench-assoc: $(STAMP)
	$(BIN)/python benchmarks/bench_assoc_speed.py --doe

bench-accuracy: $(STAMP)
	$(BIN)/python benchmarks/bench_accuracy.py

bench-scaling: $(STAMP)
	$(BIN)/python benchmarks/bench_scaling.py

bench-joints: $(STAMP)
	$(BIN)/python benchmarks/bench_joints.py

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

html-screenshot: $(STAMP)
	$(BIN)/python tools/html_screenshot.py build/html

clean:
	rm -rf $(VENV) $(LATEST) demo .pytest_cache .hypothesis
