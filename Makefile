# mechbook: every target sets up its own virtual environment first.
PYTHON ?= python3
VENV   ?= .venv
BIN     = $(VENV)/bin
STAMP   = $(VENV)/.installed

.PHONY: check test lint bench clean

$(STAMP): pyproject.toml
	test -x $(BIN)/python || $(PYTHON) -m venv $(VENV)
	$(BIN)/python -m pip install --quiet --upgrade pip
	$(BIN)/python -m pip install --quiet -e '.[dev]'
	touch $(STAMP)

check: $(STAMP)  ## check every problem against the book's answer key
	$(BIN)/mechbook check

test: $(STAMP)   ## run the test suite
	$(BIN)/python -m pytest -q -n auto  # the mutation test is long; one worker per core

lint: $(STAMP)
	$(BIN)/ruff check mechbook tests bench

clean:
	rm -rf $(VENV) results .pytest_cache
