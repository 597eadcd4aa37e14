# mech_kinematics: set-up, run and test with a local virtualenv.
#
#   make run       start the node on the default scene (ARGS='...' appends arguments)
#   make test      the whole test suite (PYTEST_ARGS='-k scene' narrows it)
#   make bench     solver benchmark (ARGS='--peer pylinkage': side by side with pylinkage)
#   make lint      ruff + flake8 + mypy --strict on the pure modules
#   make install   set up .venv with everything (what run, test and lint need)
#   make clean     remove .venv and every build/cache artefact
#
# The first target that needs it creates .venv (python3 -m venv) and installs
# what it needs in three steps, each with a stamp file inside .venv, so that a
# step is redone only when what it depends on changes:
# 1. requirements.txt (running: the node and every tool), this package editable;
# 2. tf2_msgs from its IDL (not on PyPI): scripts/build_tf2_msgs.py, 2-3 s;
# 3. requirements-dev.txt (test and lint tools): for test, lint and install.
# `make run` and `make bench` take steps 1-2; `make test` and `make lint` all
# three.  No ROS installation or sourced environment is needed: the ros-*
# wheels set their own LD_LIBRARY_PATH (ros-wheels-bootstrapper).

SHELL := /bin/bash
.DEFAULT_GOAL := help

PYTHON ?= python3
VENV := .venv
VPY := $(VENV)/bin/python
ARGS ?=
PYTEST_ARGS ?=

# The runtime stamp's name records whether the package directory existed at
# install time, so the editable install is redone once when mech_kinematics/ appears.
PKG_STATE := $(if $(wildcard mech_kinematics/__init__.py),pkg,nopkg)
STAMP := $(VENV)/.mech_kinematics-installed-$(PKG_STATE)
TF2_STAMP := $(VENV)/.tf2_msgs-built
DEV_STAMP := $(VENV)/.mech_kinematics-dev-installed

# Build in this clone, never through a link: a `.venv` that is a symlink (to another
# checkout's virtualenv, say) is refused by every target but help and clean.
ifneq ($(filter-out help clean,$(or $(MAKECMDGOALS),help)),)
ifneq ($(shell test -L $(VENV) && echo link),)
$(error $(VENV) is a symlink (to $(shell readlink $(VENV))): remove it (rm $(VENV)) and make creates this clone's own)
endif
endif

# Keep DDS discovery on the loopback interface (no multicast onto the LAN);
# override with e.g. `make run ROS_AUTOMATIC_DISCOVERY_RANGE=SUBNET`.
ROS_AUTOMATIC_DISCOVERY_RANGE ?= LOCALHOST
export ROS_AUTOMATIC_DISCOVERY_RANGE
export PIP_DISABLE_PIP_VERSION_CHECK := 1
# A value inherited from another venv's bootstrapped Python would stop this
# venv's ros-wheels-bootstrapper from setting LD_LIBRARY_PATH for its own libs.
unexport _ROS_WHEELS_BOOTSTRAP_COMPLETE

.PHONY: help install run test bench lint clean

help:
	@sed -n 's/^#   //p' $(firstword $(MAKEFILE_LIST))

$(VPY):
	$(PYTHON) -m venv $(VENV)

$(STAMP): requirements.txt setup.py setup.cfg | $(VPY)
	rm -f $(VENV)/.mech_kinematics-installed-*
	$(VPY) -m pip install --quiet -r requirements.txt
	$(VPY) -m pip install --quiet --no-build-isolation --no-deps -e .
	touch $@

# Idempotent and quiet on success; loud and failing on error.
$(TF2_STAMP): $(STAMP) scripts/build_tf2_msgs.py
	$(VPY) scripts/build_tf2_msgs.py
	touch $@

$(DEV_STAMP): $(STAMP) requirements-dev.txt
	$(VPY) -m pip install --quiet -r requirements-dev.txt
	touch $@

install: $(TF2_STAMP) $(DEV_STAMP)

run: $(TF2_STAMP)
	PYTHONUNBUFFERED=1 $(VPY) -m mech_kinematics run $(ARGS)

# The tests that time the node (marked serial: test/conftest.py) run alone, after the
# rest on two workers. One phase selecting nothing (pytest's status 5: PYTEST_ARGS='-k
# scene' may match tests of one phase only) is no failure; neither phase running a test is.
# The package's bytecode is written (in the clone's __pycache__, ignored by git) even
# where the environment says PYTHONDONTWRITEBYTECODE: the suite starts some hundreds
# of Pythons (nodes, commands), each 0.4-0.6 s slower compiling the package afresh.
test: $(TF2_STAMP) $(DEV_STAMP)
	@export PYTHONDONTWRITEBYTECODE=; \
	$(VPY) -m pytest -q -n 2 --dist loadfile -m 'not serial' --durations=10 $(PYTEST_ARGS); \
	first=$$?; \
	$(VPY) -m pytest -q -m serial --durations=10 $(PYTEST_ARGS); \
	second=$$?; \
	status=0; \
	for s in $$first $$second; do [ $$s -eq 0 ] || [ $$s -eq 5 ] || status=1; done; \
	if [ $$first -eq 5 ] && [ $$second -eq 5 ]; then \
		echo 'make test: no test ran: PYTEST_ARGS selected none in either phase' >&2; \
		status=1; \
	fi; \
	exit $$status

bench: $(TF2_STAMP)
	$(VPY) -m mech_kinematics bench $(ARGS)

# Runs all three checkers, then fails if any of them did.
lint: $(TF2_STAMP) $(DEV_STAMP)
	@status=0; \
	echo '== ruff'; $(VPY) -m ruff check mech_kinematics test setup.py scripts launch || status=1; \
	echo '== flake8'; $(VPY) -m flake8 mech_kinematics test setup.py scripts launch || status=1; \
	echo '== mypy --strict (the solver package, scene.py, errors.py, ...)'; $(VPY) -m mypy || status=1; \
	exit $$status

clean:
	rm -rf $(VENV) build install log dist *.egg-info .pytest_cache .mypy_cache .ruff_cache .hypothesis .benchmarks
	find . -path ./.git -prune -o -name __pycache__ -type d -prune -exec rm -rf {} +
