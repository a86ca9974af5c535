#!/usr/bin/env bash
# Every ```frac block of a Markdown file is a model that compiles and runs (`frac run`: its print
# statements, then its tests, which must pass). A block opened with ```frac fragment is a piece of
# syntax, not a model, and is skipped. A ```text output block right after a frac block is what the
# model prints: `frac run`'s standard output must equal it.
# Usage: check_blocks.sh FRAC FILE.md
set -uo pipefail
frac=$1
doc=$2
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
# Split the document into numbered block files: N.frac (checked), N.out (expected output of N).
awk -v dir="$work" '
    BEGIN { n = 0; mode = "" }
    mode == "" && /^```frac fragment[ \t]*$/ { mode = "skip"; last = ""; next }
    mode == "" && /^```frac[ \t]*$/ { n++; mode = "frac"; file = dir "/" n ".frac"; printf "" > file; start[n] = NR + 1; next }
    mode == "" && /^```text output[ \t]*$/ { if (last == "frac") { mode = "out"; file = dir "/" n ".out"; printf "" > file } else { mode = "skip" } ; next }
    mode != "" && /^```[ \t]*$/ { last = (mode == "frac") ? "frac" : ""; mode = ""; next }
    mode == "frac" || mode == "out" { print > file; next }
    mode == "" && NF > 0 { last = "" }
    END { for (i = 1; i <= n; i++) print i, start[i] > (dir "/lines") }
' "$doc"
failed=0
checked=0
while read -r n line; do
    checked=$((checked + 1))
    model="$work/$n.frac"
    if ! "$frac" run "$model" > "$work/$n.actual" 2> "$work/$n.err"; then
        echo "$doc:$line: the frac block does not run:"
        sed "s|$model|$doc (block at line $line)|" "$work/$n.err"
        failed=$((failed + 1))
        continue
    fi
    if [ -f "$work/$n.out" ] && ! diff -u "$work/$n.out" "$work/$n.actual" > "$work/$n.diff"; then
        echo "$doc:$line: the frac block prints something else than the text says:"
        cat "$work/$n.diff"
        failed=$((failed + 1))
    fi
done < "$work/lines"
echo "$doc: $checked frac blocks, $failed failed"
[ "$checked" -gt 0 ] && [ "$failed" -eq 0 ]
