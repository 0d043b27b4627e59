"""scripts/check-deps.sh (docs/architecture.md, "Dependencies"): it passes on this tree, and on a
small tree of its own it fails, naming the files and lines, on an include cycle between modules,
on an include against the table in each of the forms the compiler resolves, and on a folder the
table does not name; the table in docs/architecture.md is the script's."""

import re
import subprocess

import pytest

from conftest import REPO

SCRIPT = REPO / "scripts" / "check-deps.sh"

# A tree whose includes all go the way the table allows, in every form the script resolves: a
# public header, a path under src/, a file beside the includer, "..", and includes that are no
# module's (a generated header, a library's).
TREE = {
    "include/plcemu/image/image.hpp": "#pragma once\n",
    "src/image/image.cpp": '#include "plcemu/image/image.hpp"\n',
    "src/engine/engine.hpp": '#pragma once\n#include "plcemu/image/image.hpp"\n',
    "src/engine/engine.cpp": '#include "engine.hpp"\n#include <vector>\n',
    "include/plcemu/config/config.hpp": '#pragma once\n#include "plcemu/image/image.hpp"\n',
    "src/config/reader.hpp": "#pragma once\n",
    "src/config/config.cpp": '#include "plcemu/config/config.hpp"\n#include "reader.hpp"\n',
    "src/profiles/profile.cpp": '#include "plcemu/config/config.hpp"\n'
                                '#include "../engine/engine.hpp"\n',
    "src/modbus/tcp_server.hpp": '#pragma once\n  #  include "plcemu/image/image.hpp"\n',
    "src/daemon/main.cpp": '#include "modbus/tcp_server.hpp"\n#include "version.hpp"\n'
                           '#include <asio.hpp>\n// #include "plcemu/daemon/none.hpp"\n',
}


def make_tree(root, extra=None):
    for path, text in {**TREE, **(extra or {})}.items():
        f = root / path
        f.parent.mkdir(parents=True, exist_ok=True)
        f.write_text(text)
    return root


def check(root):
    return subprocess.run(["bash", str(SCRIPT), str(root)], capture_output=True, text=True,
                          timeout=60)


def test_passes_on_this_tree():
    r = check(REPO)
    assert r.returncode == 0, r.stderr
    assert "no cycle" in r.stdout


def test_passes_on_a_tree_that_keeps_the_direction(tmp_path):
    r = check(make_tree(tmp_path))
    assert r.returncode == 0, r.stderr
    # image, engine, config, profiles, modbus and daemon: each include form above was counted.
    assert r.stdout.startswith("check-deps: 6 module dependencies")


def test_fails_on_a_cycle_naming_each_include(tmp_path):
    root = make_tree(tmp_path, {
        "include/plcemu/profiles/profile.hpp": '#pragma once\n#include "plcemu/config/config.hpp"\n',
        "src/config/config.cpp": '#include "plcemu/config/config.hpp"\n'
                                 '#include "plcemu/profiles/profile.hpp"\n',
    })
    r = check(root)
    assert r.returncode == 1
    cycle = r.stderr[r.stderr.index("include cycle"):]
    assert cycle.startswith("include cycle between modules: config -> profiles -> config\n")
    assert '  config -> profiles:\n    src/config/config.cpp:2: #include "plcemu/profiles/' in cycle
    assert ('  profiles -> config:\n    include/plcemu/profiles/profile.hpp:2: #include '
            '"plcemu/config/config.hpp"\n    src/profiles/profile.cpp:1: ') in cycle


@pytest.mark.parametrize("include", [
    '#include "plcemu/config/config.hpp"',  # a public header
    '#include "config/reader.hpp"',  # a path under src/
    '#include "../config/reader.hpp"',  # beside the includer
    '#include <plcemu/config/config.hpp>',
])
def test_fails_on_an_include_against_the_table(tmp_path, include):
    root = make_tree(tmp_path, {"src/engine/engine.cpp": f'#include "engine.hpp"\n{include}\n'})
    r = check(root)
    assert r.returncode == 1
    assert r.stderr == ("check-deps: engine includes config, against the table (engine may "
                        f"include: image):\n  src/engine/engine.cpp:2: {include}\n")


def test_fails_on_a_module_the_table_does_not_name(tmp_path):
    root = make_tree(tmp_path, {"src/opcua/frame.cpp": '#include "plcemu/image/image.hpp"\n'})
    r = check(root)
    assert r.returncode == 1
    assert "check-deps: src/opcua/: module 'opcua' is not in the table" in r.stderr


def test_the_table_in_the_docs_is_the_scripts():
    text = (REPO / "docs" / "architecture.md").read_text()
    section = text[text.index("\n## Dependencies\n"):]
    section = section[:section.find("\n## ", 1)]
    docs = {m: set(re.findall(r"`(\w+)`", deps))
            for m, deps in re.findall(r"^\| `(\w+)` \| (.*) \|$", section, re.M)}
    r = subprocess.run(["bash", str(SCRIPT), "--table"], capture_output=True, text=True,
                       timeout=60)
    assert r.returncode == 0
    script = {}
    for line in r.stdout.splitlines():
        module, _, deps = line.partition(":")
        script[module] = set(deps.split())
    assert len(script) >= 9
    assert docs == script
