#!/usr/bin/env bash
# The JIT's code cache from the command line (backend/llvm/code_cache.hpp): a first render stores the
# shape's code, a second loads it and writes the same picture; damaged entries give the same picture
# again and are replaced; FRAC_CACHE_DIR=off and a directory that cannot be made store nothing and say
# nothing. The renders compile first (--engine jit): the default engine compiles in the background and
# a render that ends first leaves without it (nothing stored, by design), so only the last render, on
# the filled cache, uses the default engine. Usage: jit_cache.sh FRAC MODEL WORKDIR
set -euo pipefail
frac=$1 model=$2 work=$3
rm -rf "$work" && mkdir -p "$work" && cd "$work"
fail() { echo "FAIL: $*" >&2; exit 1; }
render() { # CACHE OUTPUT [ENGINE]
    FRAC_CACHE_DIR=$1 "$frac" render "$model" --depth 8 --engine "${3:-jit}" -o "$2" > /dev/null 2> "$2.err" ||
        fail "render $2: $(cat "$2.err")"
    ! grep -qiE 'error|warning|note|cache' "$2.err" || fail "render $2 said: $(cat "$2.err")"
}
render "$work/cache" first.png
entries=$(ls cache | wc -l)
[ "$entries" -ge 1 ] || fail "no entry stored"
render "$work/cache" second.png
cmp -s first.png second.png || fail "the cached code drew another picture"
[ "$(ls cache | wc -l)" -eq "$entries" ] || fail "a second run stored new entries"
for f in cache/*; do printf 'garbage' | dd of="$f" bs=1 seek=100 conv=notrunc status=none; done
render "$work/cache" damaged.png
cmp -s first.png damaged.png || fail "damaged entries changed the picture"
! grep -q garbage cache/* || fail "a damaged entry was kept"
render "$work/cache" repaired.png
cmp -s first.png repaired.png || fail "replaced entries changed the picture"
render off off.png
cmp -s first.png off.png || fail "FRAC_CACHE_DIR=off drew another picture"
touch not_a_directory
render "$work/not_a_directory/cache" unusable.png
cmp -s first.png unusable.png || fail "an unusable cache directory changed the picture"
render "$work/cache" auto.png auto
cmp -s first.png auto.png || fail "the default engine drew another picture from the cache"
[ "$(ls cache | wc -l)" -eq "$entries" ] || fail "the default engine stored new entries"
echo "ok: $entries entries"
