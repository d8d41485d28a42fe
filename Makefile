# The two commands of README.md:
#   make run   installs what is missing, builds, runs the main job
#   make test  installs what is missing, builds, runs every test
PRESET ?= release
BUILD := build/$(PRESET)
CLI := $(BUILD)/apps/microcobot/microcobot
JOBS ?= $(shell nproc)
# Everything `make test` builds; the sanitizer presets leave out what they leave out.
ifeq ($(filter $(PRESET),asan tsan),)
FULL_OPTS := -DMC_BUILD_TESTS=ON -DMC_BUILD_BENCH=ON -DMC_BUILD_PYTHON=ON -DMC_WITH_OPENCV=ON
else
FULL_OPTS := -DMC_BUILD_TESTS=ON -DMC_WITH_OPENCV=ON
endif

.PHONY: graph run demo report docs docs-serve results test deps deps-run configure configure-run build cli cli-only python asan tsan fuzz bench format clean

# The main job: the platform live, operated from the browser console whose URL it prints first
# (http://127.0.0.1:8080/); Ctrl-C stops it with every device in its safe state. It builds only
# the command line and the libraries it links (not the tests, benchmarks and Python module), so
# that a fresh machine reaches the console first. SERVE_ARGS adds options (`make run
# SERVE_ARGS="--scene pin-in-hole"`).
run: cli-only
	$(CLI) serve --out out/live $(SERVE_ARGS)

# The scripted session: the teleoperated pick-and-place run to completion; prints where the
# session report is.
demo: cli-only
	$(CLI) run --out out/session

# Every module's figures in one HTML report.
report: cli-only
	$(CLI) report --out out/report

test: build
	ctest --preset $(PRESET) -j $(JOBS)

# The documentation site, offline, into build/docs/ (open build/docs/index.html): docs/ with the
# reference pages generated from this build's program and Python module and Doxygen's C++ pages,
# built strict (scripts/docs/build.py; `make test` builds it too, ctest docs_build).
docs: cli python
	/usr/bin/python3 scripts/docs/build.py --cli $(CLI) --python $(BUILD)/python

# The site on http://127.0.0.1:8000/ (its search runs in a web worker, which file:// refuses).
docs-serve:
	@test -f build/docs/index.html || $(MAKE) docs
	/usr/bin/python3 -m http.server --bind 127.0.0.1 --directory build/docs 8000

# Every C++ benchmark, briefly, its JSON into bench/results/: the tables of docs/benchmarks.md.
results: build
	/usr/bin/python3 scripts/docs/gen_results.py --run $(BUILD)/bench --min-time 0.05

deps:
	@scripts/install-deps.sh

# What the main job needs, no more: a fresh machine configures without the tests, benchmarks and
# Python module (nor their packages); a build tree that has them keeps them.
deps-run:
	@scripts/install-deps.sh run

configure: deps
	@cmake --preset $(PRESET) $(FULL_OPTS) >/dev/null

configure-run: deps-run
	@if [ -f $(BUILD)/CMakeCache.txt ]; then cmake --preset $(PRESET) >/dev/null; \
	 else cmake --preset $(PRESET) -DMC_BUILD_TESTS=OFF -DMC_BUILD_BENCH=OFF -DMC_BUILD_PYTHON=OFF >/dev/null; fi

cli-only: configure-run
	cmake --build --preset $(PRESET) -j $(JOBS) --target microcobot_cli

build: configure
	cmake --build --preset $(PRESET) -j $(JOBS)

# The `microcobot` command line alone (target microcobot_cli) and what it links.
cli: configure
	cmake --build --preset $(PRESET) -j $(JOBS) --target microcobot_cli

# The Python module only: build/$(PRESET)/python/microcobot (PYTHONPATH=build/$(PRESET)/python).
python: configure
	cmake --build --preset $(PRESET) -j $(JOBS) --target _microcobot

# The sanitizer builds and their tests (docs/ci.md): AddressSanitizer and UBSan with the parsers'
# fuzzers (CI runs it after `make test`); ThreadSanitizer over the threaded modules
# (tests/tsan.supp: third-party code only).
asan:
	$(MAKE) test PRESET=asan

tsan:
	$(MAKE) test PRESET=tsan

# The parsers under libFuzzer (clang preset `fuzz`), 10 minutes each; ctest (label fuzz) runs
# 100 000 inputs each from a fixed seed.
fuzz: deps
	scripts/fuzz.sh 600

bench: build
	@for b in $(BUILD)/bench/*_bench; do echo "== $$b"; $$b --benchmark_min_time=0.2; done
	@echo "== bench/serve_bench.mjs"; MC_CLI=$(CLI) node --experimental-websocket --no-warnings bench/serve_bench.mjs

# The module graph of docs/architecture.md, drawn from the layering declared in
# src/microcobot/CMakeLists.txt (a test fails when the committed graph is stale).
graph:
	@scripts/check_layers.py --dot > docs/module-graph.dot
	@dot -Tsvg docs/module-graph.dot -o docs/module-graph.svg
	@echo "docs/module-graph.svg"

format:
	@git ls-files '*.h' '*.cc' | xargs clang-format -i

clean:
	rm -rf build out
