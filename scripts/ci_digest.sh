#!/usr/bin/env bash
# What a failed CI stage leaves to read, in a few lines at the end of the run's output (which is
# often shown cut in the middle): each failed test's output from its first failure on (30 lines,
# the messages streamed into its assertions included), and a failed fuzzer's verdict and
# sanitizer summary.
# Usage: scripts/ci_digest.sh BUILD_DIR
set -uo pipefail
build=${1:?usage: scripts/ci_digest.sh BUILD_DIR}
failed="$build/Testing/Temporary/LastTestsFailed.log"
log="$build/Testing/Temporary/LastTest.log"
echo "ci: digest of $build"
[[ -f $failed ]] || { echo "ci: no failed test recorded (the build or the configure failed?)"; exit 0; }
while IFS=: read -r _ name; do
  echo "ci: FAILED $name"
  # The test's section of LastTest.log: its first failure lines.
  awk -v n="$name" '
    index($0, "Test: " n) == 1 || $0 ~ ("^[0-9]+/[0-9]+ Test: " n "$") { on = 1; next }
    on && /^[0-9]+\/[0-9]+ Test: / { exit }
    on && !shown && /Failure|ERROR|error:|Assertion|SUMMARY/ { shown = 1 }
    on && shown { print "ci:   " $0; if (++k == 30) exit }
  ' "$log"
done <"$failed"
if grep -q "fuzz_parsers" "$failed"; then
  for f in "$build"/fuzz/*.log; do
    [[ -f $f ]] || continue
    grep -hE "ERROR: |SUMMARY: |deadly signal|out-of-memory|Test unit written" "$f" | head -4 | sed "s|^|ci:   $(basename "$f"): |"
  done
fi
exit 0
