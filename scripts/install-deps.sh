#!/usr/bin/env bash
# Installs, from Debian's packages, whatever the build and the tests need and is missing.
# Usage: scripts/install-deps.sh [run|kit|test|package|style|bench|fuzz|plot|trace|container]...
#        (default: run)
set -euo pipefail

# libboost-dev: Boost.Beast's HTTP parser (header-only); nlohmann-json3-dev: the API's JSON;
# libxxhash-dev: the state file's page sums (header-only).
want=(cmake g++ make pkg-config libmodbus-dev libasio-dev libyaml-cpp-dev libspdlog-dev libfmt-dev
      libsystemd-dev libboost-dev nlohmann-json3-dev libxxhash-dev)
for what in "${@:-run}"; do
    case "$what" in
        run) ;;
        # The README's examples against a running plcemud: mbpoll ("A first try"), pymodbus (with
        # serial-asyncio, which Debian's pymodbus only recommends yet its client package
        # imports), pytest for the plcemu_testing plugin (python3-yaml: its plcs: configs), and
        # what `pip install --no-build-isolation ./python` in a venv needs (venv, setuptools,
        # wheel).
        kit) want+=(mbpoll python3-pymodbus python3-serial-asyncio python3-pytest python3-yaml
                    python3-venv python3-setuptools python3-wheel) ;;
        # Debian's pymodbus only recommends serial-asyncio, yet its client package imports it.
        # man-db and groff-base render the man pages (tests/system/test_docs.py); python3-yaml
        # is scripts/trace.py's and python3-matplotlib scripts/plot_trace.py's
        # (tests/system/test_trace.py).
        # python3-venv, -setuptools and -wheel: tests/system/test_newcomer.py installs python/
        # in a venv. chromium, chromium-driver and python3-selenium: the console's browser
        # tests (tests/system/test_console_browser.py). podman-compose (with podman) and
        # python3-kubernetes: compose.yaml and deploy/kubernetes/ (test_containers.py).
        # e2fsprogs (mkfs.ext4) and util-linux (losetup): a disk that refuses writes
        # (test_state_write_errors.py).
        test) want+=(libgtest-dev python3-pymodbus python3-serial-asyncio python3-pytest
                     python3-serial python3-yaml python3-matplotlib mbpoll socat
                     python3-venv python3-setuptools python3-wheel systemd
                     iproute2 util-linux e2fsprogs man-db groff-base ccache
                     chromium chromium-driver python3-selenium
                     podman podman-compose python3-kubernetes) ;;
        # CPack's DEB generator needs dpkg-shlibdeps (dpkg-dev) and file; lintian checks the result.
        package) want+=(dpkg-dev file lintian) ;;
        # scripts/style.sh: the versions CI checks style with.
        style) want+=(clang-format-14 clang-tidy-14 git) ;;
        # python3-yaml: bench/many_plcs.py writes the 500-PLC config from config/default.yaml.
        bench) want+=(libbenchmark-dev python3-pymodbus python3-serial-asyncio python3-yaml socat) ;;
        fuzz) want+=(clang-14 libclang-rt-14-dev) ;;
        plot) want+=(python3-matplotlib) ;;
        trace) want+=(python3-pymodbus python3-serial-asyncio python3-yaml) ;;
        # scripts/container.sh: podman and buildah build the image (crun runs its build step;
        # uidmap, fuse-overlayfs and slirp4netns for rootless use), mmdebstrap makes its Debian
        # base from Debian's packages (with the archive's keyring), podman-compose reads
        # compose.yaml and python3-kubernetes checks deploy/kubernetes/
        # (tests/system/test_containers.py).
        container) want+=(podman buildah crun mmdebstrap debian-archive-keyring podman-compose
                          python3-kubernetes uidmap fuse-overlayfs slirp4netns
                          python3-pymodbus python3-serial-asyncio python3-pytest python3-yaml) ;;
        *) echo "install-deps: unknown set '$what'" >&2; exit 2 ;;
    esac
done

missing=()
for p in "${want[@]}"; do
    dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
((${#missing[@]} == 0)) && exit 0

echo "install-deps: installing ${missing[*]}" >&2
sudo=()
if [[ $(id -u) -ne 0 ]]; then
    command -v sudo >/dev/null || { echo "install-deps: need root (or sudo) for apt-get" >&2; exit 1; }
    sudo=(sudo)
fi
export DEBIAN_FRONTEND=noninteractive
"${sudo[@]}" apt-get update -qq
"${sudo[@]}" apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
