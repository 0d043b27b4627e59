#!/usr/bin/env bash
# Builds the libFuzzer harnesses (clang-14, ASan + UBSan, into build-fuzz/) and runs each for
# SECONDS: first every saved crash input under tests/fuzz/regressions/<harness>/ once, then
# fuzzing from the seeds in tests/fuzz/corpus/<harness>/ (the corpus grows in memory only: it
# would be thrown away, and writing a file per new input costs time). Prints one summary line
# per harness with its number of executions. A new crash, leak or timeout input is saved under
# tests/fuzz/regressions/<harness>/ and the script exits 1.
# The summary line gives libFuzzer's own count of executions (stat::number_of_executed_units,
# seeds included), the real time the run took, executions per second of it and per CPU-second
# (user + system time), and the machine's load average when the run began: on a shared machine
# the first follows the load, the second hardly. The request harnesses add a line with the
# libmodbus oracle's counts (tests/support/modbus_oracle.hpp): the frames libmodbus answered too
# (compared, compared-refused), and those it did not, by case.
#
#   scripts/fuzz.sh 20                      # every harness, 20 s each
#   scripts/fuzz.sh 600 fuzz_config         # one harness, ten minutes
#   build-fuzz/tests/fuzz/fuzz_config FILE  # replay one input
#
# Harnesses (docs/development.md, "Fuzzing", says what each covers): fuzz_tcp_request (a Modbus
# TCP byte stream into the dispatcher), fuzz_rtu_frame (RTU frames or serial chunks), fuzz_config
# (YAML text into the config loader), fuzz_config_tree (the same loader fed trees without the
# YAML library, then the PLC build and scans), fuzz_master_reply (replies a Modbus master gets),
# fuzz_fatek_frame (a FATEK TCP byte stream into the FATEK protocol), fuzz_http_request (an HTTP
# byte stream into the console and REST API), fuzz_listing (a program in a family's instruction
# list, built and scanned).
set -euo pipefail
TIMEFORMAT='%R %U %S'
cd "$(dirname "$0")/.."

readonly ALL=(fuzz_tcp_request fuzz_rtu_frame fuzz_config fuzz_config_tree fuzz_master_reply
    fuzz_fatek_frame fuzz_http_request fuzz_listing)
readonly BUILD=build-fuzz

usage() {
    echo "usage: scripts/fuzz.sh SECONDS [HARNESS...]   (harnesses: ${ALL[*]})" >&2
    exit 2
}
[[ $# -ge 1 && $1 =~ ^[0-9]+$ && $1 -gt 0 ]] || usage
readonly SECONDS_EACH=$1
shift
harnesses=("$@")
((${#harnesses[@]} > 0)) || harnesses=("${ALL[@]}")
for h in "${harnesses[@]}"; do
    [[ " ${ALL[*]} " == *" $h "* ]] || { echo "fuzz: unknown harness '$h'" >&2; usage; }
done

scripts/install-deps.sh fuzz
CC=clang-14 CXX=clang++-14 cmake -S . -B "$BUILD" -DPLCEMU_FUZZ=ON -DPLCEMU_TESTS=OFF \
    -DCMAKE_BUILD_TYPE=RelWithDebInfo >/dev/null
echo "fuzz: building ${harnesses[*]} in $BUILD/" >&2
nice -n 10 cmake --build "$BUILD" -j2 --target "${harnesses[@]}" >/dev/null

TMP=$(mktemp -d)
trap 'rm -rf "$TMP"' EXIT

# Stop at the first error of any kind; ASan's and UBSan's reports become libFuzzer crashes.
export ASAN_OPTIONS="${ASAN_OPTIONS:+$ASAN_OPTIONS:}detect_leaks=1"
export UBSAN_OPTIONS="${UBSAN_OPTIONS:+$UBSAN_OPTIONS:}print_stacktrace=1:halt_on_error=1"
# While fuzzing (not when replaying), two ASan settings that cost detection nothing an input can
# show, measured to save 5-25 % per input (docs/development.md, "Fuzzing"):
# - a 2 MB quarantine instead of 256 MB: a freed block stays poisoned while many times what
#   one input allocates (tens of kB) is allocated after it, so a use after free within an input
#   is caught all the same; the big one made every reused block cold and refaulted its pages
#   (nearly five page faults per input of fuzz_config_tree, one with 16 MB), and recycling a
#   16 MB one was still 5 % of a YAML input;
# - no allocation and free stacks in reports (malloc_context_size=0): unwinding and storing a
#   stack for every allocation was 5-10 % of an input's time. The report still shows where the
#   bad access is, and the script replays every input it saves with the full stacks.
readonly FUZZ_ASAN_OPTIONS="$ASAN_OPTIONS:quarantine_size_mb=2:malloc_context_size=0"

status=0
for h in "${harnesses[@]}"; do
    bin=$BUILD/tests/fuzz/$h
    regressions=tests/fuzz/regressions/$h
    log=$TMP/$h.log
    # fuzz_config_tree reads the keys and values fuzz_config reads, in its own syntax: its
    # dictionary is fuzz_config's and its own (libFuzzer takes one -dict).
    dicts=("tests/fuzz/$h.dict")
    [[ $h == fuzz_config_tree ]] && dicts=(tests/fuzz/fuzz_config.dict "${dicts[@]}")
    dict=()
    for d in "${dicts[@]}"; do [[ -f $d ]] && cat "$d" >>"$TMP/$h.dict"; done
    [[ -s $TMP/$h.dict ]] && dict=(-dict="$TMP/$h.dict")

    # Saved crash inputs first: each must now pass.
    mapfile -t saved < <(find "$regressions" -type f 2>/dev/null | sort)
    if ((${#saved[@]} > 0)); then
        if ! "$bin" -runs=0 "${saved[@]}" >"$log" 2>&1; then
            tail -n 40 "$log" >&2
            echo "fuzz: $h: a regression input under $regressions fails again" >&2
            status=1
            continue
        fi
    fi

    mkdir -p "$TMP/$h/artifacts"
    seeds=()
    find tests/fuzz/corpus/"$h" -type f 2>/dev/null | sort | paste -sd, >"$TMP/$h.seeds"
    [[ -s $TMP/$h.seeds ]] && seeds=(-seed_inputs=@"$TMP/$h.seeds")
    # The YAML library's parse costs 0.15 µs or more per byte under ASan: the YAML harness gets
    # shorter inputs, room for every YAML construct and a small config (the tree harness fuzzes
    # the loader with configs of any length).
    max_len=()
    [[ $h == fuzz_config ]] && max_len=(-max_len=256)
    # The request harnesses' inputs hold the largest frame (a 260-byte TCP ADU, a 256-byte RTU
    # frame in its records) or a few dozen small ones. libFuzzer's default, 4096 bytes, let them
    # grow to hundreds of frames and scans each, every input slower as the corpus grew
    # (docs/development.md, "Speed").
    [[ $h == fuzz_tcp_request || $h == fuzz_rtu_frame ]] && max_len=(-max_len=264)
    # The FATEK harness: room for two of its largest frames (508 bytes each).
    [[ $h == fuzz_fatek_frame ]] && max_len=(-max_len=1024)
    # The HTTP harness: a few requests with small JSON bodies (the limits are tested elsewhere).
    [[ $h == fuzz_http_request ]] && max_len=(-max_len=2048)
    # The listing harness: a few dozen statements; each input builds a PLC.
    [[ $h == fuzz_listing ]] && max_len=(-max_len=1024)
    rc=0
    read -r load _ </proc/loadavg
    # -verbosity=0: no status line per new input (unbuffered, each a few write calls); crash
    # reports and the final statistics are printed all the same.
    # bash's `time` gives the run's real and CPU seconds (user + system) in $TMP/$h.time.
    { time ASAN_OPTIONS=$FUZZ_ASAN_OPTIONS nice -n 10 "$bin" -max_total_time="$SECONDS_EACH" \
        -print_final_stats=1 -timeout=10 -verbosity=0 -artifact_prefix="$TMP/$h/artifacts/" \
        "${max_len[@]}" "${dict[@]}" "${seeds[@]}" >"$log" 2>&1 || rc=$?; } 2>"$TMP/$h.time"
    read -r real user sys <"$TMP/$h.time"
    execs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$log" | tail -n 1)
    added=$(sed -n 's/^stat::new_units_added: *//p' "$log" | tail -n 1)
    runs=$(awk -v n="${execs:-0}" -v t="$real" -v u="$user" -v s="$sys" -v l="$load" 'BEGIN {
        c = u + s
        printf "%d executions in %.1f s = %d/s (%d per CPU-second; load %s)",
            n, t, (t > 0 ? n / t : 0), (c > 0 ? n / c : 0), l }')
    mapfile -t found < <(find "$TMP/$h/artifacts" -type f | sort)
    if ((rc == 0 && ${#found[@]} == 0)); then
        echo "fuzz: $h: $runs, ${added:-?} new inputs, ${#saved[@]} regression inputs" \
            "replayed, no crash"
        # The request harnesses: frames libmodbus answered too, and those it did not, by case
        # (docs/testing.md, "Where the PLC differs from libmodbus on purpose").
        oracle=$(sed -n 's/^oracle: \([a-z0-9-]*\): \([0-9]*\) .*/\1 \2/p' "$log" | paste -sd,)
        [[ -n $oracle ]] && echo "fuzz: $h: libmodbus oracle, frames: ${oracle//,/, }"
        continue
    fi
    status=1
    tail -n 60 "$log" >&2
    mkdir -p "$regressions"
    for f in "${found[@]}"; do
        cp "$f" "$regressions/"
        echo "fuzz: $h: saved $regressions/$(basename "$f"); its replay, with full stacks:" >&2
        "$bin" -timeout=10 "$regressions/$(basename "$f")" 2>&1 | tail -n 60 >&2 || true
    done
    echo "fuzz: $h: $runs, FAILED (exit $rc," \
        "${#found[@]} input(s) saved under $regressions)"
done
exit "$status"
