#!/usr/bin/env bash
# Starts a pair of connected pseudo-terminals (socat) to try Modbus RTU without hardware:
# plcemud opens one end as its serial port, a master (mbpoll, pymodbus, a SCADA) the other.
# Prints the two device paths, one per line, then stays in the foreground until Ctrl-C.
#
# Usage: scripts/rtu-pty.sh [DEVICE_A [DEVICE_B]]   (default /tmp/plcemu-rtu-a /tmp/plcemu-rtu-b)
#   config:  modbus: {rtu: {device: /tmp/plcemu-rtu-a}}        (9600 8E1 by default)
#   master:  mbpoll -m rtu -b 9600 -P even -a 1 -r 1 -c 10 /tmp/plcemu-rtu-b
set -euo pipefail

a=${1:-/tmp/plcemu-rtu-a}
b=${2:-/tmp/plcemu-rtu-b}
if ! command -v socat >/dev/null; then
    echo "rtu-pty: socat is not installed (apt-get install socat)" >&2
    exit 1
fi
for link in "$a" "$b"; do
    if [[ -e $link && ! -L $link ]]; then
        echo "rtu-pty: $link exists and is not a link from an earlier run; not touching it" >&2
        exit 1
    fi
done

# raw, no echo: bytes pass unchanged, as on a serial line.
socat pty,raw,echo=0,link="$a" pty,raw,echo=0,link="$b" &
socat_pid=$!
trap 'kill "$socat_pid" 2>/dev/null || true; wait "$socat_pid" 2>/dev/null || true' EXIT
trap 'exit 0' INT TERM

for _ in $(seq 100); do
    [[ -e $a && -e $b ]] && break
    kill -0 "$socat_pid" 2>/dev/null || { echo "rtu-pty: socat failed" >&2; exit 1; }
    sleep 0.05
done
if [[ ! -e $a || ! -e $b ]]; then
    echo "rtu-pty: socat did not create $a and $b" >&2
    exit 1
fi

echo "$a"
echo "$b"
echo "rtu-pty: $a ($(readlink "$a")) <-> $b ($(readlink "$b")); Ctrl-C to stop" >&2
wait "$socat_pid"
