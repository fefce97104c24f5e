#!/bin/sh
# tests/fuzz/run.sh: build the loader's libFuzzer target and fuzz it, or
# replay the regression inputs.
#
#   sh tests/fuzz/run.sh            fuzz for FUZZ_SECONDS (default 60) seconds
#   sh tests/fuzz/run.sh replay     run every tests/fuzz/regressions/* once (CI)
#
# Environment: FUZZ_BUILD (default build/fuzz) holds the binary, the corpus
# and any crash-* / leak-* / timeout-* / oom-* artifacts; FUZZ_SECONDS;
# FUZZ_JOBS (parallel fuzzing processes, default 1); CC_FUZZ (default clang);
# FUZZ_LIBS, libraries the library sources need beyond libyaml and KLU, and
# FUZZ_CFLAGS their headers (the Makefile passes SUNDIALS's for
# src/study/simulate.c, HDF5's for src/output/output_h5.c, MINPACK's for
# src/study/fit_lm.c).
# Exits non-zero when the target crashes, leaks, times out or runs out of
# memory on some input (libFuzzer writes it to FUZZ_BUILD/artifacts/).
# Run from the repository root; needs clang with libFuzzer (Debian: clang).
set -eu
mode=${1:-fuzz}
out=${FUZZ_BUILD:-build/fuzz}
seconds=${FUZZ_SECONDS:-60}
jobs=${FUZZ_JOBS:-1}
cc=${CC_FUZZ:-clang}
bin=$out/fuzz_load

command -v "$cc" >/dev/null || { echo "run.sh: $cc not found (Debian: apt-get install clang)" >&2; exit 2; }
mkdir -p "$out/corpus" "$out/artifacts"
lib_src=$(ls src/*/*.c | grep -v '^src/cli/')
# the runtime's text for mech codegen, as the Makefile makes it
awk -f tools/c_lines.awk $(sed -n 's/^RT_SRC *= *$(addprefix src\/runtime\/,\(.*\))$/\1/p' Makefile |
    tr ' ' '\n' | sed 's|^|src/runtime/|') >"$out/rt_text.c"
src_inc=$(for d in src/*/; do printf ' -I%s' "${d%/}"; done)
# -fno-sanitize-recover: an UBSan report stops the run and counts as a crash.
$cc -g -O1 -std=c11 -D_POSIX_C_SOURCE=200809L -pthread \
    -fsanitize=fuzzer,address,undefined -fno-sanitize-recover=all \
    -Iinclude $src_inc -I/usr/include/suitesparse ${FUZZ_CFLAGS:-} \
    $lib_src "$out/rt_text.c" tests/fuzz/fuzz_load.c -o "$bin" \
    -lyaml -lklu -lbtf -lamd -lcolamd -lsuitesparseconfig ${FUZZ_LIBS:-} -lm -pthread

# -rss_limit_mb: a file must not make the loader use gigabytes; -timeout: nor
# take seconds (the target solves only small mechanisms).
opts="-rss_limit_mb=2048 -timeout=10 -max_len=8192 -dict=tests/fuzz/yaml.dict"
export ASAN_OPTIONS=${ASAN_OPTIONS:-detect_leaks=1:allocator_may_return_null=1}
export UBSAN_OPTIONS=${UBSAN_OPTIONS:-print_stacktrace=1:halt_on_error=1}

regressions=$(ls tests/fuzz/regressions/* 2>/dev/null || true)
if [ "$mode" = replay ]; then
    [ -n "$regressions" ] || { echo "no regression inputs"; exit 0; }
    # Given files, libFuzzer runs each once and stops at the first failure.
    # shellcheck disable=SC2086
    "$bin" $opts $regressions
    echo "replayed $(echo "$regressions" | wc -l) regression inputs: ok"
    exit 0
fi

# Seed corpus: the examples, the malformed corpus, the solver cases, the
# drawn-form files and every input that once crashed.
for f in mechanisms/*.yaml tests/bad/*.yaml tests/solve/*.yaml tests/drawn/*.yaml tests/dynamics/*.yaml mechanisms/dynamics/*.yaml tests/programs/*.yaml tests/cams/*.yaml mechanisms/cams/*.yaml tests/fit/*.yaml $regressions; do
    [ -f "$f" ] && cp "$f" "$out/corpus/seed-$(basename "$f")"
done
# -fork=N runs N fuzzing processes; the first crash still stops the run.
par=
[ "$jobs" -gt 1 ] && par="-fork=$jobs"
# shellcheck disable=SC2086
"$bin" $opts $par -max_total_time="$seconds" -print_final_stats=1 \
    -artifact_prefix="$out/artifacts/" "$out/corpus"
