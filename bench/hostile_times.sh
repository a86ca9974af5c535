#!/usr/bin/env bash
# Times `frac check` on each input of the hostile catalogue (tests/robustness/hostile_catalogue.sh): the
# median wall and CPU (user + system) seconds of RUNS runs, its exit status and peak memory (on a shared
# machine the CPU time is the steadier figure). Every input must be refused in well
# under a second (issue 14); tests/robustness/hostile_inputs.sh checks the messages, not the times.
# Usage: bench/hostile_times.sh FRAC [RUNS]
set -u
frac=$(realpath "$1") runs=${2:-3} here=$(cd "$(dirname "$0")" && pwd)
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
. "$here/../tests/robustness/hostile_catalogue.sh"
cd "$work" && make_hostile_catalogue
median() { printf '%s\n' "$@" | sort -n | sed -n "$((($# + 1) / 2))p"; }
printf '%-18s %8s %8s %5s %8s\n' input wall cpu exit "max MiB"
for f in *.frac; do
    [ "$f" = import_cycle_b.frac ] && continue
    walls=() cpus=() status=0 kib=0
    for _ in $(seq "$runs"); do
        /usr/bin/time -f '%e %U %S %M' -o time.txt timeout 20 "$frac" check "$f" > /dev/null 2>&1
        status=$?
        read -r wall user sys k < <(tail -n 1 time.txt)
        walls+=("$wall") cpus+=("$(awk "BEGIN { print $user + $sys }")") kib=$k
    done
    printf '%-18s %8s %8s %5s %8d\n' "${f%.frac}" "$(median "${walls[@]}")" "$(median "${cpus[@]}")" "$status" \
        $((kib / 1024))
done
echo "load: $(uptime | sed 's/.*load average: //')"
