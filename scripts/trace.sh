#!/usr/bin/env bash
# Records a closed-loop run of a config in virtual time to CSV: builds plcemud (Release, into
# build-release/ as scripts/run.sh does) unless PLCEMUD names a binary, then runs scripts/trace.py,
# which starts its own plcemud on a free port (persistence off), freezes it through the
# simulator-control unit, starts the loops and steps the scans.
#
#   scripts/trace.sh CONFIG [MINUTES] [OUT.csv] [DEVICE=VALUE ...] [--no-start]
#   scripts/trace.sh config/default.yaml 30 default.csv
#   scripts/trace.sh config/vb-pid.yaml 30 vb-pid.csv      # FNC88 PID, auto-tuning from cold
#   scripts/plot_trace.py default.csv default.png
#
# MINUTES of simulated time (default 30), sampled every simulated second. The DEVICE=VALUE writes
# come first (e.g. R4005=0, D201=0x21); then the trace turns on every TPCTL's and PID's EN and
# sets every WMn word the program moves into R4012/R4013 (what a SCADA does to start the loops),
# unless --no-start. The Modbus addresses come from the daemon's own --print-map.
set -euo pipefail
cd "$(dirname "$0")/.."

if [[ $# -lt 1 || $1 == -h || $1 == --help ]]; then
    awk 'NR > 1 && /^#/ { sub(/^# ?/, ""); print; next } NR > 1 { exit }' "$0"
    exit 2
fi
config=$1
minutes=${2:-30}
out=${3:-trace.csv}
shift $(($# < 3 ? $# : 3))

if [[ -z ${PLCEMUD:-} ]]; then
    scripts/install-deps.sh run trace
    cmake -S . -B build-release -DCMAKE_BUILD_TYPE=Release -DPLCEMU_TESTS=OFF >/dev/null
    cmake --build build-release -j2 --target plcemud >&2
    PLCEMUD=build-release/plcemud
fi
# Debian's interpreter: the one with python3-pymodbus and python3-yaml.
exec /usr/bin/python3 scripts/trace.py --plcemud "$PLCEMUD" --config "$config" \
    --minutes "$minutes" --out "$out" "$@"
