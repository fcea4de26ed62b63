# mechbook: every target sets up its own virtual environment first.
PYTHON ?= python3
VENV   ?= .venv
BIN     = $(VENV)/bin
STAMP   = $(VENV)/.installed
AJV     = .ci/ajv/node_modules/.package-lock.json

.PHONY: check test test-quick test-mutation test-min test-install lint fuzz report bench bench-check bench-sweep bench-power bench-taylor clean

$(STAMP): pyproject.toml constraints.txt
	test -x $(BIN)/python || $(PYTHON) -m venv $(VENV)
	$(BIN)/python -m pip install --quiet --upgrade pip
	$(BIN)/python -m pip install --quiet -c constraints.txt -e '.[dev]'
	touch $(STAMP)

check: $(STAMP)  ## check every problem against the book's answer key (one worker per core)
	$(BIN)/mechbook check

report: $(STAMP)  ## check (reusing stored outcomes), then write results/report/index.html
	-$(BIN)/mechbook check  # a failing part is shown in the report, not an end to it
	$(BIN)/mechbook report

# ajv, the JavaScript JSON Schema validator tests/test_schema_editors.py runs the shipped
# schemas through (ECMA-262 regexes, as editors compile them); skipped where npm is absent
# (the test then installs it itself, or skips where node is absent)
$(AJV): .ci/ajv/package.json .ci/ajv/package-lock.json
	if command -v npm >/dev/null 2>&1; then npm ci --silent --no-audit --no-fund --prefix .ci/ajv; fi

test: $(STAMP) $(AJV)   ## the test suite, the mutation tests on a sample of six answer keys (~8 min on two cores)
	$(BIN)/python -m pytest -q -n auto -m 'not mutation'

test-mutation: $(STAMP)  ## the mutation tests on every other answer key (~9 min on two cores; CI runs it)
	$(BIN)/python -m pytest -q -n auto -m mutation

test-quick: $(STAMP) $(AJV)  ## the suite without the slow tests, for every change (2698 of 3238 tests, ~3 min on two cores)
	$(BIN)/python -m pytest -q -n auto -m 'not slow'

# The oldest versions pyproject.toml's ranges allow (.ci/min_versions.py), mechbook itself
# built by the oldest setuptools allowed (no build isolation) and installed as a wheel (not
# editable), and a short suite: the lower bounds are tested.
MIN = .venv-min
MIN_TESTS = tests/test_expr.py tests/test_loading.py tests/test_domains.py \
            tests/test_author_loop.py tests/test_watch.py
test-min:  ## the oldest dependency versions allowed, a short suite and a check (~5 min)
	rm -rf $(MIN)
	$(PYTHON) -m venv $(MIN)
	$(PYTHON) .ci/min_versions.py > $(MIN)/min-constraints.txt
	$(MIN)/bin/python -m pip install --quiet -c $(MIN)/min-constraints.txt setuptools
	$(MIN)/bin/python -m pip install --quiet --no-build-isolation \
	    -c $(MIN)/min-constraints.txt . pytest
	cd $(MIN) && bin/python -c "import mechbook, numpy, sympy; \
	    print('mechbook', mechbook.__file__, 'numpy', numpy.__version__, 'sympy', sympy.__version__)"
	$(MIN)/bin/pytest -q -p no:cacheprovider $(MIN_TESTS)
	rm -rf $(MIN)/tree && $(MIN)/bin/mechbook init $(MIN)/tree
	$(MIN)/bin/mechbook --root $(MIN)/tree check
	$(MIN)/bin/mechbook check lim-2031 symon-10-05 --no-store

# The README's install instructions, run as written (.ci/readme_install.py): a copy of the
# tracked files, `pip install .` in a clean venv with its dependencies from the index, then
# `mechbook init`, `check` and `report`; a wheel built and installed into another venv.
test-install:  ## install by the README's own words in clean venvs, then init, check, report (~5 min)
	$(PYTHON) .ci/readme_install.py

fuzz: $(STAMP)   ## 10,000 mutated and hostile problem/answer files under time and memory limits (~30 min)
	$(BIN)/python tests/fuzz.py --cases 10000 --seed 1 --keep results/fuzz \
		--json results/fuzz/results.jsonl

bench: $(STAMP)  ## integrators' work-precision, symbolic cost, extreme ratios -> results/ (~15 min)
	mkdir -p results/bench
	$(BIN)/python bench/work_precision.py --out results/bench.h5 --figdir results/bench \
		> results/bench/work_precision.txt && cat results/bench/work_precision.txt
	$(BIN)/python bench/compiled_steps.py --csv results/bench/compiled \
		> results/bench/compiled_steps.txt && cat results/bench/compiled_steps.txt
	$(BIN)/python bench/symbolic.py --repeat 1 --csv results/bench/symbolic.csv \
		> results/bench/symbolic.txt && cat results/bench/symbolic.txt
	$(BIN)/python bench/extremes.py --csv results/bench/extremes.csv \
		> results/bench/extremes.txt && cat results/bench/extremes.txt

bench-check: $(STAMP)  ## cold/warm `mechbook check` before and after, side by side (~30 min)
	mkdir -p results/bench
	$(BIN)/python bench/check_time.py --tests --csv results/bench/check_time.csv \
		--profile lim-2057 symon-09-07 lim-2034 lim-2042 symon-09-31 symon-09-01 \
		          lim-2058 lim-2043 symon-09-02 lim-2055 \
		--out results/bench/check_time.md

bench-sweep: $(STAMP)  ## 10^6-point sweeps: points per second, float64 vs 30 digits (~2 min)
	mkdir -p results/bench
	$(BIN)/python bench/sweep.py --csv results/bench/sweep.csv > results/bench/sweep.txt \
		&& cat results/bench/sweep.txt

bench-taylor: $(STAMP)  ## `simulate --method taylor` against heyoka's own propagate_grid, pendulum, 10^4 periods (~2 min)
	mkdir -p results/bench
	$(BIN)/python bench/taylor.py --repeat 7 --cli 3 --float128 > results/bench/taylor.txt \
		&& cat results/bench/taylor.txt

bench-power: $(STAMP)  ## the checker's power: small wrong answers rejected, per quantity, before/after -> docs/answers.md (~1 h)
	mkdir -p results/bench
	$(BIN)/python bench/power.py --docs --json results/bench/power.jsonl \
		--out results/bench/power.md

lint: $(STAMP)
	$(BIN)/ruff check mechbook tests bench

clean:
	rm -rf $(VENV) $(MIN) results .pytest_cache .ci/ajv/node_modules
