#!/usr/bin/env bash
# Installs plcemud (built Release), its systemd units and an example configuration:
#   PREFIX/bin/plcemud                              (PREFIX: /usr/local)
#   /etc/systemd/system/plcemud.service, plcemud@.service
#   /etc/plcemu/plcemud.yaml   (config/default.yaml, only if there is none: never overwritten)
#   /etc/plcemu/example.yaml   (config/example.yaml: every key, commented)
#   PREFIX/share/doc/plcemu/README.md
#   PREFIX/share/man/man8/plcemud.8, man5/plcemud.yaml.5
# It creates no user (the units use DynamicUser=) and no state directory (StateDirectory=), and
# enables nothing. Run as root.
#
# Usage: scripts/install.sh [--prefix DIR] [--binary FILE]
#   --binary FILE   install FILE instead of building (e.g. a build made elsewhere)
#   DESTDIR=DIR     install under DIR (packaging, tests); no systemctl then
set -euo pipefail
cd "$(dirname "$0")/.."

prefix=/usr/local
binary=
while (($#)); do
    case "$1" in
        --prefix) prefix=${2:?--prefix needs a directory}; shift 2 ;;
        --binary) binary=${2:?--binary needs a file}; shift 2 ;;
        -h|--help) sed -n '2,14p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
        *) echo "install: unknown argument '$1'" >&2; exit 2 ;;
    esac
done
destdir=${DESTDIR:-}

if [[ -z $binary ]]; then
    scripts/install-deps.sh run
    cmake -S . -B build-release -DCMAKE_BUILD_TYPE=Release -DPLCEMU_TESTS=OFF >/dev/null
    cmake --build build-release -j"$(nproc)" --target plcemud
    binary=build-release/plcemud
fi

install -D -m 0755 "$binary" "$destdir$prefix/bin/plcemud"
tmp=$(mktemp)
trap 'rm -f "$tmp"' EXIT
for unit in plcemud.service plcemud@.service; do
    # The units name /usr/local; follow --prefix.
    sed -e "s|/usr/local/|$prefix/|g" "systemd/$unit" >"$tmp"
    install -D -m 0644 "$tmp" "$destdir/etc/systemd/system/$unit"
done
install -D -m 0644 config/example.yaml "$destdir/etc/plcemu/example.yaml"
if [[ -e $destdir/etc/plcemu/plcemud.yaml ]]; then
    echo "install: keeping the existing $destdir/etc/plcemu/plcemud.yaml"
else
    install -D -m 0644 config/default.yaml "$destdir/etc/plcemu/plcemud.yaml"
fi
install -D -m 0644 README.md "$destdir$prefix/share/doc/plcemu/README.md"
install -D -m 0644 man/plcemud.8 "$destdir$prefix/share/man/man8/plcemud.8"
install -D -m 0644 man/plcemud.yaml.5 "$destdir$prefix/share/man/man5/plcemud.yaml.5"

if [[ -z $destdir && -d /run/systemd/system ]]; then
    systemctl daemon-reload
fi
cat <<MSG
install: done. Edit /etc/plcemu/plcemud.yaml (it listens on 127.0.0.1:5020; a real PLC uses
0.0.0.0:502), check it with: plcemud -c /etc/plcemu/plcemud.yaml --check-config
then: systemctl enable --now plcemud
One PLC per /etc/plcemu/NAME.yaml: systemctl enable --now plcemud@NAME
MSG
