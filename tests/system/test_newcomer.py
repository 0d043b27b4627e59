"""What a new user meets first, followed to the letter on Debian 12: the README's one command
for the example tools (`scripts/install-deps.sh kit`), the plugin installed offline in a venv,
the README's pymodbus example, every profile named by --help, the man page and
docs/configuration.md, and scripts/plot_trace.py without matplotlib, before the first
conversion and with its legend off the curves."""

import ast
import csv
import importlib.util
import re
import shutil
import subprocess
import sys
import time

import pytest

from conftest import REPO, free_port, run_plcemud
from test_docs import render

README = (REPO / "README.md").read_text()
PLOT = REPO / "scripts" / "plot_trace.py"


def profiles():
    """Every registered profile (src/profiles/<name>/profile.cpp; src/profiles/fatek/ holds
    what the FATEK profiles share and is none)."""
    names = sorted(p.parent.name for p in (REPO / "src" / "profiles").glob("*/profile.cpp"))
    assert {"fbs", "vb", "fb"} <= set(names)
    return names


def kit():
    """The packages of scripts/install-deps.sh's `kit` set."""
    text = (REPO / "scripts" / "install-deps.sh").read_text()
    m = re.search(r"^\s+kit\) want\+=\(([^)]*)\)", text, re.M)
    assert m, "install-deps.sh has no kit set"
    return set(m.group(1).split())


def owner(path):
    r = subprocess.run(["dpkg", "-S", str(path)], capture_output=True, text=True, timeout=30)
    if r.returncode != 0:
        pytest.skip(f"{path} belongs to no Debian package here: {r.stderr.strip()}")
    return r.stdout.split(":")[0]


# The README's one command ----------------------------------------------------------------


def test_readme_names_the_kit_and_the_kit_holds_what_the_examples_import():
    """README: the examples' tools in one command, after the two commands. The kit holds the
    Debian packages of every module the plugin and the pymodbus example import, and mbpoll."""
    assert "scripts/install-deps.sh kit" in README
    assert "PYTHONPATH=python /usr/bin/python3 -m pytest -p plcemu_testing" in README
    want = kit()
    assert {"mbpoll", "python3-pytest", "python3-pymodbus", "python3-serial-asyncio"} <= want
    # The modules as this machine has them: each from a package of the kit.
    probe = ("import importlib, sys\n"
             "for m in ('pytest', 'pymodbus', 'serial_asyncio', 'yaml'):\n"
             "    print(importlib.import_module(m).__file__)\n")
    r = subprocess.run(["/usr/bin/python3", "-c", probe], capture_output=True, text=True,
                       timeout=60)
    assert r.returncode == 0, r.stderr
    for path in r.stdout.split():
        assert owner(path) in want, path
    mbpoll = shutil.which("mbpoll")
    if mbpoll:
        assert owner(mbpoll) in want


def test_pip_installs_the_plugin_offline(tmp_path):
    """README's venv command, as printed: a venv that sees Debian's pytest and pymodbus
    (3.0.0rc1, a pre-release the requirement must accept), pip with no index and no build
    isolation (Debian's setuptools); then the venv's python imports the plugin."""
    m = re.search(r"^(/usr/bin/python3 -m venv --system-site-packages v) && "
                  r"(v/bin/pip install --no-index --no-build-isolation ./python)$", README, re.M)
    assert m, "README gives no offline venv command"
    shutil.copytree(REPO / "python", tmp_path / "python",
                    ignore=shutil.ignore_patterns("build", "*.egg-info", "__pycache__"))
    env = {"PATH": "/usr/bin:/bin", "HOME": str(tmp_path), "PIP_NO_CACHE_DIR": "1",
           "PIP_DISABLE_PIP_VERSION_CHECK": "1", "LC_ALL": "C.UTF-8"}
    for cmd in (m.group(1), m.group(2)):
        r = subprocess.run(cmd.split(), cwd=tmp_path, env=env, capture_output=True, text=True,
                           timeout=300)
        assert r.returncode == 0, f"{cmd}\n{r.stdout}\n{r.stderr}"
    r = subprocess.run(
        [tmp_path / "v" / "bin" / "python", "-c",
         "import importlib.metadata as m, plcemu_testing; print(plcemu_testing.__file__);"
         "print([e.value for e in m.entry_points(group='pytest11')])"],
        env=env, capture_output=True, text=True, timeout=60)
    assert r.returncode == 0, r.stderr
    assert str(tmp_path / "v" / "lib") in r.stdout.splitlines()[0]
    assert "plcemu_testing" in r.stdout.splitlines()[1]


def test_readme_pymodbus_example_heats_and_lets_the_simulation_run_again(start_plcemud):
    """README, "A first try": the pymodbus example, as printed (but for the port), against
    config/default.yaml: ten simulated minutes heat every channel, and it ends with the
    simulation running (simulator unit 247, register 1: 0), not frozen."""
    m = re.search(r"The same with\s+pymodbus.*?```python\n(.*?)```", README, re.S)
    assert m, "README has no pymodbus example"
    code = m.group(1)
    assert "port=5020" in code
    # The console on a free port: config/default.yaml's 8020 may be taken on this machine.
    d = start_plcemud((REPO / "config" / "default.yaml").read_text(), "--http-port",
                      str(free_port()))
    r = subprocess.run([sys.executable, "-c", code.replace("port=5020", f"port={d.port}")],
                       capture_output=True, text=True, timeout=120)
    assert r.returncode == 0, r.stderr
    temperatures, outputs = (ast.literal_eval(line) for line in r.stdout.splitlines()[:2])
    assert len(temperatures) == 10 and min(temperatures) > 1000, temperatures
    assert len(outputs) == 10
    c = d.client()
    assert c.read_holding_registers(1, 1, slave=247).registers == [0]  # running
    t0 = c.read_holding_registers(3, 2, slave=247).registers
    deadline = time.monotonic() + 10
    while c.read_holding_registers(3, 2, slave=247).registers == t0:  # simulated time moves
        assert time.monotonic() < deadline, "the simulation stays frozen"
        time.sleep(0.1)


def test_readme_console_is_default_yamls_and_its_curl_answers(start_plcemud):
    """README, "A first try": config/default.yaml serves the console on 127.0.0.1:8020, the
    page named there is HTML, and the README's curl line answers ten values of R0-R9."""
    import json
    import urllib.request
    assert "http://127.0.0.1:8020/" in README
    text = (REPO / "config" / "default.yaml").read_text()
    assert re.search(r"(?m)^http:\n  bind: 127\.0\.0\.1\n  port: 8020$", text), text
    m = re.search(r"curl '127\.0\.0\.1:8020(/api/v1/[^']+)'", README)
    assert m, "README has no curl line for the console's API"
    port = free_port()
    start_plcemud(text, "--http-port", str(port))
    base = f"http://127.0.0.1:{port}"
    with urllib.request.urlopen(base + "/plcs/0/devices?from=R0&count=10", timeout=5) as r:
        assert r.headers["Content-Type"].startswith("text/html")
    with urllib.request.urlopen(base + m.group(1), timeout=5) as r:
        body = json.load(r)
    assert body["names"] == [f"R{i}" for i in range(10)]
    assert len(body["values"]) == 10


# Every profile, everywhere a user looks ----------------------------------------------------


def test_help_man_page_and_configuration_name_every_profile():
    r = run_plcemud("--help")
    assert r.returncode == 0
    # plcemud(8)'s NAME line names each family.
    name = render(REPO / "man" / "plcemud.8").split("SYNOPSIS")[0] if shutil.which("man") else None
    titles = {"fbs": "FATEK FBs", "vb": "VIGOR VB", "fb": "FATEK FB"}
    conf = (REPO / "docs" / "configuration.md").read_text()
    rows = {m.group(1): m.group(2) for m in re.finditer(r"^\| `(\w+)` \|[^|]*\|(.*)\|$", conf,
                                                        re.M)}
    for p in profiles():
        assert re.search(rf"\b{p} \(", r.stdout), f"--help: {p}"
        if name is not None:
            assert re.search(rf"{titles.get(p, p)}(?!\w)", name), f"plcemud(8) NAME: {p}"
        assert f"`{p}`" in rows["profile"], f"configuration.md, profile: {p}"
        assert f"`{p}`:" in rows["model"], f"configuration.md, model: {p}"


def test_help_says_which_map_print_map_shows_without_a_config(tmp_path):
    """--help names the profile whose map --print-map prints without -c; it is that one's."""
    r = run_plcemud("--help")
    m = re.search(r"Without -c, --print-map shows the map of profile (\w+)", r.stdout)
    assert m, r.stdout
    bare = run_plcemud("--print-map")
    cfg = tmp_path / "p.yaml"
    cfg.write_text(f"profile: {m.group(1)}\n")
    named = run_plcemud("-c", str(cfg), "--print-map")
    assert bare.returncode == named.returncode == 0
    body = [line for line in bare.stdout.splitlines() if "<built-in>" not in line]
    assert body == [line for line in named.stdout.splitlines() if str(cfg) not in line]
    other = next(p for p in profiles() if p != m.group(1))
    cfg.write_text(f"profile: {other}\n")
    assert run_plcemud("-c", str(cfg), "--print-map").stdout != bare.stdout


# scripts/plot_trace.py ---------------------------------------------------------------------


def test_plot_without_matplotlib_says_what_to_install(tmp_path):
    fake = tmp_path / "site" / "matplotlib"
    fake.mkdir(parents=True)
    (fake / "__init__.py").write_text("raise ImportError('No module named matplotlib')\n")
    (tmp_path / "t.csv").write_text("time_s,c0_pv,c0_sp,c0_or,c0_duty\n0,25,150,0,0\n")
    r = subprocess.run([sys.executable, PLOT, tmp_path / "t.csv", tmp_path / "t.png"],
                       env={"PYTHONPATH": str(tmp_path / "site"), "PATH": "/usr/bin:/bin"},
                       capture_output=True, text=True, timeout=60)
    assert r.returncode == 2
    assert "Traceback" not in r.stderr
    assert "python3-matplotlib" in r.stderr and "scripts/install-deps.sh plot" in r.stderr
    assert not (tmp_path / "t.png").exists()


def plot_module():
    pytest.importorskip("matplotlib")
    spec = importlib.util.spec_from_file_location("plot_trace", PLOT)
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def synthetic_rows(tmp_path, channels=4, first_reading_s=3):
    """A TPCTL trace whose readings are 0 until the modules' first conversion."""
    head = ["time_s"] + [f"c{c}_{k}" for c in range(channels) for k in ("pv", "sp", "or", "duty")]
    path = tmp_path / "t.csv"
    with open(path, "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(head)
        for t in range(121):
            pv = 0 if t < first_reading_s else 25 + t
            w.writerow([t] + [pv, 150, 16383, 100] * channels)
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


def test_plot_starts_each_curve_at_the_first_reading(tmp_path):
    mod = plot_module()
    assert mod.measured([0, 0, 25.0, 26.0]) == pytest.approx([float("nan")] * 2 + [25.0, 26.0],
                                                             nan_ok=True)
    assert mod.measured([0, 0, 0]) == [0, 0, 0]  # 0 throughout: a reading of 0 °C
    assert mod.measured([25.0, 0, 26.0]) == [25.0, 0, 26.0]  # a 0 after a reading stays
    fig = mod.draw(synthetic_rows(tmp_path), "t.csv")
    pv = next(line for line in fig.axes[0].get_lines() if line.get_label() == "PV")
    drawn = [y for y in pv.get_ydata() if y == y]
    assert drawn[0] == 25 + 3 and min(drawn) > 0
    assert fig.axes[0].get_ylim()[0] > 0  # the axis does not reach down to 0 °C


def test_plot_legend_covers_no_panel(tmp_path):
    mod = plot_module()
    fig = mod.draw(synthetic_rows(tmp_path), "t.csv")
    fig.canvas.draw()
    renderer = fig.canvas.get_renderer()
    legends = fig.legends + [a.get_legend() for a in fig.axes if a.get_legend()]
    assert legends
    labels = {t.get_text() for lg in legends for t in lg.get_texts()}
    assert {"PV", "SP"} <= labels
    for lg in legends:
        box = lg.get_window_extent(renderer)
        for ax in fig.axes:
            if ax.get_visible():
                assert not box.overlaps(ax.get_window_extent(renderer)), ax.get_title()
