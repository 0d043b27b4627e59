#!/usr/bin/env bash
# Builds the Debian package build/plcemu_<version>_<arch>.deb: plcemud (Release, Debian's
# hardening flags), the units, /etc/plcemu/plcemud.yaml (a conffile), the example configurations,
# the man pages and the docs. Prints the package's path on its last line.
#
# CPack's DEB generator (cmake/Packaging.cmake) rather than dpkg-buildpackage: the package comes
# from the same CMake install rules as every other install, with no debian/ tree to keep in sync.
# It builds in a fresh build-package/, so nothing of an earlier build leaks in (--reuse-build:
# an incremental build in the build-package/ there is, for scripts/test.sh).
#
# Usage: scripts/package.sh [--lintian] [--reuse-build]
#   --lintian                               also run lintian on the package (errors fail)
#   PLCEMU_MAINTAINER="Name <address>"      Maintainer field (default: the last commit's author)
#   PLCEMU_WERROR=OFF                       let compiler warnings pass (default: they fail the
#                                           build, as in the test build, so that the Release
#                                           build stays as clean as it)
set -euo pipefail
cd "$(dirname "$0")/.."

lint=no
reuse=no
for a in "$@"; do
    case "$a" in
        --lintian) lint=yes ;;
        --reuse-build) reuse=yes ;;
        *) echo "package: unknown argument '$a'" >&2; exit 2 ;;
    esac
done

scripts/install-deps.sh run package

maintainer=${PLCEMU_MAINTAINER:-$(git log -1 --format='%an <%ae>' 2>/dev/null || true)}
maintainer=${maintainer:-plcemu maintainers <maintainers@localhost>}
# Reproducible: file times and the changelog date are those of the last commit.
SOURCE_DATE_EPOCH=${SOURCE_DATE_EPOCH:-$(git log -1 --format=%ct 2>/dev/null || date +%s)}
export SOURCE_DATE_EPOCH

# Debian's build flags (fortify, stack protector, relro, bindnow, PIE), as a Debian package
# built by debhelper gets them.
export DEB_BUILD_MAINT_OPTIONS=hardening=+all
cppflags=$(dpkg-buildflags --get CPPFLAGS)
cxxflags=$(dpkg-buildflags --get CXXFLAGS)
ldflags=$(dpkg-buildflags --get LDFLAGS)

build=build-package
[[ $reuse == yes ]] || rm -rf "$build"
rm -f "$build"/plcemu_*.deb
cmake -S . -B "$build" -DCMAKE_BUILD_TYPE=Release -DPLCEMU_TESTS=OFF -DPLCEMU_PACKAGE=ON \
    -DPLCEMU_WERROR="${PLCEMU_WERROR:-ON}" \
    -DCMAKE_INSTALL_PREFIX=/usr -DPLCEMU_MAINTAINER="$maintainer" \
    -DCMAKE_CXX_FLAGS="$cppflags $cxxflags" -DCMAKE_EXE_LINKER_FLAGS="$ldflags" >/dev/null
cmake --build "$build" -j"$(nproc)" >/dev/null
(cd "$build" && cpack -G DEB >/dev/null)

mkdir -p build
deb=$(ls "$build"/plcemu_*.deb)
mv -f "$deb" build/
deb=build/$(basename "$deb")
if [[ $lint == yes ]]; then
    # Errors fail the build; warnings are listed (docs/operations.md, "Packaging", says why
    # those that remain are there).
    lintian --fail-on error --tag-display-limit 0 "$deb" >&2
fi
echo "$deb"
