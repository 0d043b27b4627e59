#!/usr/bin/env bash
# Builds plcemud (Release) and runs it with config/default.yaml on 127.0.0.1:5020, logging to
# the terminal. Extra arguments go to plcemud (e.g. --time-scale 60).
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/install-deps.sh run
cmake -S . -B build-release -DCMAKE_BUILD_TYPE=Release -DPLCEMU_TESTS=OFF >/dev/null
cmake --build build-release -j"$(nproc)" --target plcemud
exec build-release/plcemud -c config/default.yaml "$@"
