#!/usr/bin/env bash
# Wall time of whole `frac render` runs under each engine: auto (the command line's default: the
# interpreter while the JIT compiles, backend/llvm/tiered.hpp), jit (compiled first) and interp, on
# small and large jobs, with the JIT's code cache off (every run compiles) and warm. Runs are
# interleaved (auto, jit, interp, auto, ...) and the median of RUNS is printed with the ratios to the
# interpreter: the default engine must never be slower than the interpreter alone (issue 13).
# Usage: bench/engine_wall.sh FRAC [RUNS]   (ONLY=REGEX runs the jobs whose names match)
set -u
frac=$(realpath "$1") runs=${2:-5} here=$(cd "$(dirname "$0")/.." && pwd)
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
median() { printf '%s\n' "$@" | sort -n | sed -n "$((($# + 1) / 2))p"; }
now() { date +%s.%N; }

jobs=(
    "carpet d4|examples/fig6_carpet.frac --depth 4"
    "carpet d8|examples/fig6_carpet.frac --depth 8"
    "carpet d10|examples/fig6_carpet.frac --depth 10"
    "cantor d10|examples/fig5_cantor.frac --depth 10"
    "koch d9|examples/fig9_koch_tiling.frac --depth 9"
    "menger d5|examples/menger_frame.frac --depth 5"
    "terrain d5|examples/rough_terrain.frac --depth 5"
    "gyroid d7|bench/kernel_scenes.frac gyroid_sphere --depth 7 --slice z=0.1"
    "sum3000 d15|$work/long_sum.frac --depth 15"
    "sum3000 d17|$work/long_sum.frac --depth 17"
)
# A long tape (12,373 instructions: the mean of 3,000 distances, nothing to prune): the default engine
# compiles it only once the interpreted work a cover foresees to its depth is three times what the compile will
# take, or at once from a warm cache (driver/engines.cpp).
awk 'BEGIN {
    printf "shape s(x, y) over [-1, 1] * [-1, 1] = (";
    for (i = 0; i < 3000; ++i)
        printf "%ssqrt((x - %.4f)^2 + (y - %.4f)^2 + 0.01)", i ? " + " : "", (i % 97) / 97, (i % 89) / 89;
    printf ") / 3000 - 0.75;\n";
}' > "$work/long_sum.frac"
printf '%-12s %-5s %9s %9s %9s %10s %10s\n' job cache auto_s jit_s interp_s auto/interp jit/interp
for cache in off warm; do
    for job in "${jobs[@]}"; do
        name=${job%%|*} args=${job#*|}
        [[ "$name" =~ ${ONLY:-.} ]] || continue
        declare -A t=([auto]="" [jit]="" [interp]="")
        if [ "$cache" = off ]; then export FRAC_CACHE_DIR=off; else export FRAC_CACHE_DIR="$work/cache"; fi
        # The warm cache is filled by one run first (the other engines do not use it).
        [ "$cache" = warm ] && (cd "$here" && "$frac" render $args --engine jit -o "$work/x.png" > /dev/null 2>&1)
        for _ in $(seq "$runs"); do
            for engine in auto jit interp; do
                start=$(now)
                (cd "$here" && "$frac" render $args --engine $engine -o "$work/$engine.png" > /dev/null 2>&1) ||
                    { echo "frac render $args --engine $engine failed" >&2; exit 1; }
                t[$engine]+="$(awk "BEGIN { print $(now) - $start }") "
            done
        done
        a=$(median ${t[auto]}) j=$(median ${t[jit]}) i=$(median ${t[interp]})
        printf '%-12s %-5s %9.3f %9.3f %9.3f %9.2fx %9.2fx\n' "$name" "$cache" "$a" "$j" "$i" \
            "$(awk "BEGIN { print $a / $i }")" "$(awk "BEGIN { print $j / $i }")"
    done
done
echo "load: $(uptime | sed 's/.*load average: //')"
