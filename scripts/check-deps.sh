#!/usr/bin/env bash
# Checks the direction of the dependencies between the modules of src/ (docs/architecture.md,
# "Dependencies"). A module is a folder src/<module>/ with its public headers in
# include/plcemu/<module>/; the graph is read off every `#include "..."` (and `<...>`) line of
# their files, resolved as the compiler does: beside the including file, then include/, then
# src/ (so "plcemu/config/config.hpp", "modbus/mbap.hpp" and "operands.hpp" all count; an
# include found in none of them, such as the generated version.hpp or a library's, is not a
# module's). Fails (exit 1), naming the files and lines, on
#   - an include cycle between modules;
#   - an include the table below does not allow;
#   - a folder under src/ or include/plcemu/ the table does not name.
# No build and no network: it reads the tree. scripts/test.sh runs it.
#
# Usage: scripts/check-deps.sh [ROOT]   check the tree at ROOT (default: this checkout)
#        scripts/check-deps.sh --table  print the table below, one module a line
set -euo pipefail

# What each module may include besides itself; a module not listed right of the colon of a line
# may not be included by that line's module. The table has no cycle (checked below). Keep it as
# docs/architecture.md, "Dependencies", shows it. A new module (say src/fatek/) is one line: the
# modules it may include; then add it to the lines of the modules that may include it (daemon).
readonly TABLE='
image:
engine:       image
instructions: engine image
plant:        engine image
modbus:       image
config:       plant image
profiles:     config instructions plant modbus engine image
simulator:    profiles listener modbus plant engine image
listener:     config modbus plant engine image
modbus_slave: listener modbus image
fatek:        listener engine image
http:         listener config modbus plant engine image
daemon:       http fatek modbus_slave listener simulator profiles config modbus instructions plant engine image
'

declare -A allowed=()  # module -> " m1 m2 ... " (spaces around each name)
modules=()             # in the order of the table
while read -r name deps; do
    [[ -z $name ]] && continue
    name=${name%:}
    modules+=("$name")
    allowed[$name]=" $deps "
done <<<"$TABLE"

if [[ ${1:-} == --table ]]; then
    for m in "${modules[@]}"; do
        read -ra d <<<"${allowed[$m]}"
        printf '%s:' "$m"
        for x in "${d[@]}"; do printf ' %s' "$x"; done
        echo
    done
    exit 0
fi
case ${1:-} in
    -*) echo "usage: scripts/check-deps.sh [ROOT] | --table" >&2; exit 2 ;;
esac
root=${1:-$(dirname "$0")/..}
cd "$root" || exit 2
[[ -d src ]] || { echo "check-deps: no src/ under $root" >&2; exit 2; }

status=0
fail() {
    echo "check-deps: $*" >&2
    status=1
}

# The include lines of an edge, each indented by $1 spaces, in $shown.
list_sites() {
    local pad
    printf -v pad '%*s' "$1" ''
    shown="${2%$'\n'}"
    shown="$pad${shown//$'\n'/$'\n'$pad}"
}

# The module of a path relative to the root, in $module ("" when it is none's).
module_of() {
    module=""
    case $1 in
        src/*/*) module=${1#src/} ;;
        include/plcemu/*/*) module=${1#include/plcemu/} ;;
        *) return 0 ;;
    esac
    module=${module%%/*}
}

# A path with "." and ".." steps removed, in $normal.
normalise() {
    local -a out=()
    local part
    local IFS=/
    for part in $1; do
        case $part in
            '' | .) ;;
            ..) ((${#out[@]})) && unset 'out[${#out[@]}-1]' ;;
            *) out+=("$part") ;;
        esac
    done
    normal="${out[*]}"
}

# Every folder is a module of the table.
for dir in src/*/ include/plcemu/*/; do
    [[ -d $dir ]] || continue
    module_of "$dir."
    if [[ -z ${allowed[$module]+x} ]]; then
        fail "$dir: module '$module' is not in the table at the top of scripts/check-deps.sh" \
            "(add a line: what it may include; docs/architecture.md, \"Dependencies\")"
    fi
done

# The graph: sites["from>to"] lists "file:line: #include ..." lines, one per include.
declare -A sites=()
while IFS= read -r hit; do
    file=${hit%%:*}
    rest=${hit#*:}
    line=${rest%%:*}
    text=${rest#*:}
    module_of "$file"
    from=$module
    [[ -z $from ]] && continue
    if [[ $text =~ include[[:space:]]*\"([^\"]+)\" ]]; then
        name=${BASH_REMATCH[1]}
        candidates=("${file%/*}/$name" "include/$name" "src/$name")
    elif [[ $text =~ include[[:space:]]*\<([^\>]+)\> ]]; then
        name=${BASH_REMATCH[1]}
        candidates=("include/$name" "src/$name")
    else
        continue
    fi
    to=""
    for c in "${candidates[@]}"; do
        if [[ -f $c ]]; then
            if [[ $c == *..* || $c == */./* ]]; then
                normalise "$c"
                c=$normal
            fi
            module_of "$c"
            to=$module
            break
        fi
    done
    [[ -z $to || $to == "$from" ]] && continue
    sites["$from>$to"]+="$file:$line: ${text#"${text%%[![:space:]]*}"}"$'\n'
done < <(find src include -type f \( -name '*.hpp' -o -name '*.cpp' -o -name '*.h' \
    -o -name '*.cc' -o -name '*.ipp' -o -name '*.in' \) -print0 2>/dev/null | sort -z |
    xargs -0 -r grep -nE '^[[:space:]]*#[[:space:]]*include[[:space:]]*["<]' /dev/null || true)

# (b) Includes against the table.
for edge in "${!sites[@]}"; do
    from=${edge%>*}
    to=${edge#*>}
    [[ -z ${allowed[$from]+x} ]] && continue  # refused above as a module without a line
    if [[ ${allowed[$from]} != *" $to "* ]]; then
        read -ra d <<<"${allowed[$from]}"
        list_sites 2 "${sites[$edge]}"
        fail "$from includes $to, against the table ($from may include: ${d[*]:-nothing}):"$'\n'"$shown"
    fi
done

# (a) Cycles: a depth-first walk; an edge back to a module on the walk's path closes a cycle,
# reported with the includes that make each of its edges. $1: "graph" (the includes) or "table".
declare -A colour=()
path=()
cycles=0
successors() {
    local m=$1 kind=$2 e
    next=()
    if [[ $kind == table ]]; then
        read -ra next <<<"${allowed[$m]:-}"
    else
        for e in "${!sites[@]}"; do
            [[ ${e%>*} == "$m" ]] && next+=("${e#*>}")
        done
    fi
    return 0
}
visit() {
    local m=$1 kind=$2 n i start
    colour[$m]=grey
    path+=("$m")
    successors "$m" "$kind"
    local -a mine=("${next[@]}")
    for n in "${mine[@]}"; do
        if [[ ${colour[$n]:-white} == grey ]]; then
            for i in "${!path[@]}"; do [[ ${path[$i]} == "$n" ]] && start=$i; done
            local -a cycle=("${path[@]:$start}" "$n")
            cycles=$((cycles + 1))
            local IFS=' '
            local chain="${cycle[*]}"
            chain=${chain// / -> }
            if [[ $kind == table ]]; then
                fail "the table at the top of scripts/check-deps.sh has a cycle: $chain"
            else
                local msg="include cycle between modules: $chain"
                for ((i = 0; i + 1 < ${#cycle[@]}; i++)); do
                    list_sites 4 "${sites["${cycle[$i]}>${cycle[$i + 1]}"]}"
                    msg+=$'\n'"  ${cycle[$i]} -> ${cycle[$i + 1]}:"$'\n'"$shown"
                done
                fail "$msg"
            fi
        elif [[ ${colour[$n]:-white} == white ]]; then
            visit "$n" "$kind"
        fi
    done
    unset 'path[${#path[@]}-1]'
    colour[$m]=black
}
for m in "${modules[@]}"; do
    [[ ${colour[$m]:-white} == white ]] && visit "$m" table
done
colour=()
graph_modules=()
for e in "${!sites[@]}"; do graph_modules+=("${e%>*}"); done
for m in $(printf '%s\n' "${graph_modules[@]}" | sort -u); do
    [[ ${colour[$m]:-white} == white ]] && visit "$m" graph
done

if ((status == 0)); then
    echo "check-deps: ${#sites[@]} module dependencies, no cycle, each as the table allows"
fi
exit "$status"
