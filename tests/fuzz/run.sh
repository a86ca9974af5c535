#!/usr/bin/env bash
# Runs each libFuzzer target for SECONDS: fuzz_frontend from a seed corpus of every .frac under tests/lang
# and stdlib, fuzz_eval from its own corpus. A crash, a hang (> 2 s) or an internal error is written to
# BUILD/findings/ and fails the run; the last lines of each log give executions and coverage.
# Usage: run.sh BUILD SECONDS
set -u
build=$1 seconds=$2
root=$(cd "$(dirname "$0")/../.." && pwd)
mkdir -p "$build/corpus/frontend" "$build/corpus/eval" "$build/findings" "$build/seeds"
n=0
while IFS= read -r f; do # numbered: files of one name live in several directories
    cp "$f" "$build/seeds/$n.frac"
    n=$((n + 1))
done < <(find "$root/tests/lang" "$root/stdlib" -name '*.frac' -size -64k)
status=0
for target in fuzz_frontend fuzz_eval; do
    corpus=$build/corpus/${target#fuzz_}
    # The frontend from the models; the evaluators' inputs are a few dozen choices, at full length at once,
    # each compiled by the JIT (a second or more under ASan on a busy machine: 10 s before a hang).
    args=(-len_control=0 -max_len=256 -timeout=10)
    [ "$target" = fuzz_frontend ] && args=("$build/seeds" -max_len=8192 -timeout=2)
    echo "== $target, $seconds s"
    "$build/tests/fuzz/$target" "$corpus" "${args[@]}" -max_total_time="$seconds" \
        -rss_limit_mb=4096 -print_final_stats=1 -artifact_prefix="$build/findings/$target-" \
        > "$build/$target.log" 2>&1 || status=1
    grep -E "^#[0-9]+.*(DONE|cov:)" "$build/$target.log" | tail -1
    grep -E "stat::number_of_executed_units|stat::peak_rss_mb" "$build/$target.log"
done
ls "$build/findings"
exit $status
