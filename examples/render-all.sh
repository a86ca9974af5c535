#!/usr/bin/env bash
# Renders the paper's figures from the bundled examples: left the subdivision process, right the cover.
set -euo pipefail
frac=${1:?usage: render-all.sh FRAC OUTDIR}
out=${2:?usage: render-all.sh FRAC OUTDIR}
here=$(cd "$(dirname "$0")" && pwd)
mkdir -p "$out"
render_as() { # file shape depth name
    "$frac" render "$here/$1" "$2" --depth "$3" --size 512 -o "$out/$4.png"
}
render() { # file shape depth
    "$frac" render "$here/$1" "$2" --depth "$3" --size 512 -o "$out/${1%.frac}.png"
    "$frac" render "$here/$1" "$2" --depth "$(( $3 < 8 ? $3 : 8 ))" -o "$out/${1%.frac}.svg"
}
render fig2_takagi.frac takagi_curve 12
render fig3_staircase.frac staircase_graph 10
for k in 0 1 2 3 4 5; do render_as fig4_cantor_levels.frac "cantor$k" 9 "fig4_cantor_C$k"; done
render fig5_cantor.frac cantor_graph 10
render fig6_carpet.frac sierpinski_carpet 9
render fig7_triangle.frac sierpinski_triangle 9
render_as fig9_koch_tiling.frac triangle_tiling 8 fig9_tiling
render_as fig9_koch_tiling.frac lattice_disks 8 fig9_disks
render_as fig8_stripes.frac stripe_triangles 8 fig8_stripes
render_as fig10_double_koch.frac single_flake 8 fig10_single_flake
render fig10_double_koch.frac double_flake 8
render_as fig11_koch_levels.frac flake0 8 fig11_flake0
render_as fig11_koch_levels.frac flake1 8 fig11_flake1
render_as fig11_koch_levels.frac flake2 8 fig11_flake2
render_as fig11_koch_levels.frac double0 8 fig11_double0
render_as fig11_koch_levels.frac double1 8 fig11_double1
render_as fig11_koch_levels.frac double2 8 fig11_double2
render_as fig12_lattice_plane.frac plane_lattice 8 fig12_lattice_plane
render fig13_koch_polar.frac koch_flake 9
render similitude_disks.frac turned_disks_direct 8
render_as rough_terrain.frac terrain_profile 9 rough_terrain_profile
"$frac" mesh "$here/rough_terrain.frac" terrain --depth 6 -o "$out/rough_terrain.stl"
# The 3D-printable example: an exact, watertight STL of the sponge in its collar (every face on the lattice).
"$frac" mesh "$here/menger_frame.frac" sponge_in_frame --depth 4 --split 3 -o "$out/menger_frame.stl"
# Automata of the standard library (examples/automata.frac): evaluation trees and chaos games.
automaton() { # name method depth-or-empty
    "$frac" render "$here/automata.frac" "$1" --method "$2" --depth "${3:-8}" --size 512 -o "$out/automaton_$1.$4"
}
automaton sierpinski tree 7 png
automaton koch_curve tree 6 svg
automaton quadratic_bspline tree 6 svg
automaton cubic_bspline tree 6 svg
automaton barnsley_fern chaos "" png
automaton fern_of_triangles chaos "" png
automaton penrose chaos "" png
# Seed 004's junctions of a cubic and a quadratic B-spline (examples/differential.frac, frac analyze):
# G1 (λ2 > 0), a spiral (complex λ2) and an oscillation (λ2 < 0) at the junction point.
for j in junction_g1 junction_spiral junction_oscillation; do
    "$frac" render "$here/differential.frac" "$j" --method tree --depth 10 -o "$out/$j.svg"
done
# Boundary controlled IFS (examples/bcifs.frac): constraints solved by the compiler, drawn by the chaos game.
for name in fractal_edge spiky_edge c1_edge quad_patch; do
    "$frac" render "$here/bcifs.frac" "$name" --method chaos --size 512 -o "$out/bcifs_$name.png"
done
# Fractal surfaces from bcifs: a patch with seeded facet entries, a closed cube of six rough faces.
"$frac" mesh "$here/bcifs.frac" rough_patch --depth 6 -o "$out/bcifs_rough_patch.obj"
# Solids of volume cells (seed 002 sec. 3.3): the arborescent condensation of Bezier blocks, watertight.
"$frac" mesh "$here/arborescent.frac" arborescent --depth 4 -o "$out/arborescent.stl"
"$frac" mesh "$here/bcifs.frac" rough_cube --depth 5 -o "$out/bcifs_rough_cube.stl"
# Junctions of curves built by different processes, solved from seed 004's constraints.
for j in spline_junction refined_junction fractal_junction; do
    "$frac" render "$here/junction.frac" "$j" --method tree --depth 10 -o "$out/$j.svg"
done
# Projected-IFS surfaces and curves (stdlib/ifs.frac): quad patches tessellated, a curve as a polyline.
"$frac" mesh "$here/automata.frac" bicubic_bspline_patch --depth 7 -o "$out/bicubic_bspline_patch.stl"
"$frac" mesh "$here/automata.frac" biquadratic_bezier_patch --depth 6 -o "$out/biquadratic_bezier_patch.obj"
"$frac" mesh "$here/automata.frac" cubic_bspline --depth 7 -o "$out/cubic_bspline_curve.svg"
echo
echo "pictures (left: recursive subdivision process, right: cover) and meshes are in $out:"
ls -1 "$out" | sed "s|^|  $out/|"
