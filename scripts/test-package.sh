#!/usr/bin/env bash
# Tests the Debian package on this machine: installs it with apt-get, checks its files, runs the
# PLC from /etc/plcemu/plcemud.yaml and reads and writes it over Modbus TCP, then purges it three
# times: keeping the state data when /etc/plcemu/keep-state exists, keeping it with
# PLCEMU_KEEP_STATE=1, and removing it otherwise (docs/operations.md, "Packaging").
# It installs and purges the package `plcemu` on this machine (a plcemu installed before is
# purged first). Needs root (or sudo). Exits non-zero on any failure.
#
# Usage: scripts/test-package.sh PACKAGE.deb      test that package
#        scripts/test-package.sh [--reuse-build]  build one with scripts/package.sh --lintian
#                                                 (lintian errors fail) and test it
set -euo pipefail
cd "$(dirname "$0")/.."

sudo=()
if [[ $(id -u) -ne 0 ]]; then
    command -v sudo >/dev/null || { echo "test-package: need root (or sudo)" >&2; exit 1; }
    sudo=(sudo)
fi
export DEBIAN_FRONTEND=noninteractive

if [[ ${1:-} == *.deb ]]; then
    deb=$1
else
    deb=$(scripts/package.sh --lintian "$@" | tail -n 1)
fi
[[ -f $deb ]] || { echo "test-package: no package '$deb'" >&2; exit 1; }
deb=$(realpath "$deb")
size=$(stat -c %s "$deb")
echo "== test-package: $deb ($size bytes)"

fail() { echo "test-package: FAIL: $*" >&2; exit 1; }
installed() { dpkg-query -W -f='${Status}' plcemu 2>/dev/null | grep -q "install ok installed"; }
quiet() {  # runs "$@", showing its output only when it fails
    local out
    out=$("$@" 2>&1) || { echo "$out" >&2; fail "$*"; }
}
install_pkg() { quiet "${sudo[@]}" apt-get install -y -qq "$deb"; }
purge_pkg() { quiet "${sudo[@]}" env "$@" apt-get purge -y -qq plcemu; }

pid=
cleanup() {
    if [[ -n $pid ]]; then "${sudo[@]}" kill -TERM "$pid" 2>/dev/null || true; fi
    if installed; then purge_pkg; fi
}
trap cleanup EXIT

if dpkg-query -W plcemu >/dev/null 2>&1; then
    echo "test-package: purging the plcemu installed before"
    purge_pkg
fi
"${sudo[@]}" rm -rf /var/lib/plcemu /var/lib/private/plcemu

# docs/operations.md gives the package's size ("plcemu_0.1.0_amd64.deb`, about N kB"): it must
# be within 25 % of this one's.
stated=$(tr '\n' ' ' <docs/operations.md | grep -oP '_amd64\.deb`, +about \K[0-9]+(?= kB)' || true)
[[ -n $stated ]] || fail "docs/operations.md states no package size"
((size * 4 >= stated * 1000 * 3 && size * 4 <= stated * 1000 * 5)) ||
    fail "docs/operations.md says about $stated kB; the package is $((size / 1000)) kB"

echo "== install"
install_pkg
installed || fail "not installed"
for f in /usr/bin/plcemud /lib/systemd/system/plcemud.service /lib/systemd/system/plcemud@.service \
         /etc/plcemu/plcemud.yaml /usr/share/doc/plcemu/examples/example.yaml \
         /usr/share/doc/plcemu/examples/default.yaml /usr/share/doc/plcemu/copyright \
         /usr/share/doc/plcemu/changelog.gz /usr/share/man/man8/plcemud.8.gz \
         /usr/share/man/man5/plcemud.yaml.5.gz; do
    [[ -f $f ]] || fail "missing $f"
done
# Every configuration of config/ (the README and docs name them) and every figure the docs show.
for f in config/*.yaml config/programs/*.il; do
    cmp -s "$f" "/usr/share/doc/plcemu/examples/${f#config/}" || fail "missing or stale examples/${f#config/}"
done
for f in docs/images/*; do
    cmp -s "$f" "/usr/share/doc/plcemu/$f" || fail "missing or stale /usr/share/doc/plcemu/$f"
done
dpkg-query -W -f='${Conffiles}\n' plcemu | grep -q '^ /etc/plcemu/plcemud.yaml ' ||
    fail "/etc/plcemu/plcemud.yaml is not a conffile"
grep -q '^ExecStart=/usr/bin/plcemud -c /etc/plcemu/plcemud.yaml$' \
    /lib/systemd/system/plcemud.service || fail "plcemud.service does not run /usr/bin/plcemud"
grep -q '^DynamicUser=yes$' /lib/systemd/system/plcemud.service || fail "no DynamicUser="
# Enabled by nothing, started by nothing.
compgen -G '/etc/systemd/system/*.wants/plcemud*' >/dev/null && fail "a unit was enabled"
if [[ -d /run/systemd/system ]] && systemctl is-active --quiet plcemud; then
    fail "plcemud.service was started"
fi
if command -v man >/dev/null; then
    man -w plcemud >/dev/null && man -w plcemud.yaml >/dev/null || fail "man pages not found"
    warnings=$(MANWIDTH=80 man --warnings plcemud.yaml 2>&1 >/dev/null)
    [[ -z $warnings ]] || fail "man plcemud.yaml: $warnings"
fi
/usr/bin/plcemud --version
/usr/bin/plcemud -c /etc/plcemu/plcemud.yaml --check-config || fail "the packaged config is invalid"
# An example that reads its program from a file beside it finds it where the package put it.
/usr/bin/plcemud -c /usr/share/doc/plcemu/examples/oven-il.yaml --check-config ||
    fail "the packaged oven-il.yaml does not find its program"
# Its header speaks of the installed file: a source tree's commands are not in it.
grep -q 'scripts/run.sh' /etc/plcemu/plcemud.yaml && fail "/etc/plcemu/plcemud.yaml names scripts/run.sh"

# Runs the PLC from the packaged configuration (as plcemud.service would, state directory
# included), checks Modbus writes and reads, stops it. $1: the D1000 value to expect at first.
run_plc() {
    local expect=$1 port log
    port=$(/usr/bin/python3 -c 'import socket; s=socket.socket(); s.bind(("127.0.0.1", 0)); print(s.getsockname()[1])')
    log=$(mktemp)
    if [[ -d /run/systemd/system ]] && systemctl --quiet is-system-running 2>/dev/null; then
        "${sudo[@]}" mkdir -p /run/systemd/system/plcemud.service.d
        printf '[Service]\nExecStart=\nExecStart=/usr/bin/plcemud -c /etc/plcemu/plcemud.yaml --port %s\n' \
            "$port" | "${sudo[@]}" tee /run/systemd/system/plcemud.service.d/test.conf >/dev/null
        "${sudo[@]}" systemctl daemon-reload
        "${sudo[@]}" systemctl start plcemud || fail "systemctl start plcemud"
    else
        # PID 1 is not systemd: what the unit's StateDirectory= would give.
        "${sudo[@]}" install -d -m 0750 /var/lib/plcemu
        "${sudo[@]}" env STATE_DIRECTORY=/var/lib/plcemu /usr/bin/plcemud \
            -c /etc/plcemu/plcemud.yaml --port "$port" 2>"$log" &
        pid=$!
    fi
    /usr/bin/python3 - "$port" "$expect" <<'PY' || { cat "$log" >&2; fail "Modbus exchange"; }
import sys, time
from pymodbus.client import ModbusTcpClient
port, expect = int(sys.argv[1]), int(sys.argv[2])
c = ModbusTcpClient("127.0.0.1", port=port)
deadline = time.monotonic() + 10
while not c.connect():
    if time.monotonic() > deadline:
        sys.exit("plcemud did not listen on port %d" % port)
    time.sleep(0.1)
r = c.read_holding_registers(4167, 1, slave=1)             # R4167: model code
assert not r.isError() and r.registers == [0x0118], r        # FBs-24MC
r = c.read_holding_registers(7000, 1, slave=1)             # D1000 (retentive)
assert not r.isError() and r.registers == [expect], (r, expect)
assert not c.write_register(7000, 1234, slave=1).isError()
assert c.read_holding_registers(7000, 1, slave=1).registers == [1234]
c.close()
print("modbus: R4167 = 0118h, D1000 was %d, now 1234" % expect)
PY
    if [[ -z $pid ]]; then
        "${sudo[@]}" systemctl stop plcemud
        "${sudo[@]}" rm -rf /run/systemd/system/plcemud.service.d
        "${sudo[@]}" systemctl daemon-reload
    else
        "${sudo[@]}" kill -TERM "$pid"
        local rc=0
        wait "$pid" || rc=$?
        pid=
        ((rc == 0)) || { cat "$log" >&2; fail "plcemud exited $rc after SIGTERM"; }
    fi
    rm -f "$log"
    "${sudo[@]}" test -f /var/lib/plcemu/plcemud.state || fail "no state file in /var/lib/plcemu"
}

echo "== run"
run_plc 0

check_removed() {
    [[ ! -e /usr/bin/plcemud ]] || fail "/usr/bin/plcemud left after purge"
    # Neither the links of enabled units nor deb-systemd-helper's mask stay behind.
    if compgen -G '/etc/systemd/system/*.wants/plcemud*' >/dev/null ||
        [[ -L /etc/systemd/system/plcemud.service ]]; then
        fail "links left after purge: $(ls -l /etc/systemd/system/*.wants/plcemud* \
              /etc/systemd/system/plcemud.service 2>/dev/null)"
    fi
    [[ ! -e /etc/plcemu ]] || fail "/etc/plcemu left after purge"
    [[ ! -e /lib/systemd/system/plcemud.service ]] || fail "plcemud.service left after purge"
    ! dpkg-query -W plcemu >/dev/null 2>&1 || fail "plcemu still known to dpkg after purge"
}

# An administrator enables the unit and an instance (systemctl works on the unit files without
# a running systemd too); purge must remove the links (checked by check_removed).
"${sudo[@]}" systemctl enable plcemud.service plcemud@check.service >/dev/null 2>&1 ||
    fail "systemctl enable plcemud plcemud@check"
[[ -L /etc/systemd/system/multi-user.target.wants/plcemud.service ]] || fail "enable made no link"

echo "== purge, keeping the state (/etc/plcemu/keep-state)"
"${sudo[@]}" touch /etc/plcemu/keep-state
purge_pkg
check_removed
"${sudo[@]}" test -f /var/lib/plcemu/plcemud.state || fail "keep-state: the state file was removed"

echo "== install again: the kept state is used"
install_pkg
run_plc 1234

echo "== remove, then purge, keeping the state (PLCEMU_KEEP_STATE=1)"
"${sudo[@]}" systemctl enable plcemud.service >/dev/null 2>&1 || fail "systemctl enable plcemud"
quiet "${sudo[@]}" apt-get remove -y -qq plcemu
purge_pkg PLCEMU_KEEP_STATE=1
check_removed
"${sudo[@]}" test -f /var/lib/plcemu/plcemud.state || fail "PLCEMU_KEEP_STATE=1: the state was removed"

echo "== purge, removing the state"
install_pkg
purge_pkg
check_removed
[[ ! -e /var/lib/plcemu ]] || fail "/var/lib/plcemu left after a plain purge"
echo "test-package: ok"
