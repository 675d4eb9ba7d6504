# `make demo` and `make test` each set up .venv (tubefsi and its plugins, editable) first.
PYTHON ?= python3
VENV   := .venv
PY     := $(VENV)/bin/python
STAMP  := $(VENV)/.installed
PLUGINS := $(wildcard plugins/*/pyproject.toml)

.PHONY: demo test docs install clean

$(STAMP): pyproject.toml $(PLUGINS)
	$(PYTHON) -m venv $(VENV)
	$(PY) -m pip install --quiet -e '.[test,verify,docs]' $(foreach p,$(PLUGINS),-e $(dir $(p)))
	touch $(STAMP)

install: $(STAMP)

demo: $(STAMP)
	MPLBACKEND=Agg $(PY) examples/demo.py

test: $(STAMP)
	MPLBACKEND=Agg $(PY) -m pytest -q -p no:cacheprovider

# the documentation site (warnings are errors); figures are regenerated first
docs: $(STAMP)
	MPLBACKEND=Agg $(PY) examples/demo.py docs/_generated/demo
	MPLBACKEND=Agg $(PY) examples/fit_synthetic.py docs/_generated/fit
	$(PY) -m sphinx -W --keep-going -q -b html docs docs/_build/html

clean:
	rm -rf $(VENV) build src/*.egg-info docs/_build docs/_generated
