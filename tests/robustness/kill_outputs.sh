#!/usr/bin/env bash
# Outputs are atomic: frac render, mesh and compile killed (SIGKILL) at random moments leave at each
# output path either the old complete file or a complete new one, no temporary file beside it once the
# process is gone (its cleaner removes a name killed between creation and rename), and (for compile) no
# temporary directory. The verdict does not depend on when the kill lands; the moments only
# vary which phase (compiling, subdividing, writing) is interrupted.
# Usage: kill_outputs.sh FRAC EXAMPLES_DIR WORK_DIR [RUNS]
set -u
frac=$1 examples=$2 work=$3 runs=${4:-4}
rm -rf "$work" && mkdir -p "$work/out" "$work/tmp" || exit 1
export TMPDIR=$work/tmp
cd "$work/out" || exit 1
failures=0
fail() { echo "FAIL: $*"; failures=$((failures + 1)); }

# Completeness of each format, from its own structure.
complete() {
    local f=$1 size
    size=$(stat -c %s "$f")
    case $f in
    *.png) # the signature first and the IEND chunk last
        [ "$(head -c 8 "$f" | od -An -tx1 | tr -d ' \n')" = 89504e470d0a1a0a ] &&
            [ "$(tail -c 12 "$f" | od -An -tx1 | tr -d ' \n')" = 0000000049454e44ae426082 ] ;;
    *.svg) [ "$(tail -c 7 "$f")" = "</svg>" ] || [ "$(tail -n 1 "$f")" = "</svg>" ] ;;
    *.stl) # 84-byte header and count, then 50 bytes a triangle
        local n
        n=$(od -An -tu4 -j80 -N4 "$f" | tr -d ' ')
        [ "$size" -eq $((84 + 50 * n)) ] ;;
    *.so) # ELF, and the section header table (written last by the linker) ends the file
        local shoff shentsize shnum
        [ "$(head -c 4 "$f" | od -An -tx1 | tr -d ' ')" = 7f454c46 ] || return 1
        shoff=$(od -An -tu8 -j40 -N8 "$f" | tr -d ' ')
        shentsize=$(od -An -tu2 -j58 -N2 "$f" | tr -d ' ')
        shnum=$(od -An -tu2 -j60 -N2 "$f" | tr -d ' ')
        [ "$size" -eq $((shoff + shentsize * shnum)) ] ;;
    *.h) tail -n 1 "$f" | grep -q '^#endif' ;;
    *) return 1 ;;
    esac
}

# Runs `frac ARGS` to completion; it must succeed.
run_ok() { "$frac" "$@" > /dev/null 2>&1 || fail "frac $* failed"; }

# Kills `frac ARGS` after a random delay below LIMIT_MS, RUNS times; each output must then be complete and
# be the old file or (where the format is reproducible, REF given) the new one, with nothing left beside.
# Usage: trial LIMIT_MS "OUT:OLD:REF ..." ARGS...
trial() {
    local limit=$1 outputs=$2
    shift 2
    local i spec out old ref pid delay waited
    for ((i = 0; i < runs; i++)); do
        for spec in $outputs; do
            IFS=: read -r out old ref <<< "$spec"
            cp "$old" "$out"
        done
        "$frac" "$@" > /dev/null 2>&1 &
        pid=$!
        delay=$((RANDOM % limit))
        sleep "$(printf '0.%03d' "$delay")"
        kill -KILL "$pid" 2> /dev/null
        wait "$pid" 2> /dev/null
        for spec in $outputs; do
            IFS=: read -r out old ref <<< "$spec"
            if [ ! -f "$out" ]; then
                fail "$*: killed after ${delay} ms: $out is gone"
            elif ! complete "$out"; then
                fail "$*: killed after ${delay} ms: $out is not complete"
            elif ! cmp -s "$out" "$old" && [ -n "$ref" ] && ! cmp -s "$out" "$ref"; then
                fail "$*: killed after ${delay} ms: $out is neither the old file nor the new one"
            fi
        done
        # Only the outputs, the old files and the references: no temporary beside them. A temporary has a
        # name only for the span of a few system calls; one killed there is removed by the process's
        # cleaner once the process is gone, as the compile's directory is once the process and its tools are.
        for ((waited = 0; waited < 100; waited++)); do
            stray=$(find . -name '.*' -type f)
            [ -z "$stray" ] && [ -z "$(ls -A "$TMPDIR")" ] && break
            sleep 0.1
        done
        [ -z "$stray" ] || fail "$*: killed after ${delay} ms: temporaries left: $stray"
        [ -z "$(ls -A "$TMPDIR")" ] || fail "$*: killed after ${delay} ms: left in TMPDIR: $(ls -A "$TMPDIR")"
    done
}

carpet=$examples/fig6_carpet.frac
menger=$examples/menger_frame.frac
# Old files (another depth) and reproducible new ones.
run_ok render "$carpet" -o old.png --depth 4
run_ok render "$carpet" -o new.png --depth 10 --size 2048
run_ok render "$carpet" -o old.svg --depth 4
run_ok render "$carpet" -o new.svg --depth 9
run_ok mesh "$menger" -o old.stl --depth 4
run_ok mesh "$menger" -o new.stl --depth 7
run_ok compile "$carpet" -o old.so --header old.h
for f in old.png new.png old.svg new.svg old.stl new.stl old.so old.h; do
    complete "$f" || fail "the reference $f is not complete"
done

trial 700 "out.png:old.png:new.png" render "$carpet" -o out.png --depth 10 --size 2048
trial 900 "out.svg:old.svg:new.svg" render "$carpet" -o out.svg --depth 9
trial 600 "out.stl:old.stl:new.stl" mesh "$menger" -o out.stl --depth 7
trial 900 "out.so:old.so: out.h:old.h:" compile "$carpet" -o out.so --header out.h

# A complete run still replaces the old files.
run_ok render "$carpet" -o out.svg --depth 9
cmp -s out.svg new.svg || fail "a complete render did not write the new picture"
[ $failures -eq 0 ] && echo "ok: every killed run left old or new complete outputs and no temporaries"
exit $((failures > 0))
