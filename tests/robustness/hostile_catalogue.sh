# The hostile catalogue, written into the current directory by make_hostile_catalogue: one NAME.frac per
# input (import_cycle_b.frac is imported by import_cycle.frac, not checked on its own). Sourced by
# tests/robustness/hostile_inputs.sh (the verdicts) and bench/hostile_times.sh (the times).
make_hostile_catalogue() {
    repeat() { head -c "$2" < /dev/zero | tr '\0' "$1"; } # CHAR COUNT
    { printf 'shape s(x, y) = '; repeat '(' 100000; printf x; repeat ')' 100000; printf ';\n'; } > parens_1e5.frac
    { printf 'shape s(x, y) = '; repeat '(' 1000000; printf x; repeat ')' 1000000; printf ';\n'; } > parens_1e6.frac
    { printf 'shape s(x, y) = '; repeat '-' 1000000; printf 'x;\n'; } > minus_1e6.frac
    { printf 'shape s(x, y) = if '; repeat '!' 1000000 | sed 's/!/not /g'; printf 'x < y then x else y;\n'; } > not_1e6.frac
    { printf 'shape s(x, y) = '; repeat '!' 100000 | sed 's/!/let a = x in /g'; printf 'a;\n'; } > let_1e5.frac
    { printf 'shape s(x, y) = '; repeat 'f' 100000 | sed 's/f/f(/g'; printf x; repeat ')' 100000; printf ';\n'; } > calls_1e5.frac
    { printf 'shape s(x, y) = x'; repeat '^' 300000 | sed 's/\^/^x/g'; printf ';\n'; } > power_chain_3e5.frac
    { printf 'shape s(x, y) = x'; repeat '+' 1000000 | sed 's/+/ + x/g'; printf ';\n'; } > plus_chain_1e6.frac
    # Within the limits (199,999 operators): compiled and evaluated, not refused.
    { printf 'shape s(x, y) = x'; repeat '+' 199999 | sed 's/+/ + x/g'; printf ';\n'; } > plus_chain_2e5.frac
    { printf 'shape s(x, y) = x'; repeat '.' 1000000 | sed 's/\./.x/g'; printf ';\n'; } > field_chain_1e6.frac
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
    { printf 'import "/dev/zero";\nshape s(x, y) = x;\n'; } > import_dev_zero.frac
    seq 0 100000 | sed 's/.*/&,0.5/' > fif_rows_1e5.csv
    { printf 'fif big { data "fif_rows_1e5.csv"; scale 0.5; }\n'; } > fif_data_1e5.frac
    { printf 'fif wide { points (0, 0)'; seq 1 10000 | sed 's/.*/, (&, 1)/' | tr -d '\n'
      printf '; scale 0.5; domains '; seq 1 10000 | sed 's/.*/(0, 10000)/' | paste -sd, - | tr -d '\n'
      printf ';}\n'; } > fif_arcs_1e8.frac
    { printf 'import "/tmp";\nshape s(x, y) = x;\n'; } > import_directory.frac
    { printf 'fif many {\n'; seq 0 10000 | sed 's|.*|piece [0, 1] [[1/10001, 0, &/10001], [0, 0.5, 0], [0, 0, 1]];|'
      printf '}\n'; } > pfif_pieces_1e4.frac
    # A PFIF whose cuts never close up (ratios 999999/1000000 and 999998/1000000): the interval closure
    # runs into its limit with ever longer rationals.
    { printf 'fif endless {\n piece [0, 500000/999999] [[999999/1000000, 0, 0], [0, 0.5, 0], [0, 0, 1]];\n'
      printf ' piece [1/7, 1/7 + 500000/999998] [[999998/1000000, 0, 1/2 - 999998/1000000 / 7], [0, 0.5, 0], [0, 0, 1]];\n}\n'; } > pfif_endless.frac
}
