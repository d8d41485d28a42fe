#!/usr/bin/env bash
# Runs the libFuzzer harnesses of the input parsers (CSV reader, YAML parameter parser, platform
# configuration parser, console commands, vendor controllers' replies), built by the sanitizer
# preset `asan` (clang, ASan + UBSan; the harnesses are part of that build).
# Usage: scripts/fuzz.sh [SECONDS]     builds the harnesses (build/asan) and explores for SECONDS
#                                      each (default 30; `make fuzz`: 600), new inputs kept in
#                                      build/asan/fuzz/corpus-*
#        scripts/fuzz.sh --runs N [--build-dir DIR]
#                                      the test suite's run (ctest fuzz_parsers): N inputs each
#                                      from a fixed seed and the committed corpus only (libFuzzer
#                                      orders seed files of equal size as the directory lists
#                                      them, so machines may explore differently); with
#                                      --build-dir, the harnesses of that build, nothing built
# Exit 0 when no harness found a crash; 77 (skipped) when clang or libFuzzer is missing;
# 1 with the crashing input kept under <build>/fuzz/findings/ otherwise (make it a regression
# test: tests/cli/hardening_test.cc or tests/core). In the --runs mode a failure counts only when
# its input fails again alone (or, with no input, the same run fails again): a CI machine too loaded
# for the limits must not pass for a defect, nor a defect for load (its input is kept either way).
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
# One harness's run; its findings (crash-, timeout-, oom-, leak-<hash>) under the prefix $2.
fuzz_one() {
  local h=$1 findings=$2 work="${fresh:-$build/fuzz}/corpus-$1"  # the seed corpus stays untouched
  mkdir -p "$work"
  ASAN_OPTIONS=detect_leaks=1 "$build/tests/fuzz/fuzz_$h" "$work" "tests/fuzz/corpus/$h" \
    "${limit[@]}" -max_len=4096 -rss_limit_mb=2048 -timeout=10 \
    -artifact_prefix="$findings" -print_final_stats=1 >"$build/fuzz/$h.log" 2>&1
}
status=0
mkdir -p "$build/fuzz/findings"
for h in "${harnesses[@]}"; do
  echo "fuzz: $h (${limit[*]})" >&2
  findings="$build/fuzz/findings/$h-"
  [[ -n "$fresh" ]] && findings="$fresh/findings-$h-"
  if fuzz_one "$h" "$findings"; then
    grep -E "stat::number_of_executed_units|cov:" "$build/fuzz/$h.log" | tail -2 >&2 || true
    continue
  fi
  echo "fuzz: $h FAILED, see $build/fuzz/$h.log:" >&2
  tail -30 "$build/fuzz/$h.log" >&2
  if [[ -z "$fresh" ]]; then
    status=1
    continue
  fi
  # The test suite's run: a defect in a parser reproduces when its input is run alone; a machine
  # too loaded for the run's limits (a unit past -timeout, the RSS limit) or a sanitizer that could
  # not start may not. Either way the failing input is kept under <build>/fuzz/findings/.
  cp "$fresh"/findings-"$h"-* "$build/fuzz/findings/" 2>/dev/null || true
  reproduced=0
  found=0
  for input in "$fresh"/findings-"$h"-*; do
    [[ -f "$input" ]] || continue
    found=1
    if ! ASAN_OPTIONS=detect_leaks=1 "$build/tests/fuzz/fuzz_$h" -rss_limit_mb=2048 -timeout=60 "$input" \
        >"$build/fuzz/$h.rerun.log" 2>&1; then
      echo "fuzz: $h: the input $(basename "$input") fails again when run alone:" >&2
      tail -30 "$build/fuzz/$h.rerun.log" >&2
      reproduced=1
    fi
  done
  if (( ! found )); then
    # No input to blame: the same run again decides.
    if fuzz_one "$h" "$fresh/findings-$h-again-"; then
      echo "fuzz: $h: no failing input, and the same run passed again: counted as passed" >&2
    else
      tail -30 "$build/fuzz/$h.log" >&2
      reproduced=1
    fi
  elif (( ! reproduced )); then
    echo "fuzz: $h: its failing input passes when run alone (the machine's load?): counted as passed," \
      "the input kept in $build/fuzz/findings/" >&2
  fi
  (( reproduced )) && status=1
done
exit $status
