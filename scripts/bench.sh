#!/usr/bin/env bash
# Benchmarks. Builds Release into build-bench/, runs the closed-loop load client against plcemud
# and three yardsticks (noop: a do-nothing epoll server; libmodbus: a plain libmodbus select()
# server; pymodbus: pymodbus' asyncio server) and prints one `name value unit` line per figure on
# stdout. Lines starting with `#` are notes; build output goes to stderr. It reports speed and
# never fails on it.
#
# plcemud, noop and libmodbus are compared in alternating rounds (plcemud noop libmodbus,
# plcemud noop libmodbus, ...) at 1 and 16 connections, so that a change in the machine's load
# falls on every server alike; each figure is the median of the rounds with its min and max, and
# the ratios are ratios of medians.
#
#   scripts/bench.sh                     # 5 s per run after a 1 s warm-up
#   BENCH_SECONDS=2 scripts/bench.sh     # shorter runs (BENCH_WARMUP sets the warm-up)
#   BENCH_ROUNDS=6 scripts/bench.sh      # rounds of the alternating comparison (4 by default)
#   BENCH_PLCS=5000 scripts/bench.sh     # the many-PLC run with 5000 PLCs as well as 500
#   BENCH_ONLY=many_plcs scripts/bench.sh   # one hook alone (engine, plcemud, servers, fatek,
#                                           # console, scan_lateness, rtu_turnaround, many_plcs,
#                                           # stepping)
set -euo pipefail

cd "$(dirname "$0")/.."

readonly RUN_SECONDS="${BENCH_SECONDS:-5}"
readonly WARMUP_SECONDS="${BENCH_WARMUP:-1}"
readonly BUILD=build-bench
readonly CONNECTIONS=(1 4 16)
readonly ROUNDS="${BENCH_ROUNDS:-4}"
# Debian's interpreter: the one on PATH may lack python3-pymodbus.
readonly PY=/usr/bin/python3

declare -A FIG=()  # figure name -> value, for the ratio lines
BUILD_OK=0         # 1 when the whole tree built, so plcemud and bench_engine are current
SERVER_PID=""
TMP=$(mktemp -d)
trap 'stop_server; rm -rf "$TMP"' EXIT

note() { echo "# $*"; }

# Prints `name value unit` lines from stdin and remembers each value under its name.
emit() {
    local name value unit
    while read -r name value unit; do
        echo "$name $value $unit"
        FIG[$name]=$value
    done
}

install_packages() {
    # One list of what each job needs, kept by the install script (pymodbus needs
    # python3-serial-asyncio besides, which Debian only recommends).
    scripts/install-deps.sh bench >&2
}

build() {
    # The unit tests are not needed to benchmark, and building them would double the build.
    local src=. options=(-DPLCEMU_BENCH=ON -DPLCEMU_TESTS=OFF -DCMAKE_BUILD_TYPE=Release)
    if [[ ! -f CMakeLists.txt ]]; then
        note "no top-level CMakeLists.txt: building the bench tools alone"
        src=bench
        options=(-DCMAKE_BUILD_TYPE=Release)
    fi
    # cmake refuses a build directory configured from another source tree.
    if [[ -f $BUILD/CMakeCache.txt ]] &&
        ! grep -qx "CMAKE_HOME_DIRECTORY:INTERNAL=$(cd "$src" && pwd)" "$BUILD/CMakeCache.txt"; then
        rm -rf "$BUILD"
    fi
    cmake -S "$src" -B "$BUILD" "${options[@]}" >&2
    if cmake --build "$BUILD" -j2 >&2; then
        BUILD_OK=1
    else
        # Still measure the yardsticks; a stale plcemud would give misleading figures.
        note "full build failed (see stderr): plcemud and bench_engine are skipped"
        cmake --build "$BUILD" -j2 --target load_client noop_server libmodbus_peer >&2
    fi
}

free_port() {
    "$PY" -c 'import socket
s = socket.socket()
s.bind(("127.0.0.1", 0))
print(s.getsockname()[1])'
}

# A child that has exited stays a zombie until waited for, so kill -0 alone would say alive.
alive() { [[ -r /proc/$1/status ]] && ! grep -qs '^State:[[:space:]]*Z' "/proc/$1/status"; }

# start_server NAME PORT COMMAND...: runs COMMAND in the background, logging to a temp file, and
# waits until it accepts connections on PORT.
start_server() {
    local name=$1 port=$2
    shift 2
    "$@" >"$TMP/$name.log" 2>&1 &
    SERVER_PID=$!
    for _ in $(seq "${START_TRIES:-200}"); do
        alive "$SERVER_PID" || break
        if (exec 3<>"/dev/tcp/127.0.0.1/$port") 2>/dev/null; then return 0; fi
        sleep 0.05
    done
    note "$name did not accept connections on port $port; skipped. Its log:"
    sed 's/^/#   /' "$TMP/$name.log"
    stop_server
    return 1
}

stop_server() {
    [[ -n $SERVER_PID ]] || return 0
    kill "$SERVER_PID" 2>/dev/null || true
    for _ in $(seq "${STOP_TRIES:-50}"); do
        alive "$SERVER_PID" || break
        sleep 0.1
    done
    kill -KILL "$SERVER_PID" 2>/dev/null || true
    wait "$SERVER_PID" 2>/dev/null || true
    SERVER_PID=""
}

# bench_server NAME PORT COMMAND...: the load runs against one server, then its peak RSS.
bench_server() {
    local name=$1 port=$2 c out
    start_server "$@" || return 0
    for c in "${CONNECTIONS[@]}"; do
        if out=$("$BUILD/load_client" --port "$port" --connections "$c" \
            --seconds "$RUN_SECONDS" --warmup "$WARMUP_SECONDS" --label "$name.c$c"); then
            emit <<<"$out"
        else
            note "$name.c$c: load_client could not connect"
        fi
    done
    # VmHWM is the peak resident set over the server's life, so it covers the 16-connection run.
    if alive "$SERVER_PID"; then
        emit < <(awk -v n="$name" '/^VmHWM:/ { printf "%s.peak_rss %.1f MB\n", n, $2 / 1024 }' \
            "/proc/$SERVER_PID/status")
    else
        note "$name exited during the load; its log is lost with $TMP"
    fi
    stop_server
}

# median_of NAME UNIT: `NAME.median`, `.min` and `.max` of the values given one a line on stdin.
median_of() {
    sort -g | awk -v n="$1" -v u="$2" '
        { v[NR] = $1 }
        END {
            if (!NR) exit
            m = NR % 2 ? v[(NR + 1) / 2] : (v[NR / 2] + v[NR / 2 + 1]) / 2
            printf "%s.median %.0f %s\n", n, m, u
            printf "%s.min %.0f %s\n%s.max %.0f %s\n", n, v[1], u, n, v[NR], u
        }'
}

# ratio NAME A B: the ratio of A's median throughput to B's, at 1 and 16 connections.
ratio() {
    local c a b
    for c in 1 16; do
        a=${FIG[$2.c$c.rps.median]:-}
        b=${FIG[$3.c$c.rps.median]:-}
        if [[ -n $a && -n $b && $b != 0 ]]; then
            awk -v n="ratio.$1.c$c" -v a="$a" -v b="$b" \
                'BEGIN { printf "%s %.2f ratio\n", n, a / b }'
        else
            note "ratio.$1.c$c: needs both $2 and $3 figures"
        fi
    done
}

bench_plcemud() {
    local port
    if [[ $BUILD_OK != 1 || ! -x $BUILD/plcemud ]]; then
        note "plcemud: $BUILD/plcemud not built; skipped"
        return 0
    fi
    port=$(free_port)
    bench_server plcemud "$port" "$BUILD/plcemud" -c config/default.yaml --port "$port" \
        --http-port "$(free_port)"
}

# ---- Alternating rounds ---------------------------------------------------------------------
# rounds STARTER CLIENT_ARGS SERVER...: ROUNDS rounds, each starting every SERVER afresh in turn
# (`STARTER NAME PORT` starts one) and loading it at 1 and 16 connections with load_client and
# CLIENT_ARGS (word-split). Prints each round's figure as a note, then
# `<server>.c<N>.rps.median|min|max`.
rounds() {
    local starter=$1 client=$2 round name port c out rps
    shift 2
    declare -A runs=()  # "<server>.c<N>" -> the rounds' req/s, one a line
    for round in $(seq "$ROUNDS"); do
        for name in "$@"; do
            port=$(free_port)
            "$starter" "$name" "$port" || continue
            for c in 1 16; do
                # shellcheck disable=SC2086 # the client's arguments are words
                if out=$("$BUILD/load_client" $client --port "$port" --connections "$c" \
                    --seconds "$RUN_SECONDS" --warmup "$WARMUP_SECONDS" --label "$name.c$c"); then
                    rps=$(awk '$1 ~ /\.rps$/ { print $2 }' <<<"$out")
                    note "round $round: $name.c$c $rps req/s"
                    runs[$name.c$c]+="$rps"$'\n'
                else
                    note "round $round: $name.c$c: load_client could not connect"
                fi
            done
            stop_server
        done
    done
    for name in "$@"; do
        for c in 1 16; do
            emit < <(printf '%s' "${runs[$name.c$c]:-}" | median_of "$name.c$c.rps" req/s)
        done
    done
}

# ---- Hook: servers compared ------------------------------------------------------------------
# plcemud, the do-nothing server and libmodbus, FC03 of 125 registers, and the ratios of the
# medians.
start_modbus_server() {
    case $1 in
        plcemud) start_server "$1" "$2" "$BUILD/plcemud" -c config/default.yaml --port "$2" \
            --http-port "$(free_port)" ;;
        noop) start_server "$1" "$2" "$BUILD/noop_server" --port "$2" ;;
        libmodbus) start_server "$1" "$2" "$BUILD/libmodbus_peer" --port "$2" ;;
    esac
}

bench_servers() {
    local servers=(noop libmodbus)
    if [[ $BUILD_OK == 1 && -x $BUILD/plcemud ]]; then
        servers=(plcemud noop libmodbus)
    else
        note "servers: $BUILD/plcemud not built; comparing the yardsticks alone"
    fi
    note "servers: $ROUNDS rounds of ${servers[*]}, each ${WARMUP_SECONDS} s warm-up and ${RUN_SECONDS} s measured at 1 and 16 connections"
    rounds start_modbus_server "" "${servers[@]}"
    ratio plcemud_vs_noop plcemud noop
    ratio plcemud_vs_libmodbus plcemud libmodbus
}

# ---- Hook: FATEK protocol compared -----------------------------------------------------------
# plcemud serving FATEK's command 46 (64 registers from R0) on its fatek.tcp listener against the
# do-nothing server answering the same frame (noop_server --fatek), and the ratio.
start_fatek_server() {
    case $1 in
        fatek_plcemud)
            # default.yaml's PLC with its Modbus listener on a port of its own.
            { cat config/default.yaml
              printf 'fatek: {tcp: {bind: 127.0.0.1, port: %s}}\n' "$2"; } >"$TMP/fatek.yaml"
            start_server "$1" "$2" "$BUILD/plcemud" -c "$TMP/fatek.yaml" --port 0 \
                --http-port "$(free_port)" ;;
        fatek_noop) start_server "$1" "$2" "$BUILD/noop_server" --port "$2" --fatek ;;
    esac
}

bench_fatek() {
    local servers=(fatek_noop)
    if [[ $BUILD_OK == 1 && -x $BUILD/plcemud ]]; then
        servers=(fatek_plcemud fatek_noop)
    else
        note "fatek: $BUILD/plcemud not built; measuring the yardstick alone"
    fi
    note "fatek: $ROUNDS rounds of ${servers[*]}, command 46 of 64 registers, at 1 and 16 connections"
    rounds start_fatek_server "--protocol fatek --quantity 64" "${servers[@]}"
    ratio plcemud_vs_noop_fatek fatek_plcemud fatek_noop
}

# ---- Hook: the console's cost ----------------------------------------------------------------
# plcemud (config/default.yaml) loaded with FC03 at 16 connections, alone and with 10 browsers'
# worth of live-update subscribers (bench/console_load.py: 20 event streams), in alternating
# rounds on one daemon; the ratio of the medians; and how soon a value written over Modbus
# reaches a subscriber.
bench_console() {
    local port http round out rps sub
    if [[ $BUILD_OK != 1 || ! -x $BUILD/plcemud ]]; then
        note "console: $BUILD/plcemud not built; skipped"
        return 0
    fi
    port=$(free_port)
    http=$(free_port)
    start_server console "$port" "$BUILD/plcemud" -c config/default.yaml --port "$port" \
        --http-port "$http" || return 0
    note "console: $ROUNDS rounds of FC03 at 16 connections, without and with 10 browsers' subscribers"
    declare -A runs=()
    for round in $(seq "$ROUNDS"); do
        for sub in none browsers10; do
            if [[ $sub == browsers10 ]]; then
                "$PY" bench/console_load.py browsers --http-port "$http" --browsers 10 \
                    --seconds "$((WARMUP_SECONDS + RUN_SECONDS + 1))" >"$TMP/subscribers.out" &
                sleep 0.5
            fi
            if out=$("$BUILD/load_client" --port "$port" --connections 16 \
                --seconds "$RUN_SECONDS" --warmup "$WARMUP_SECONDS" --label "console_$sub.c16"); then
                rps=$(awk '$1 ~ /\.rps$/ { print $2 }' <<<"$out")
                note "round $round: console_$sub.c16 $rps req/s"
                runs[$sub]+="$rps"$'\n'
            fi
            if [[ $sub == browsers10 ]]; then
                wait $! || note "console: the subscribers failed: $(cat "$TMP/subscribers.out")"
            fi
        done
    done
    emit < <(printf '%s' "${runs[none]:-}" | median_of console_none.c16.rps req/s)
    emit < <(printf '%s' "${runs[browsers10]:-}" | median_of console_browsers10.c16.rps req/s)
    local a=${FIG[console_browsers10.c16.rps.median]:-} b=${FIG[console_none.c16.rps.median]:-}
    if [[ -n $a && -n $b && $b != 0 ]]; then
        awk -v a="$a" -v b="$b" 'BEGIN { printf "ratio.console_browsers10_vs_none.c16 %.2f ratio\n", a / b }'
    fi
    emit < <("$PY" bench/console_load.py latency --http-port "$http" --modbus-port "$port" \
        --samples 200)
    stop_server
}

# ---- Hook: scan-engine benchmark --------------------------------------------------------------
# Google Benchmark over the core (build-bench/bench_engine), each result as `engine.<name>.*`.
bench_engine() {
    local bin=$BUILD/bench_engine json
    if [[ $BUILD_OK != 1 || ! -x $bin ]]; then
        note "engine: $bin not built; skipped"
        return 0
    fi
    if ! json=$("$bin" --benchmark_format=json 2>/dev/null); then
        note "engine: $bin failed"
        return 0
    fi
    emit < <("$PY" -c '
import json, sys
standard = {"name", "family_index", "per_family_instance_index", "run_name", "run_type",
            "repetitions", "repetition_index", "threads", "iterations", "real_time", "cpu_time",
            "time_unit", "aggregate_name", "aggregate_unit", "label", "error_occurred",
            "error_message"}
def fmt(v):
    return "%.0f" % v if abs(v) >= 1000 else "%.4g" % v
for b in json.load(sys.stdin).get("benchmarks", []):
    name = "engine." + b["name"].replace(" ", "_")
    print("%s.time %s %s" % (name, fmt(b["real_time"]), b["time_unit"]))
    for key, value in b.items():
        if key in standard or not isinstance(value, (int, float)):
            continue
        unit = key[: -len("_per_second")] + "/s" if key.endswith("_per_second") else "value"
        print("%s.%s %s %s" % (name, key, fmt(value), unit))
' <<<"$json")
}

# ---- Hook: scan lateness ----------------------------------------------------------------------
# How late each scan starts against its absolute deadline (p50/p99/max), with the daemon idle
# and under the 16-connection load.
bench_scan_lateness() {
    local port log=$TMP/lateness.log what c
    if [[ $BUILD_OK != 1 || ! -x $BUILD/plcemud ]]; then
        note "scan lateness: $BUILD/plcemud not built; skipped"
        return 0
    fi
    for what in idle c16; do
        port=$(free_port)
        start_server lateness "$port" "$BUILD/plcemud" -c config/default.yaml --port "$port" \
            --http-port "$(free_port)" || return 0
        if [[ $what == c16 ]]; then
            "$BUILD/load_client" --port "$port" --connections 16 --seconds "$RUN_SECONDS" \
                --warmup "$WARMUP_SECONDS" --label lateness >/dev/null || true
        else
            sleep "$((RUN_SECONDS + WARMUP_SECONDS))"
        fi
        stop_server
        # plcemud logs the lateness of every scan start against its deadline when it stops.
        cp "$TMP/lateness.log" "$log.$what"
        emit < <(sed -n 's/.*scan lateness: \([0-9]*\) scans, p50 \([0-9]*\) us, p99 \([0-9]*\) us, max \([0-9]*\) us.*/\2 \3 \4/p' \
            "$log.$what" | awk -v n="plcemud.scan_lateness.$what" \
            '{ printf "%s.p50 %s us\n%s.p99 %s us\n%s.max %s us\n", n, $1, n, $2, n, $3 }')
    done
    c=${FIG[plcemud.scan_lateness.c16.p99]:-}
    [[ -n $c ]] || note "scan lateness: no figures (see plcemud's log)"
}

# ---- Hook: RTU turnaround ---------------------------------------------------------------------
# Request-to-reply time over a socat pty pair at a given baud rate, against the t3.5 silence.
bench_rtu_turnaround() {
    local a=$TMP/rtu-a b=$TMP/rtu-b pty_pid cfg=$TMP/rtu.yaml
    if [[ $BUILD_OK != 1 || ! -x $BUILD/plcemud ]] || ! command -v socat >/dev/null; then
        note "rtu turnaround: needs $BUILD/plcemud and socat; skipped"
        return 0
    fi
    scripts/rtu-pty.sh "$a" "$b" >/dev/null &
    pty_pid=$!
    for _ in $(seq 100); do [[ -e $a && -e $b ]] && break; sleep 0.05; done
    cat >"$cfg" <<YAML
profile: fbs
modbus:
  tcp: {enabled: false}
  rtu: {device: $a, baud: 115200, parity: N}
persistence: {enabled: false}
YAML
    "$BUILD/plcemud" -c "$cfg" >"$TMP/rtu.log" 2>&1 &
    SERVER_PID=$!
    sleep 0.5
    emit < <("$PY" bench/rtu_turnaround.py "$b" --label plcemud.rtu115200)
    stop_server
    kill "$pty_pid" 2>/dev/null || true
    wait "$pty_pid" 2>/dev/null || true
}

# ---- Hook: many PLCs in one process ----------------------------------------------------------
# The server's RSS now, as figure NAME.
rss() {
    emit < <(awk -v n="$1" '/^VmRSS:/ { printf "%s %.1f MB\n", n, $2 / 1024 }' \
        "/proc/$SERVER_PID/status")
}

# N copies of config/default.yaml's PLC in one `plcs:` process, each on its own port with its own
# state file: the time to start, the CPU share of one core while nobody polls (scans every 10 ms,
# plants running), then one client per PLC polling FC03 (R0-R9) every second: its latency and
# overruns, a reload of the whole config with one PLC's setpoint changed (how long until it was
# applied, and the longest any polling client waited meanwhile), the RSS at rest, while polled,
# at its peak and once the reload is over, and the scan-start lateness every PLC logs when the daemon stops (the
# worst PLC's p99 and the median PLC's). Run for 500 PLCs, and for BENCH_PLCS as well when that
# is another count, so that each figure of a large run is printed beside the 500-PLC one.
many_plcs_run() {
    local n=$1 dir=$TMP/plcs$1 cfg base started up hz t0 t1 c0 c1 poll poll_pid done_lines
    mkdir -p "$dir"
    # Below the ephemeral range (32768 on), where clients' own ports come from.
    base=$((10000 + RANDOM % (22768 - n)))
    if ! cfg=$("$PY" bench/many_plcs.py --count "$n" --port "$base" --dir "$dir"); then
        note "plcs: no $n free ports from $base; skipped"
        return 0
    fi
    started=$(date +%s.%N)
    # The last PLC's port accepting means every listener is open.
    START_TRIES=2400 start_server "plcs$n" "$((base + n - 1))" "$BUILD/plcemud" -c "$cfg" ||
        return 0
    up=$(awk -v a="$started" -v b="$(date +%s.%N)" 'BEGIN { printf "%.2f", b - a }')
    emit <<<"plcs$n.start $up s"
    hz=$(getconf CLK_TCK)
    cpu_ticks() { awk '{ print $14 + $15 }' "/proc/$SERVER_PID/stat"; }
    sleep 2  # past the start-up's own work
    c0=$(cpu_ticks)
    t0=$(date +%s.%N)
    sleep "$((RUN_SECONDS * 2))"
    c1=$(cpu_ticks)
    t1=$(date +%s.%N)
    emit < <(awk -v n="plcs$n.idle_cpu" -v c="$((c1 - c0))" -v hz="$hz" -v a="$t0" -v b="$t1" \
        'BEGIN { printf "%s %.1f %%\n", n, 100 * c / hz / (b - a) }')
    rss "plcs$n.rss_idle"
    # Each PLC holds three descriptors (its listener, its state file and the file's lock) and
    # a client one more: where the hard limit cannot hold them all, fewer PLCs are polled (the
    # daemon keeps the rest of its descriptors for itself, and further clients wait at accept).
    poll=$(($(ulimit -Hn) - 3 * n - 100))
    ((poll > n)) && poll=$n
    ((poll < n)) && note "plcs$n: $poll of the $n PLCs polled (descriptor limit $(ulimit -Hn))"
    emit < <("$BUILD/load_client" --port "$base" --ports "$n" --connections "$poll" \
        --interval-ms 1000 --quantity 10 --seconds "$((RUN_SECONDS * 2))" \
        --warmup "$WARMUP_SECONDS" --label "plcs$n.fc03" | grep -v '\.fairness ')
    # The reload: plc0's first setpoint changed, applied while the PLCs are polled.
    cp "$cfg.reload" "$cfg"
    "$BUILD/load_client" --port "$base" --ports "$n" --connections "$poll" --interval-ms 1000 \
        --quantity 10 --seconds "$((RUN_SECONDS * 4))" --warmup "$WARMUP_SECONDS" \
        --label "plcs$n.reload_fc03" >"$TMP/reload_poll.txt" &
    poll_pid=$!
    sleep "$((WARMUP_SECONDS + 1))"
    # What the clients cost beside the RSS at rest: each its connection, each PLC its ring of
    # exchanges.
    rss "plcs$n.rss_polled"
    done_lines=$(grep -c 'reload: applied to ' "$TMP/plcs$n.log" || true)
    t0=$(date +%s.%N)
    kill -HUP "$SERVER_PID"
    for _ in $(seq 3600); do
        (($(grep -c 'reload: applied to ' "$TMP/plcs$n.log" || true) > done_lines)) && break
        grep -q 'configuration rejected' "$TMP/plcs$n.log" && break
        sleep 0.05
    done
    t1=$(date +%s.%N)
    if (($(grep -c 'reload: applied to ' "$TMP/plcs$n.log" || true) > done_lines)); then
        emit < <(awk -v n="plcs$n.reload" -v a="$t0" -v b="$t1" 'BEGIN { printf "%s %.2f s\n", n, b - a }')
    elif grep -q 'configuration rejected' "$TMP/plcs$n.log"; then
        note "plcs$n: the reload was refused:"
        grep 'reload: ' "$TMP/plcs$n.log" | grep -v ' info ' | sed 's/^/#   /' | head -5
    else
        note "plcs$n: the reload did not finish in $(awk -v a="$t0" -v b="$t1" 'BEGIN { printf "%.0f", b - a }') s"
    fi
    wait "$poll_pid" || true
    emit < <(grep -E '\.(max|p99|errors|overruns) ' "$TMP/reload_poll.txt")
    if alive "$SERVER_PID"; then
        # The RSS once the reload's leftovers are freed (the retirer's thread frees them in the
        # background: a second is ample), beside the peak the reload reached.
        sleep 1
        emit < <(awk -v n="plcs$n" '
            /^VmHWM:/ { printf "%s.peak_rss %.1f MB\n", n, $2 / 1024 }
            /^VmRSS:/ { printf "%s.rss_after_reload %.1f MB\n", n, $2 / 1024 }' \
            "/proc/$SERVER_PID/status")
    fi
    # Closing thousands of state files (each synced) takes a while.
    STOP_TRIES=$((50 + n / 10)) stop_server
    emit < <(sed -n 's/.*scan lateness: [0-9]* scans, p50 [0-9]* us, p99 \([0-9]*\) us.*/\1/p' \
        "$TMP/plcs$n.log" | sort -n | awk -v n="plcs$n.scan_lateness" '
            { v[NR] = $1 }
            END { if (NR) printf "%s.p99_median_plc %s us\n%s.p99_worst_plc %s us\n",
                                 n, v[int((NR + 1) / 2)], n, v[NR] }')
    [[ -n ${FIG[plcs$n.scan_lateness.p99_worst_plc]:-} ]] ||
        note "plcs$n: no scan lateness in plcemud's log"
    rm -rf "$dir"
}

bench_many_plcs() {
    local n=${BENCH_PLCS:-500} name
    if [[ $BUILD_OK != 1 || ! -x $BUILD/plcemud ]]; then
        note "plcs: $BUILD/plcemud not built; skipped"
        return 0
    fi
    many_plcs_run 500
    ((n == 500)) && return 0
    many_plcs_run "$n"
    note "plcs: $n PLCs beside 500"
    for name in start idle_cpu fc03.p99 fc03.max fc03.overruns rss_idle rss_polled peak_rss \
        rss_after_reload reload reload_fc03.max scan_lateness.p99_worst_plc; do
        [[ -n ${FIG[plcs$n.$name]:-} && -n ${FIG[plcs500.$name]:-} ]] || continue
        echo "# plcs.$name: ${FIG[plcs500.$name]} at 500, ${FIG[plcs$n.$name]} at $n"
    done
}

# ---- Hook: stepping many PLCs ------------------------------------------------------------------
# Read latency of an idle PLC of a `plcs:` process while 1 and then 10 other PLCs of it are
# stepped through their simulator units (bench/stepping_fairness.py): p50, p99 and max.
bench_stepping() {
    local n out
    if [[ $BUILD_OK != 1 || ! -x $BUILD/plcemud ]]; then
        note "stepping: $BUILD/plcemud not built; skipped"
        return 0
    fi
    for n in 1 10; do
        # It fails when the steps ran out before the reads did: figures not taken under load.
        if out=$("$PY" bench/stepping_fairness.py --plcemud "$BUILD/plcemud" --steppers "$n" \
            --seconds "$RUN_SECONDS" --label "plcemud.stepping$n"); then
            emit <<<"$out"
        else
            note "stepping: the run with $n stepped PLCs failed"
        fi
    done
}

install_packages
build
if [[ -n ${BENCH_ONLY:-} ]]; then
    # One hook alone, e.g. BENCH_ONLY=many_plcs.
    declare -F "bench_$BENCH_ONLY" >/dev/null || { echo "bench: no hook '$BENCH_ONLY'" >&2; exit 2; }
    "bench_$BENCH_ONLY"
    exit 0
fi
note "each run: ${WARMUP_SECONDS} s warm-up, ${RUN_SECONDS} s measured; FC03 of 125 registers"
bench_engine
# One run each at 1, 4 and 16 connections (latency percentiles, fairness, peak RSS)...
bench_plcemud
port=$(free_port)
bench_server noop "$port" "$BUILD/noop_server" --port "$port"
port=$(free_port)
bench_server libmodbus "$port" "$BUILD/libmodbus_peer" --port "$port"
port=$(free_port)
bench_server pymodbus "$port" "$PY" bench/pymodbus_server.py --port "$port"
# ...and the throughput comparison, which one run per server cannot make.
bench_servers
bench_fatek
bench_console
bench_scan_lateness
bench_rtu_turnaround
bench_many_plcs
bench_stepping
