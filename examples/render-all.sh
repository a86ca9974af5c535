#!/usr/bin/env bash
# Renders the paper's figures from the bundled examples: left the subdivision process, right the cover.
set -euo pipefail
frac=${1:?usage: render-all.sh FRAC OUTDIR}
out=${2:?usage: render-all.sh FRAC OUTDIR}
here=$(cd "$(dirname "$0")" && pwd)
mkdir -p "$out"
render() { # file shape depth
    "$frac" render "$here/$1" "$2" --depth "$3" --size 512 -o "$out/${1%.frac}.png"
    "$frac" render "$here/$1" "$2" --depth "$(( $3 < 8 ? $3 : 8 ))" -o "$out/${1%.frac}.svg"
}
render fig2_takagi.frac takagi_curve 12
render fig3_staircase.frac staircase_graph 10
render fig5_cantor.frac cantor_graph 10
render fig6_carpet.frac sierpinski_carpet 9
render fig7_triangle.frac sierpinski_triangle 9
echo
echo "pictures (left: recursive subdivision process, right: cover) are in $out:"
ls -1 "$out" | sed "s|^|  $out/|"
