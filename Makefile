# One entry point. `make demo` runs the main job, `make test` the test suite; both set up first.
VENV := .venv
PY := $(VENV)/bin/python
# Two workers: CI machines have two cores; ROS tests are isolated per process (tests/conftest.py).
PYTEST_ARGS ?= -q -n 2

.PHONY: setup test demo lint clean

setup:
	bash scripts/setup.sh

# pytest exits 5 when it collected no test: that is a failure here, not a pass.
test: setup
	@rc=0; $(PY) -m pytest $(PYTEST_ARGS) || rc=$$?; \
	if [ $$rc -eq 5 ]; then echo "make test: error: pytest collected no tests" >&2; exit 1; fi; \
	exit $$rc

demo: setup
	$(VENV)/bin/viscoadh demo

lint: setup
	$(VENV)/bin/ruff check .

clean:
	rm -rf $(VENV) build install log .pytest_cache .ruff_cache
