#!/usr/bin/env bash
# Runs the libFuzzer harnesses of the input parsers (CSV reader, YAML parameter parser, platform
# configuration parser, console commands, vendor controllers' replies), built by the sanitizer
# preset `asan` (clang, ASan + UBSan; the harnesses are part of that build).
# Usage: scripts/fuzz.sh [SECONDS]     builds the harnesses (build/asan) and explores for SECONDS
#                                      each (default 30; `make fuzz`: 600), new inputs kept in
#                                      build/asan/fuzz/corpus-*
#        scripts/fuzz.sh --runs N [--build-dir DIR]
#                                      the test suite's run (ctest fuzz_parsers): N inputs each
#                                      from a fixed seed and the committed corpus only, so the
#                                      same build gives the same verdict on every machine; with
#                                      --build-dir, the harnesses of that build, nothing built
# Exit 0 when no harness found a crash; 77 (skipped) when clang or libFuzzer is missing;
# 1 with the crashing input kept under <build>/fuzz/findings/ otherwise (make it a regression
# test: tests/cli/hardening_test.cc or tests/core).
set -euo pipefail
cd "$(dirname "$0")/.."
limit=(-max_total_time="${1:-30}")
fresh=""
build=""
if [[ "${1:-}" == --runs ]]; then
  limit=(-runs="${2:?--runs needs a count}" -seed=1)
  [[ "${3:-}" == --build-dir ]] && build="${4:?--build-dir needs a directory}"
  fresh=$(mktemp -d)
  trap 'rm -rf "$fresh"' EXIT
fi
harnesses=(csv params config console vendor)
if [[ -z "$build" ]]; then
  if ! command -v clang++ >/dev/null || ! ls /usr/lib/llvm-*/lib/clang/*/lib/linux/libclang_rt.fuzzer-x86_64.a >/dev/null 2>&1; then
    echo "fuzz: skipped (clang++ and libclang-rt-14-dev are needed: scripts/install-deps.sh)" >&2
    exit 77
  fi
  build=build/asan
  if [[ ! -f $build/CMakeCache.txt ]]; then
    cmake --preset asan -DMC_BUILD_TESTS=ON >/dev/null
  fi
  mkdir -p "$build/fuzz"
  # The build's log is shown when it fails (CI=true makes warnings errors).
  if ! cmake --build --preset asan --target "${harnesses[@]/#/fuzz_}" -j "${JOBS:-2}" \
      >"$build/fuzz/build.log" 2>&1; then
    echo "fuzz: the clang build failed ($build/fuzz/build.log):" >&2
    grep -E "error|FAILED" "$build/fuzz/build.log" | head -20 >&2
    exit 1
  fi
fi
status=0
for h in "${harnesses[@]}"; do
  work="${fresh:-$build/fuzz}/corpus-$h"   # new inputs go here; the seed corpus stays untouched
  mkdir -p "$work" "$build/fuzz/findings"
  echo "fuzz: $h (${limit[*]})" >&2
  if ! ASAN_OPTIONS=detect_leaks=1 "$build/tests/fuzz/fuzz_$h" "$work" "tests/fuzz/corpus/$h" \
      "${limit[@]}" -max_len=4096 -rss_limit_mb=2048 -timeout=10 \
      -artifact_prefix="$build/fuzz/findings/$h-" -print_final_stats=1 >"$build/fuzz/$h.log" 2>&1; then
    echo "fuzz: $h FAILED, see $build/fuzz/$h.log and $build/fuzz/findings/" >&2
    tail -30 "$build/fuzz/$h.log" >&2
    status=1
  else
    grep -E "stat::number_of_executed_units|cov:" "$build/fuzz/$h.log" | tail -2 >&2 || true
  fi
done
exit $status
