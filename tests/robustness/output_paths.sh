#!/usr/bin/env bash
# Outputs never destroy what they should not: an output naming the model, the data or another output is
# refused before any work (exit 64) and every file stays as it was; an output that is a FIFO (as a device
# or /dev/stdout would be) is written through and stays a FIFO instead of being replaced by a file; the
# standard output on a full device fails the run.
# Usage: output_paths.sh FRAC EXAMPLES_DIR WORK_DIR
set -u
frac=$1 examples=$2 work=$3
rm -rf "$work" && mkdir -p "$work/files" && cd "$work/files" || exit 1
failures=0
fail() { echo "FAIL: $*"; failures=$((failures + 1)); }
# refused EXPECTED_MESSAGE COMMAND...: exit 64, the message on stderr, and no file changed.
refused() {
    local message=$1
    shift
    local before
    before=$(md5sum ./* | sort)
    "$frac" "$@" > ../out.txt 2> ../err.txt
    local status=$?
    [ "$status" -eq 64 ] || fail "$*: exit $status, not 64 ($(cat ../err.txt))"
    grep -qF "$message" ../err.txt || fail "$*: no '$message' in: $(cat ../err.txt)"
    [ "$before" = "$(md5sum ./* | sort)" ] || fail "$*: files changed"
}

cp "$examples/fig6_carpet.frac" model.frac
printf 'x,y\n0,0\n0.25,0.5\n0.5,0.25\n0.75,0.75\n1,0\n' > data.csv
ln model.frac linked.frac

refused "cannot write 'model.frac': it would overwrite the input 'model.frac'" \
    compile model.frac -o m.o --header model.frac
refused "it would overwrite the input 'model.frac'" compile model.frac -o m.o --header linked.frac
refused "'m.o' is the file of two outputs ('m.o' too)" compile model.frac -o m.o --header m.o
refused "'./m.ll' is the file of two outputs ('m.ll' too)" compile model.frac -o m.so --emit-llvm --header ./m.ll
refused "it would overwrite the input 'data.csv'" fit data.csv -o data.csv
cp model.frac model.obj
refused "it would overwrite the input 'model.obj'" mesh model.obj -o model.obj
[ ! -e m.o ] && [ ! -e m.so ] && [ ! -e m.ll ] || fail "an output was written by a refused command"

# A FIFO named as the picture: its reader gets the PNG, and it is still a FIFO afterwards.
mkfifo picture.png
timeout 30 cat picture.png > received.png &
reader=$!
"$frac" render model.frac -o picture.png --depth 4 --size 64 > /dev/null 2> ../err.txt ||
    fail "render into a FIFO: $(cat ../err.txt)"
wait "$reader"
[ -p picture.png ] || fail "the FIFO was replaced"
[ "$(head -c 8 received.png | od -An -tx1 | tr -d ' \n')" = 89504e470d0a1a0a ] ||
    fail "the FIFO's reader got no PNG"

# The standard output on a full device: the lost output is an error, not a success.
if [ -w /dev/full ]; then
    "$frac" check model.frac --emit=lex > /dev/full 2> ../err.txt
    status=$?
    [ "$status" -eq 1 ] || fail "check > /dev/full: exit $status, not 1"
    grep -qF "cannot write the standard output: No space left on device" ../err.txt ||
        fail "check > /dev/full: $(cat ../err.txt)"
fi

[ "$failures" -eq 0 ] && echo "output paths: all checks passed"
exit $((failures > 0))
