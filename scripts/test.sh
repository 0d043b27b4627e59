#!/usr/bin/env bash
# Builds with AddressSanitizer and UndefinedBehaviorSanitizer, checks the direction of the
# dependencies (scripts/check-deps.sh) and style (scripts/style.sh) and runs every test: unit
# tests (GoogleTest, through ctest, with the fuzz harnesses' corpora replayed), the Debian
# package (scripts/test-package.sh) and system tests (pytest + pymodbus against the real daemon).
# Exits non-zero on any failure.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/install-deps.sh test

# The builds below (sanitized, the package's Release) go through ccache,
# keyed on paths relative to the checkout, so a second run or another clone on the same
# machine compiles only what changed. CMake reads these variables
# when it configures a build directory.
if command -v ccache >/dev/null; then
    export CMAKE_CXX_COMPILER_LAUNCHER=ccache CMAKE_C_COMPILER_LAUNCHER=ccache
    export CCACHE_BASEDIR=$PWD CCACHE_NOHASHDIR=1
fi

# Each step says how long it took, so a slow one shows in CI's log.
step_start=$SECONDS
step() {
    echo "== $1 (the step before took $((SECONDS - step_start)) s)"
    step_start=$SECONDS
}

build=build-test
# -O1 (RelWithDebInfo's -O2 otherwise), as AddressSanitizer's own docs advise: the optimizer's
# passes over instrumented code were most of this build's time, and -O1 takes a third off the
# slowest files (tcp_listener.cpp 29.7 -> 20.3 s, config.cpp 20.3 -> 13.9 s, listing_test.cpp
# 18.1 -> 11.7 s) while the stacks keep their lines (-g). The package's build stays -O2.
cmake -S . -B "$build" -DCMAKE_BUILD_TYPE=RelWithDebInfo -DPLCEMU_SANITIZE=ON -DPLCEMU_WERROR=ON \
    -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O1 -g -DNDEBUG" -DPLCEMU_TESTS=ON >/dev/null
cmake --build "$build" -j"$(nproc)"

step "dependencies"
# Include cycles between modules and includes against the direction of docs/architecture.md,
# "Dependencies" (no build needed).
scripts/check-deps.sh

step "style"
# clang-format over the tree and clang-tidy over src/ (using $build/compile_commands.json).
scripts/style.sh "$build"

export ASAN_OPTIONS=detect_leaks=1:abort_on_error=1
export UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1

step "unit tests"
(cd "$build" && ctest --output-on-failure -j"$(nproc)" --timeout 300)

if [[ ${PLCEMU_TEST_PACKAGE:-1} == 1 ]]; then
    # Builds the .deb (Release, incrementally in build-package/), runs lintian (errors fail),
    # installs, runs and purges it on this machine. A cold build-package/ takes minutes;
    # PLCEMU_TEST_PACKAGE=0 skips it.
    step "package"
    scripts/test-package.sh --reuse-build
fi

# The fuzz harnesses' seeds and saved crash inputs are replayed by the unit tests above
# (fuzz_replay.*, built with this build's sanitizers). Fuzzing needs its own clang build, most of
# ten minutes from a cold clone: PLCEMU_FUZZ_SECONDS=N adds a run of N s a harness here;
# scripts/fuzz.sh is the fuzzer's own command.
if [[ -n ${PLCEMU_FUZZ_SECONDS:-} ]]; then
    step "fuzz"
    scripts/fuzz.sh "$PLCEMU_FUZZ_SECONDS"
fi

step "system tests"
# Debian's pytest and pymodbus belong to /usr/bin/python3.
PLCEMUD="$PWD/$build/plcemud" /usr/bin/python3 -m pytest -q -p no:cacheprovider tests/system
