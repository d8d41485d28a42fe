# The two commands of README.md:
#   make run   installs what is missing, builds, runs the main job
#   make test  installs what is missing, builds, runs every test
PRESET ?= release
BUILD := build/$(PRESET)
CLI := $(BUILD)/apps/microcobot/microcobot
JOBS ?= $(shell nproc)

.PHONY: run demo report test deps configure build cli python asan fuzz bench format clean

# The main job: the platform live, operated from the browser console whose URL it prints first
# (http://127.0.0.1:8080/); Ctrl-C stops it with every device in its safe state. It builds only
# the command line and the libraries it links (not the tests, benchmarks and Python module), so
# that a fresh machine reaches the console first. SERVE_ARGS adds options (`make run
# SERVE_ARGS="--scene pin-in-hole"`).
run: cli
	$(CLI) serve --out out/live $(SERVE_ARGS)

# The scripted session: the teleoperated pick-and-place run to completion; prints where the
# session report is.
demo: cli
	$(CLI) run --out out/session

# Every module's figures in one HTML report.
report: cli
	$(CLI) report --out out/report

test: build
	ctest --preset $(PRESET) -j $(JOBS)

deps:
	@scripts/install-deps.sh

configure: deps
	@cmake --preset $(PRESET) >/dev/null

build: configure
	cmake --build --preset $(PRESET) -j $(JOBS)

# The `microcobot` command line alone (target microcobot_cli) and what it links.
cli: configure
	cmake --build --preset $(PRESET) -j $(JOBS) --target microcobot_cli

# The Python module only: build/$(PRESET)/python/microcobot (PYTHONPATH=build/$(PRESET)/python).
python: configure
	cmake --build --preset $(PRESET) -j $(JOBS) --target _microcobot

# Sanitizer build and its tests (CI runs this after `make test`).
asan:
	$(MAKE) test PRESET=asan

# The parsers under libFuzzer (clang preset `fuzz`), 10 minutes each; ctest (label fuzz) runs
# 100 000 inputs each from a fixed seed.
fuzz: deps
	scripts/fuzz.sh 600

bench: build
	@for b in $(BUILD)/bench/*_bench; do echo "== $$b"; $$b --benchmark_min_time=0.2; done
	@echo "== bench/serve_bench.mjs"; MC_CLI=$(CLI) node --experimental-websocket --no-warnings bench/serve_bench.mjs

format:
	@git ls-files '*.h' '*.cc' | xargs clang-format -i

clean:
	rm -rf build out
