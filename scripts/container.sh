#!/usr/bin/env bash
# Builds the container image plcemu:<version> (and plcemu:latest) from Containerfile and the
# Debian package that scripts/package.sh makes, so that the image and the .deb never drift
# (docs/operations.md, "Containers and Kubernetes"). Without a registry in reach it makes its
# Debian base itself: mmdebstrap writes a slim Debian 12 (minbase, no docs, man pages or
# locales) holding the package's dependencies, imported as localhost/plcemu-base:bookworm, and
# rebuilt only when the dependencies change. Prints the image's size; the last line is its name.
#
# Usage: scripts/container.sh [--base IMAGE] [--deb FILE] [--reuse-build] [--rebuild-base] [--test]
#   --base IMAGE     build on IMAGE (e.g. debian:bookworm-slim, pulled from a registry) instead of
#                    the base made with mmdebstrap
#   --deb FILE       use this package instead of building one with scripts/package.sh
#   --reuse-build    passed to scripts/package.sh: an incremental build in build-package/
#   --rebuild-base   make the mmdebstrap base anew even when its dependencies are unchanged
#   --test           then run tests/system/test_containers.py against the image: its files, the
#                    daemon started from its root file system (chroot, as its user) answering
#                    Modbus and exiting 0 on SIGTERM with its state synced, compose.yaml and
#                    deploy/kubernetes/ (docs/operations.md says what each checks)
#   PLCEMU_CONTAINER_ENGINE=docker   build with docker instead of podman (needs a Docker engine)
#   PLCEMU_DEBIAN_MIRROR=URL         the mirror mmdebstrap reads (default: Debian's, with the
#                                    updates and security suites)
set -euo pipefail
cd "$(dirname "$0")/.."

base=
deb=
package_args=()
rebuild_base=no
run_tests=no
while (($#)); do
    case "$1" in
        --base) base=${2:?--base needs an image}; shift ;;
        --deb) deb=${2:?--deb needs a file}; shift ;;
        --reuse-build) package_args+=(--reuse-build) ;;
        --rebuild-base) rebuild_base=yes ;;
        --test) run_tests=yes ;;
        *) echo "container: unknown argument '$1'" >&2; exit 2 ;;
    esac
    shift
done

engine=${PLCEMU_CONTAINER_ENGINE:-podman}
case "$engine" in
    podman) scripts/install-deps.sh container ;;
    docker) command -v docker >/dev/null || { echo "container: no docker" >&2; exit 1; } ;;
    *) echo "container: PLCEMU_CONTAINER_ENGINE is podman or docker, not '$engine'" >&2; exit 2 ;;
esac

start=$SECONDS
step() { echo "== container: $* ($((SECONDS - start)) s)" >&2; }

# The package: the context (.dockerignore) holds build/plcemu_*.deb and deploy/container/ only.
if [[ -z $deb ]]; then
    step "building the Debian package (scripts/package.sh ${package_args[*]})"
    deb=$(scripts/package.sh "${package_args[@]}" | tail -n 1)
fi
[[ -f $deb ]] || { echo "container: no package '$deb'" >&2; exit 1; }
name=$(basename "$deb")
[[ $name == plcemu_*.deb ]] || { echo "container: '$deb' is not a plcemu_*.deb" >&2; exit 1; }
mkdir -p build
if [[ $(realpath "$deb") != $(realpath -m "build/$name") ]]; then
    cp -f "$deb" "build/$name"
fi
deb=build/$name
version=$(dpkg-deb -f "$deb" Version)
image=plcemu:$version

# The base. Its label records the packages mmdebstrap included: the package's dependencies, so
# that installing it needs neither package lists nor a network inside the build.
if [[ -z $base ]]; then
    base=localhost/plcemu-base:bookworm
    # "libc6 (>= 2.34), libfmt9 (>= 9.1.0+ds1)" -> "libc6,libfmt9" (first of any alternatives)
    includes=$(dpkg-deb -f "$deb" Depends | tr ',' '\n' | sed 's/|.*//; s/(.*)//; s/[[:space:]]//g' |
        grep -v '^$' | sort -u | paste -sd, -)
    have=$("$engine" image inspect --format '{{index .Labels "org.plcemu.base.includes"}}' "$base" \
        2>/dev/null || true)
    if [[ $rebuild_base == yes || $have != "$includes" ]]; then
        step "making the Debian base $base with mmdebstrap (including $includes)"
        tmp=$(mktemp -d)
        trap 'rm -rf "$tmp"' EXIT
        mirror=()
        [[ -z ${PLCEMU_DEBIAN_MIRROR:-} ]] || mirror=("$PLCEMU_DEBIAN_MIRROR")
        # As debian:bookworm-slim: minbase (Essential, apt), no recommends, no documentation, man
        # pages, info pages or translations (dpkg's path-exclude, kept in the image for later
        # installs); copyright files stay.
        # merged-usr: /usr merged with symlinks, as Debian 12 is, without the usrmerge package
        # (and the perl it needs).
        mmdebstrap --variant=minbase --format=tar --include="$includes" \
            --hook-dir=/usr/share/mmdebstrap/hooks/merged-usr \
            --aptopt='APT::Install-Recommends "false"' \
            --dpkgopt='path-exclude=/usr/share/doc/*' \
            --dpkgopt='path-include=/usr/share/doc/*/copyright' \
            --dpkgopt='path-exclude=/usr/share/man/*' \
            --dpkgopt='path-exclude=/usr/share/info/*' \
            --dpkgopt='path-exclude=/usr/share/groff/*' \
            --dpkgopt='path-exclude=/usr/share/lintian/*' \
            --dpkgopt='path-exclude=/usr/share/locale/*' \
            --dpkgopt='path-include=/usr/share/locale/locale.alias' \
            --customize-hook='rm -f "$1/etc/hostname" "$1/etc/resolv.conf"' \
            --customize-hook='rm -rf "$1"/var/log/apt/* "$1"/var/log/dpkg.log "$1"/var/cache/ldconfig/aux-cache' \
            bookworm "$tmp/base.tar" "${mirror[@]}" >&2
        "$engine" import --change 'CMD ["/bin/bash"]' \
            --change "LABEL org.plcemu.base.includes=$includes" \
            "$tmp/base.tar" "$base" >/dev/null
        rm -rf "$tmp"
        trap - EXIT
    fi
fi

step "building $image on $base"
# Podman: the docker format (the OCI format has no HEALTHCHECK), and the build step run with
# chroot isolation: it only installs a package, and needs no OCI runtime able to create a
# container (crun cannot on a host with cgroups in hybrid mode, and `podman run` is refused
# where the container's resource limits cannot be set).
format=()
[[ $engine != podman ]] || format=(--format docker --isolation chroot)
"$engine" build "${format[@]}" -f Containerfile --build-arg BASE="$base" \
    --build-arg DEB="$deb" --build-arg VERSION="$version" \
    -t "$image" -t plcemu:latest . >&2

size=$("$engine" image inspect --format '{{.Size}}' "$image")
base_size=$("$engine" image inspect --format '{{.Size}}' "$base")
step "built"
echo "$image: $((size / 1000000)) MB ($((base_size / 1000000)) MB of them the base $base)"

if [[ $run_tests == yes ]]; then
    step "testing $image (tests/system/test_containers.py)"
    plcemud=()
    [[ -x build-package/plcemud ]] && plcemud=(PLCEMUD="$PWD/build-package/plcemud")
    env "${plcemud[@]}" PLCEMU_TEST_IMAGE="$image" PLCEMU_CONTAINER_ENGINE="$engine" \
        /usr/bin/python3 -m pytest -q -p no:cacheprovider tests/system/test_containers.py >&2
fi
echo "$image"
