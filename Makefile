# Two commands: `make demo` and `make test`. Both create .venv when missing.
PYTHON ?= python3
VENV   := .venv
PY     := $(VENV)/bin/python
# What a virtual display and Qt's xcb platform plugin need on Debian, and the
# Open Asset Import Library (FBX clips); checked one by one so a machine that
# has them all needs neither root nor network.
APT_PACKAGES := libassimp5 xvfb xauth libxcb-cursor0 libxkbcommon-x11-0 libxcb-icccm4 libxcb-keysyms1 \
	libxcb-image0 libxcb-render-util0 libxcb-xinerama0 libxcb-shape0 libxcb-randr0 \
	libxcb-xfixes0 libxcb-xkb1 libxkbcommon0 libegl1 libgl1 libglx-mesa0 libgl1-mesa-dri \
	libfontconfig1 libdbus-1-3 libgomp1
DEMO_OUT ?= demo-out

.PHONY: demo test test-all flake explore install install-test system-deps lint bench docs tables screenshots coverage clean

$(VENV)/.installed: pyproject.toml
	test -x $(PY) || $(PYTHON) -m venv $(VENV)
	$(PY) -m pip install -q --upgrade pip
	$(PY) -m pip install -q -e .
	$(PY) -m volanim_core warmup  # every numba kernel compiled now, not on a user's first scan (#61)
	touch $@

# The Khronos glTF validator (its own JavaScript build, from npm) checks the .glb files export-gltf writes.
GLTF_VALIDATOR := gltf-validator@2.0.0-dev.3.10

$(VENV)/.installed-test: $(VENV)/.installed
	$(PY) -m pip install -q -e '.[test]'
	@command -v npm >/dev/null || { echo "npm is missing (the glTF validator's tests need it): sudo apt-get install npm"; exit 1; }
	npm install --silent --no-audit --no-fund --prefix $(VENV)/npm $(GLTF_VALIDATOR)
	touch $@

install: $(VENV)/.installed
install-test: $(VENV)/.installed-test

system-deps:
	@missing=$$(for p in $(APT_PACKAGES); do dpkg -s $$p >/dev/null 2>&1 || echo $$p; done); \
	if [ -z "$$missing" ]; then exit 0; fi; \
	if [ "$$(id -u)" = 0 ]; then \
		echo "installing Debian packages: $$missing"; \
		apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends $$missing; \
	else \
		echo "missing Debian packages (the virtual display, assimp for FBX); run:"; \
		echo "  sudo apt-get install -y $$missing"; exit 1; \
	fi

# The headless pipeline always runs; then the studio opens on the mannequin when
# there is a display (and not under CI).
demo: install
	$(VENV)/bin/volanim demo -o $(DEMO_OUT)
	@if [ -n "$${DISPLAY}$${WAYLAND_DISPLAY}" ] && [ -z "$${CI}" ]; then \
		echo "opening the studio on the mannequin (close the window to finish)"; \
		$(VENV)/bin/volanim-studio --demo mannequin; \
	else \
		echo "no display: ran the pipeline headless; on a desktop run .venv/bin/volanim-studio --demo mannequin"; \
	fi

# Two tiers, as napari and scikit-image have them (README, "Testing"). Two pytest-xdist workers, each
# with its own virtual display (pytest-xvfb); no test depends on another having run in the same process
# (xdist may put them on different workers); hypothesis draws the same examples every run (tests/conftest.py).
#   make test      every unit, model, GUI and CLI test that proves a behaviour: under 10 minutes on 2 cores
#   make test-all  everything: also the `slow` tier (the README and --help chains, the fault corpus,
#                  disk-full, Visible-Human scale, long property runs, the longest CLI chains); what .ci/run runs
#   make flake     the default tier FLAKE_RUNS times under a CPU load: any test whose result changes
#   make explore   the property tests drawing new examples (HYPOTHESIS_PROFILE=explore)
PYTEST_WORKERS ?= 2
FLAKE_RUNS ?= 3
test: install-test system-deps
	$(VENV)/bin/ruff check src tests benchmarks assets docs
	$(PY) -m pytest -n $(PYTEST_WORKERS) -m "not slow"

test-all: install-test system-deps
	$(VENV)/bin/ruff check src tests benchmarks assets docs
	$(PY) -m pytest -n $(PYTEST_WORKERS)

flake: install-test system-deps
	$(PY) tests/flake.py --runs $(FLAKE_RUNS) -- -n $(PYTEST_WORKERS) -m "not slow"

explore: install-test system-deps
	HYPOTHESIS_PROFILE=explore $(PY) -m pytest -n $(PYTEST_WORKERS) tests/studio/model/test_document_state.py \
		tests/core/io/test_io_fuzz.py

# The coverage of volanim_core (about 30 minutes on 2 cores): the core tests with the kernels compiled (numba
# code runs as machine code, so coverage sees none of its lines), then the kernels' own tests on small
# inputs with NUMBA_DISABLE_JIT=1, which runs them as Python, as stumpy measures its kernels. A report per
# module; htmlcov/ has every line. The CLI tests' child processes are not measured.
KERNEL_TESTS := tests/core/reconstruct/test_labels.py tests/core/reconstruct/test_neighbours.py \
	tests/core/skeleton/test_skeletonize.py tests/core/rig/test_attach.py tests/core/colour/test_sort.py
coverage: install-test system-deps
	rm -rf .coverage-data htmlcov && mkdir -p .coverage-data
	$(VENV)/bin/coverage run -m pytest -q -p no:cacheprovider tests/core
	# (as Python a kernel holds the GIL: the test that the compiled ones release it does not apply)
	NUMBA_DISABLE_JIT=1 $(VENV)/bin/coverage run -m pytest -q -p no:cacheprovider -k "not other_threads_run" \
		$(KERNEL_TESTS)
	NUMBA_DISABLE_JIT=1 $(VENV)/bin/coverage run -m pytest -q -p no:cacheprovider -k oracle \
		tests/core/reconstruct/test_engine.py
	NUMBA_DISABLE_JIT=1 $(VENV)/bin/coverage run -m pytest -q -p no:cacheprovider \
		-k "settled_heap or cannot_fit or any_axis or what_rests or acceleration_sets" tests/core/sequence/test_effects.py
	NUMBA_DISABLE_JIT=1 $(VENV)/bin/coverage run -m pytest -q -p no:cacheprovider \
		-k "star or bent_chain or a_t_has or splits or refused" tests/core/rig/test_autorig.py
	$(VENV)/bin/coverage combine -q
	$(VENV)/bin/coverage report
	$(VENV)/bin/coverage html -q

lint: install-test
	$(VENV)/bin/ruff check src tests benchmarks
	$(VENV)/bin/lint-imports --no-cache

bench: install-test system-deps
	$(PY) benchmarks/bench_skeleton.py
	$(PY) benchmarks/bench_reconstruct.py
	$(PY) benchmarks/thesis_tables.py
	xvfb-run -a $(PY) benchmarks/bench_studio.py
	xvfb-run -a $(PY) benchmarks/bench_motion.py
	$(PY) benchmarks/bench_colour.py
	$(PY) benchmarks/bench_scans.py

# The docs pages' generated tables (volume tools, every benchmark's figures): about 15 minutes on 2 cores.
tables: install-test system-deps
	xvfb-run -a -s "-screen 0 1600x1000x24" $(PY) docs/update_tables.py

# The documentation site (Sphinx: docs/conf.py) into docs/_build/html, strict: a warning, a broken link or a
# missing API name fails it. The gallery's scripts run as it builds.
docs: install-test system-deps
	xvfb-run -a $(PY) -m sphinx -W --keep-going -n -b html docs docs/_build/html
	@echo "open docs/_build/html/index.html"

screenshots: install-test system-deps
	xvfb-run -a -s "-screen 0 1600x1000x24" $(PY) docs/make_screenshots.py
	xvfb-run -a $(PY) docs/make_drag_strip.py
	$(PY) docs/make_colour_renders.py
	$(PY) docs/make_shape_pictures.py
	$(PY) docs/make_autorig_pictures.py
	$(PY) docs/make_thesis_figures.py

clean:
	rm -rf $(VENV) $(DEMO_OUT) .pytest_cache .coverage-data htmlcov docs/_build docs/auto_examples
