# `make install` sets up .venv from the lock requirements/dev.txt (every dependency, test, docs
# and build tool at an exact version), then tubefsi and its plugins editable without
# dependencies; `make demo`, `make test` and `make docs` do that first whenever the lock or a
# pyproject changed. `make test-latest` runs the tests in .venv-latest against the newest
# releases instead, and `make lock` re-resolves the lock (README, "Development").
PYTHON ?= python3.11
VENV   := .venv
PY     := $(VENV)/bin/python
STAMP  := $(VENV)/.installed
LOCK   := requirements/dev.txt
PLUGINS := $(wildcard plugins/*/pyproject.toml)
EDITABLES := -e . $(foreach p,$(PLUGINS),-e $(dir $(p)))
LATEST := .venv-latest
# `make lock` refreshes every pin to the newest release; `make lock LOCK_FLAGS=` keeps the
# current pins and resolves only what the inputs changed; `LOCK_FLAGS='-P numpy'` bumps one.
UV_VERSION := 0.13.9
LOCK_FLAGS ?= --upgrade

.PHONY: demo test test-all test-explore fuzz docs install test-latest lock clean

$(STAMP): $(LOCK) pyproject.toml $(PLUGINS)
	test -x $(PY) || $(PYTHON) -m venv $(VENV)
	$(PY) -m pip install --quiet -r $(LOCK)
	$(PY) -m pip install --quiet --no-deps --no-build-isolation $(EDITABLES)
	$(PY) -m pip check
	touch $(STAMP)

install: $(STAMP)

demo: $(STAMP)
	MPLBACKEND=Agg $(PY) examples/demo.py

# hypothesis profiles (tubefsi.testing.profiles, docs/verification.md "Random tests"): `make test`
# is seeded ("ci": the same examples on every machine and in every fresh clone); `make
# test-explore` draws new random examples on every run, ten times each test's own number, and
# keeps failures in .hypothesis/ to replay them first; `make test-explore PYTEST_ARGS=tests/test_limits.py`
# explores a part
# `make test` leaves out the tests marked slow (long reference checks, the plugins' fuzz
# contracts); `make test-all` runs them too. Tests run in one process per core (pytest-xdist;
# `make test WORKERS=0` runs them in this process)
PYTEST_ARGS ?=
WORKERS ?= auto
test: $(STAMP)
	TUBEFSI_HYPOTHESIS_PROFILE=ci MPLBACKEND=Agg $(PY) -m pytest -q -p no:cacheprovider -n $(WORKERS) -m "not slow" $(PYTEST_ARGS)

test-all: $(STAMP)
	TUBEFSI_HYPOTHESIS_PROFILE=ci MPLBACKEND=Agg $(PY) -m pytest -q -p no:cacheprovider -n $(WORKERS) $(PYTEST_ARGS)

test-explore: $(STAMP)
	TUBEFSI_HYPOTHESIS_PROFILE=explore MPLBACKEND=Agg $(PY) -m pytest -q -p no:cacheprovider -n $(WORKERS) $(PYTEST_ARGS)

# the long fuzz campaign (docs/verification.md, "Fuzzing"): every bad-input probe of every
# registered model and entry point and FUZZ_SCENES random valid scenes; prints the counts per
# category and entry point and the wall time, exits nonzero on any breach
FUZZ_SCENES ?= 300
fuzz: $(STAMP)
	MPLBACKEND=Agg $(PY) -m tubefsi.testing.fuzz --scenes $(FUZZ_SCENES)

# the documentation site (warnings are errors); figures are regenerated first. Then two checks
# of the built site that Sphinx does not make: no raw reST markup in its pages
# (tests/test_docs_build.py), and a look in headless Chromium, offline but for the site itself
# (docs/check_site.py: the theory page's math typeset by the site's own MathJax, the API's
# solve entry, a gallery figure; screenshots in docs/_build/screenshots/). It needs Debian's
# chromium (apt-get install chromium; another browser: make docs CHROMIUM=/path/to/chrome)
docs: $(STAMP)
	MPLBACKEND=Agg $(PY) examples/demo.py docs/_generated/demo
	MPLBACKEND=Agg $(PY) examples/fit_synthetic.py docs/_generated/fit
	MPLBACKEND=Agg $(PY) examples/network.py docs/_generated/network
	$(PY) -m sphinx -W --keep-going -q -b html docs docs/_build/html
	$(PY) -m pytest -q -p no:cacheprovider tests/test_docs_build.py
	$(PY) docs/check_site.py

# the same tests against the newest releases of everything (not the lock), in their own venv
test-latest:
	test -x $(LATEST)/bin/python || $(PYTHON) -m venv $(LATEST)
	$(LATEST)/bin/python -m pip install --quiet --upgrade pip setuptools wheel
	$(LATEST)/bin/python -m pip install --quiet --upgrade --upgrade-strategy eager \
	  -e '.[test,verify,fem,docs,network,pandas,xarray,progress,units,parallel]' $(foreach p,$(PLUGINS),-e $(dir $(p)))
	TUBEFSI_HYPOTHESIS_PROFILE=ci MPLBACKEND=Agg $(LATEST)/bin/python -m pytest -q -p no:cacheprovider -n $(WORKERS) -m "not slow"

# uv, at a fixed version in a throw-away venv, writes the lock from PyPI (not pip's indexes)
lock:
	tmp=$$(mktemp -d) && trap 'rm -rf "$$tmp"' EXIT && \
	$(PYTHON) -m venv "$$tmp" && "$$tmp/bin/python" -m pip install --quiet uv==$(UV_VERSION) && \
	"$$tmp/bin/uv" pip compile --quiet $(LOCK_FLAGS) --no-config --python-version 3.11 \
	  --python-platform x86_64-unknown-linux-gnu --no-emit-package tubefsi \
	  requirements/dev.in $(PLUGINS) -o $(LOCK) && \
	sed -i '2a # with uv $(UV_VERSION), from the repository root; `make lock` runs it, adding --upgrade by default.' $(LOCK)

clean:
	rm -rf $(VENV) $(LATEST) build src/*.egg-info docs/_build docs/_generated
