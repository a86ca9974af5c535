#!/usr/bin/env bash
# A hostile catalogue: each input must give a located diagnostic with the message expected of it and exit
# 65 (a compile error), never a crash, an internal error (70) or a hang, and a bounded stderr (an error
# on a 10^6-character token quotes an excerpt). A generous 20 s timeout catches hangs only; the time of
# each input is measured by bench/hostile_times.sh, not here (the two runs at the limits get 60 s: a sanitizer
# build takes 20 s there).
# Usage: hostile_inputs.sh FRAC WORK_DIR
set -u
frac=$(realpath "$1") work=$2 here=$(cd "$(dirname "$0")" && pwd)
rm -rf "$work" && mkdir -p "$work" && cd "$work" || exit 1
failures=0
repeat() { head -c "$2" < /dev/zero | tr '\0' "$1"; } # CHAR COUNT
fail() { echo "FAIL: $*"; failures=$((failures + 1)); }

# NAME MESSAGE: NAME.frac gives exit 65 and a located error "FILE.frac:LINE:COL: error: ...MESSAGE...".
expect_error() {
    local name=$1 message=$2 status
    timeout 20 "$frac" check "$name.frac" > "$name.out" 2> "$name.err"
    status=$?
    if [ $status -ne 65 ]; then
        fail "$name: exit $status (want 65); stderr: $(head -c 300 "$name.err")"
    elif ! grep -q "\.frac:[0-9]*:[0-9]*: error: .*$message" "$name.err"; then
        fail "$name: no located error with '$message': $(head -c 300 "$name.err")"
    elif [ "$(stat -c %s "$name.err")" -gt 20000 ]; then
        fail "$name: $(stat -c %s "$name.err") bytes of stderr (an excerpt of the input is expected)"
    fi
}

# The catalogue (bench/hostile_times.sh times the same files).
. "$here/hostile_catalogue.sh"
make_hostile_catalogue || exit 1

expect_error parens_1e5 "expression nested deeper than the limit of 200 levels"
expect_error parens_1e6 "expression nested deeper than the limit of 200 levels"
expect_error minus_1e6 "expression nested deeper than the limit of 200 levels"
expect_error not_1e6 "expression nested deeper than the limit of 200 levels"
expect_error let_1e5 "expression nested deeper than the limit of 200 levels"
expect_error calls_1e5 "expression nested deeper than the limit of 200 levels"
expect_error power_chain_3e5 "expression nested deeper than the limit of 200 levels"
expect_error plus_chain_1e6 "more than the limit of 200000 operators"
expect_error field_chain_1e6 "more than the limit of 200000 operators"
expect_error huge_literal "is too large"
expect_error invalid_utf8 "unexpected character"
expect_error nul_byte "unexpected character"
expect_error binary_garbage ""
expect_error identifier_1e6 "unknown name 'bbbbbbbb"
expect_error mutual_recursion "recursive"
expect_error import_cycle "import cycle: import_cycle.frac imports import_cycle_b.frac imports import_cycle.frac"
expect_error inline_explosion "more than the limit of 2000000"
expect_error special_imports "cannot read '/proc/self/mem': read error"
expect_error import_dev_zero "cannot import '/dev/zero': not a regular file"
expect_error import_directory "is a directory"
expect_error fif_data_1e5 "a fif of more than 10000 pieces"
expect_error fif_arcs_1e8 "more than the limit of 100000 arcs"
expect_error pfif_pieces_1e4 "a fif of 10001 pieces is more than the limit of 10000"
expect_error pfif_endless "cut its graph into more than 10000 intervals, or at ends of more than 1024 bits: it is no finite automaton"

# At the limits, evaluated: a sum of 200,000 terms (one function LLVM would take hours and gigabytes to
# compile) is interpreted, never a blow-up.
timeout 60 "$frac" eval plus_chain_2e5.frac s --at 0.5,0 > plus_chain_2e5.out 2> plus_chain_2e5.err
status=$?
if [ $status -ne 0 ]; then
    fail "plus_chain_2e5: eval exit $status (want 0); stderr: $(head -c 300 plus_chain_2e5.err)"
elif ! grep -q "^s = 100000$" plus_chain_2e5.out; then
    fail "plus_chain_2e5: eval printed $(head -c 300 plus_chain_2e5.out) (want s = 100000)"
fi
# ... and refused, with its limit, where it would be compiled ahead of time.
timeout 60 "$frac" compile plus_chain_2e5.frac -o plus_chain_2e5.o > /dev/null 2> plus_chain_2e5.compile.err
status=$?
if [ $status -ne 1 ] || ! grep -q "more than the limit of 20000 for compiled code" plus_chain_2e5.compile.err; then
    fail "plus_chain_2e5: compile exit $status (want 1 and the limit); stderr: $(head -c 300 plus_chain_2e5.compile.err)"
fi
[ $failures -eq 0 ] && echo "ok: every hostile input gave its located error"
exit $((failures > 0))
