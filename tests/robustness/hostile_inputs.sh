#!/usr/bin/env bash
# A hostile catalogue: each input must give located diagnostics and exit 65 (a compile error), never a
# crash, an internal error (70) or a hang (a generous 20 s timeout catches hangs only; speed is measured
# in bench/, not here).
# Usage: hostile_inputs.sh FRAC WORK_DIR
set -u
frac=$1 work=$2
rm -rf "$work" && mkdir -p "$work" && cd "$work" || exit 1
failures=0
repeat() { head -c "$2" < /dev/zero | tr '\0' "$1"; } # CHAR COUNT

# name: the input file is NAME.frac
expect_error() {
    local name=$1 status
    timeout 20 "$frac" check "$name.frac" > "$name.out" 2> "$name.err"
    status=$?
    if [ $status -ne 65 ]; then
        echo "FAIL: $name: exit $status (want 65); stderr: $(head -c 300 "$name.err")"
        failures=$((failures + 1))
    elif ! grep -q "\.frac:[0-9]*:[0-9]*: error: " "$name.err"; then
        echo "FAIL: $name: no located error: $(head -c 300 "$name.err")"
        failures=$((failures + 1))
    fi
}

{ printf 'shape s(x, y) = '; repeat '(' 100000; printf x; repeat ')' 100000; printf ';\n'; } > parens_1e5.frac
{ printf 'shape s(x, y) = '; repeat '(' 1000000; printf x; repeat ')' 1000000; printf ';\n'; } > parens_1e6.frac
{ printf 'shape s(x, y) = '; repeat '-' 1000000; printf 'x;\n'; } > minus_1e6.frac
{ printf 'shape s(x, y) = x'; repeat '^' 300000 | sed 's/\^/^x/g'; printf ';\n'; } > power_chain_3e5.frac
{ printf 'shape s(x, y) = '; repeat 'f' 100000 | sed 's/f/f(/g'; printf x; repeat ')' 100000; printf ';\n'; } > calls_1e5.frac
{ printf 'shape s(x, y) = x + '; repeat 9 1000000; printf ';\nshape t(x, y) = 1e999999999 - x;\n'; } > huge_literal.frac
{ printf 'shape s(x, y) = x '; printf '\xff\xfe\xc3\x28 '; printf '+ y;\n'; } > invalid_utf8.frac
{ printf 'shape s(x, y) = x\0 + y;\n'; } > nul_byte.frac
head -c 100000 /dev/urandom > binary_garbage.frac
{ printf 'shape '; repeat a 1000000; printf '(x, y) = '; repeat b 1000000; printf ';\n'; } > identifier_1e6.frac
{ printf 'fn f(x) = g(x);\nfn g(x) = f(x);\nshape s(x, y) = f(x);\n'; } > mutual_recursion.frac
{ printf 'import "import_cycle_b.frac";\nshape s(x, y) = x;\n'; } > import_cycle.frac
{ printf 'import "import_cycle.frac";\nshape t(x, y) = y;\n'; } > import_cycle_b.frac
{ echo 'fn f0(x) = x * 0.5;'; for i in $(seq 1 30); do echo "fn f$i(x) = f$((i - 1))(x) + f$((i - 1))(x + 1);"; done; echo 'shape s(x, y) = f30(x) - y;'; } > inline_explosion.frac
{ printf 'import "/proc/self/mem";\nimport "/dev/urandom";\nshape s(x, y) = x;\n'; } > special_imports.frac

for f in *.frac; do
    [ "$f" = import_cycle_b.frac ] && continue
    expect_error "${f%.frac}"
done
[ $failures -eq 0 ] && echo "ok: every hostile input gave located errors"
exit $((failures > 0))
