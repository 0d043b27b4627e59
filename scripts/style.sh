#!/usr/bin/env bash
# The style checks CI runs (scripts/test.sh runs this), with the tools scripts/install-deps.sh
# installs:
#   clang-format-14 --dry-run --Werror over every C++ file of the tree (tracked or new, not
#     ignored): any difference from .clang-format fails;
#   clang-tidy-14 over src/ with the checks of .clang-tidy (and src/*/.clang-tidy), using the
#     build's compile_commands.json: any finding fails.
# Fix a format difference with: clang-format-14 -i FILE
#
# Usage: scripts/style.sh [--format-only] [BUILD_DIR]   (BUILD_DIR: default build-test; it needs
#        a configured build, e.g. the one scripts/test.sh makes)
#   PLCEMU_TIDY_JOBS=N   clang-tidy processes at once (default: the number of cores)
set -euo pipefail
cd "$(dirname "$0")/.."

tidy=yes
build=build-test
for a in "$@"; do
    case "$a" in
        --format-only) tidy=no ;;
        -*) echo "style: unknown option '$a'" >&2; exit 2 ;;
        *) build=$a ;;
    esac
done
scripts/install-deps.sh style

status=0
files=()
while IFS= read -r f; do
    [[ -f $f ]] && files+=("$f")  # a tracked file deleted from the tree is not checked
done < <(git ls-files -co --exclude-standard -- '*.cpp' '*.hpp' '*.h' '*.cc')
echo "== clang-format-14: ${#files[@]} files"
if ! clang-format-14 --dry-run --Werror "${files[@]}"; then
    echo "style: clang-format differences (fix: clang-format-14 -i FILE)" >&2
    status=1
fi

if [[ $tidy == yes ]]; then
    db=$build/compile_commands.json
    [[ -f $db ]] || { echo "style: no $db (configure $build first)" >&2; exit 2; }
    # The translation units under src/ that the build compiles.
    mapfile -t units < <(/usr/bin/python3 -c '
import json, os, sys
seen = set()
for e in json.load(open(sys.argv[1])):
    f = os.path.normpath(os.path.join(e["directory"], e["file"]))
    if f.startswith(sys.argv[2] + "/") and f not in seen and os.path.exists(f):
        seen.add(f)
        print(f)' "$db" "$PWD/src")
    jobs=${PLCEMU_TIDY_JOBS:-$(nproc)}
    echo "== clang-tidy-14: ${#units[@]} files, $jobs at a time"
    out=$(mktemp)
    trap 'rm -f "$out"' EXIT
    start=$SECONDS
    if ! printf '%s\0' "${units[@]}" |
        xargs -0 -n1 -P"$jobs" clang-tidy-14 -p "$build" --quiet --use-color=false >"$out" 2>&1
    then
        # Each finding once (a header's is reported from every file that includes it).
        grep -E '^[^ ].*: (warning|error): ' "$out" | sort -u >&2 || cat "$out" >&2
        echo "style: clang-tidy findings (checks: .clang-tidy)" >&2
        status=1
    fi
    echo "== clang-tidy-14: $((SECONDS - start)) s"
fi
exit $status
