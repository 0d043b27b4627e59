"""The documentation: plcemud(8) and plcemud.yaml(5) render without warnings and cover every
option of `plcemud --help` and every configuration key; the README stays short and every link
between README.md and docs/ leads to a page and heading that exist (docs/README.md)."""

import os
import re
import shutil
import subprocess

import pytest

from conftest import PLCEMUD, REPO

MAN = REPO / "man"
PAGES = (MAN / "plcemud.8", MAN / "plcemud.yaml.5")


def render(page) -> str:
    """The page as plain text: no hyphenation, no justification, wide lines, no overstrikes."""
    env = {**os.environ, "MANWIDTH": "250", "LC_ALL": "C.UTF-8", "MAN_KEEP_FORMATTING": ""}
    r = subprocess.run(["man", "--nh", "--nj", "-P", "cat", "-l", str(page)], env=env,
                       capture_output=True, text=True, timeout=60)
    assert r.returncode == 0, r.stderr
    text = re.sub(".\b", "", r.stdout)
    # Hyphens and minus signs as typed.
    return text.translate({0x2010: "-", 0x2212: "-", 0x2011: "-"})


def need(tool):
    if shutil.which(tool) is None:
        pytest.skip(f"{tool} is not installed (scripts/install-deps.sh test installs it)")


@pytest.mark.parametrize("page", PAGES, ids=lambda p: p.name)
def test_man_page_renders_without_warnings(page):
    need("man")
    need("groff")
    r = subprocess.run(["man", "--warnings", "-l", str(page)], capture_output=True, text=True,
                       timeout=60, env={**os.environ, "MANWIDTH": "80", "LC_ALL": "C.UTF-8"})
    assert r.returncode == 0 and r.stderr == "", r.stderr
    r = subprocess.run(["groff", "-mandoc", "-ww", "-z", str(page)], capture_output=True,
                       text=True, timeout=60)
    assert r.returncode == 0 and r.stderr == "", r.stderr


def test_a_warning_is_caught():
    """The check above can fail: an unknown macro is reported."""
    need("groff")
    r = subprocess.run(["groff", "-mandoc", "-ww", "-z"], input=".Dd June 1, 2025\n.Xyzzy\n",
                       capture_output=True, text=True, timeout=60)
    assert r.stderr != ""


def test_plcemud_8_documents_every_option_of_help():
    need("man")
    r = subprocess.run([PLCEMUD, "--help"], capture_output=True, text=True, timeout=30)
    assert r.returncode == 0
    options = set(re.findall(r"(?<![\w-])(--?[a-z][a-z-]*)", r.stdout))
    assert {"-c", "--config", "--check-config", "--print-map", "--port", "--help"} <= options
    text = render(MAN / "plcemud.8")
    missing = [o for o in sorted(options) if not re.search(rf"(?<![\w-]){o}(?![\w-])", text)]
    assert not missing, missing
    for section in ("SYNOPSIS", "OPTIONS", "SIGNALS", "ENVIRONMENT", "FILES", "EXIT STATUS",
                    "EXAMPLES"):
        assert f"\n{section}\n" in text, section
    for word in ("SIGHUP", "SIGTERM", "SIGINT", "STATE_DIRECTORY", "NOTIFY_SOCKET"):
        assert word in text, word


def top_level_keys(yaml_text):
    return {m.group(1) for m in re.finditer(r"^([a-z_]+):", yaml_text, re.M)}


def test_plcemud_yaml_5_documents_every_key():
    need("man")
    text = render(MAN / "plcemud.yaml.5")
    example = (REPO / "config" / "example.yaml").read_text()
    top = top_level_keys(example)
    assert {"profile", "modbus", "plant", "persistence", "log"} <= top
    missing = [k for k in sorted(top) if not re.search(rf"(?<![\w.]){k}(?![\w])", text)]
    assert not missing, missing
    # Every key the loader accepts (its check_keys lists and key vectors in src/config/), by
    # name, and the sections profiles read themselves (src/profiles/<name>/*_config.cpp).
    sources = [*sorted((REPO / "src" / "config").glob("*.cpp")),
               *sorted((REPO / "src" / "profiles").glob("*/*_config.cpp"))]
    source = "".join(p.read_text() for p in sources)
    accepted = set()
    for group in re.findall(r"(?:check_keys\(|std::vector<std::string> keys)[^{]*\{([^}]*)\}",
                            source):
        accepted |= set(re.findall(r'"([a-z_]+)"', group))
    assert {"frame_timeout_ms", "sync_ms", "reading_frozen", "writable", "udp"} <= accepted
    missing = [k for k in sorted(accepted) if not re.search(rf"(?<![\w]){k}(?![\w])", text)]
    assert not missing, missing
    # Every registered profile (src/profiles/<name>/profile.cpp; src/profiles/fatek/ holds what
    # the FATEK profiles share and is none).
    profiles = sorted(p.parent.name for p in (REPO / "src" / "profiles").glob("*/profile.cpp"))
    assert {"fbs", "vb"} <= set(profiles)
    for profile in profiles:
        assert re.search(rf"^\s+(\w+, )?{profile}\b", text, re.M), profile


def slug(heading):
    """GitHub's anchor for a Markdown heading."""
    h = re.sub(r"[^\w\- ]", "", heading.strip().lower())
    return h.replace(" ", "-")


def test_readme_is_short_and_every_docs_link_resolves():
    assert len((REPO / "README.md").read_text().splitlines()) < 250
    pages = [REPO / "README.md", *sorted((REPO / "docs").glob("*.md"))]
    assert len(pages) >= 8
    broken = []
    for page in pages:
        for target in re.findall(r"\]\(([^)\s]+)\)", page.read_text()):
            if re.match(r"[a-z]+:", target):
                continue
            path, _, anchor = target.partition("#")
            dest = (page.parent / path).resolve() if path else page
            if not dest.is_file():
                broken.append(f"{page.name}: {target}")
            elif anchor:
                headings = re.findall(r"^#+ (.+)$", dest.read_text(), re.M)
                if anchor not in {slug(h) for h in headings}:
                    broken.append(f"{page.name}: {target}")
    assert not broken, broken
    # The table of contents names every page.
    toc = (REPO / "docs" / "README.md").read_text()
    for page in (REPO / "docs").glob("*.md"):
        assert page.name == "README.md" or f"({page.name})" in toc, page.name
