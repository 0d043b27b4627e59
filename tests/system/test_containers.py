"""The container image, compose.yaml and deploy/kubernetes/ (docs/operations.md, "Containers and
Kubernetes").

Always run: every configuration under deploy/ passes --check-config; the compose plant runs on
loopback, the dryer's MBUS reading the oven; the Containerfile, compose.yaml and the manifests
name the same image, user, ports and volumes. With podman-compose: `podman-compose config`
passes. With Debian's python3-kubernetes: every manifest loads into its typed models, no field
unknown.

With PLCEMU_TEST_IMAGE=plcemu:<version> (`scripts/container.sh --test` builds the image and sets
it; a multi-minute build has no place in scripts/test.sh): the image's configuration and files
(through `podman image mount`), and the daemon started from a copy of its root file system with
chroot, as the image's user (this machine refuses `podman run`): it answers Modbus and the
HEALTHCHECK on loopback, logs to stdout and exits 0 on SIGTERM with its state synced.
"""

import copy
import ipaddress
import json
import os
import re
import shutil
import signal
import socket
import subprocess
import time
from pathlib import Path

import pytest
import yaml

from conftest import PLCEMUD, REPO, free_port, port_open, raw_request

CONTAINERFILE = (REPO / "Containerfile").read_text()
KUBE = REPO / "deploy" / "kubernetes"
COMPOSE_CONFIGS = REPO / "deploy" / "compose"
VERSION = re.search(r"project\(plcemu VERSION ([0-9.]+)", (REPO / "CMakeLists.txt").read_text())[1]
IMAGE = os.environ.get("PLCEMU_TEST_IMAGE", "")
ENGINE = os.environ.get("PLCEMU_CONTAINER_ENGINE", "podman")


def containerfile(instruction):
    """The arguments of every `instruction` line of the Containerfile (continuations joined)."""
    text = CONTAINERFILE.replace("\\\n", " ")
    return [m[1].strip() for m in re.finditer(rf"^{instruction}\s+(.*)$", text, re.M)]


IMAGE_UID = int(re.search(r"^ARG PLCEMU_UID=(\d+)$", CONTAINERFILE, re.M)[1])
EXPOSED = sorted(int(p.split("/")[0]) for p in containerfile("EXPOSE")[0].split())
VOLUMES = json.loads(containerfile("VOLUME")[0])
CONFIG_PATH = json.loads(containerfile("CMD")[0])[1]


def listen_ports(config):
    """The TCP ports a config (a dict) listens on: Modbus, FATEK and console."""
    ports = set()
    for plc in config.get("plcs", [config]):
        for section in ("modbus", "fatek"):
            tcp = (plc.get(section) or {}).get("tcp") or {}
            if tcp.get("enabled", True) and (section == "modbus" or tcp):
                ports.add(tcp.get("port", 502))
        if "http" in plc:
            ports.add(plc["http"].get("port", 8020))
    if "http" in config:
        ports.add(config["http"].get("port", 8020))
    return ports


def kube_docs():
    docs = []
    for path in sorted(KUBE.glob("*.yaml")):
        docs += [(path.name, d) for d in yaml.safe_load_all(path.read_text()) if d]
    return docs


def kube(kind, name=None):
    found = [d for _, d in kube_docs() if d["kind"] == kind
             and (name is None or d["metadata"]["name"] == name)]
    assert found, (kind, name)
    return found


def group_config():
    return kube("ConfigMap", "plcemu-group")[0]["data"]["plcemud.yaml"]


# --- every configuration under deploy/ is valid and the plant they make works ------------------

def deploy_configs():
    configs = {p.name: p.read_text() for p in sorted(COMPOSE_CONFIGS.glob("*.yaml"))}
    configs["configmap.yaml"] = group_config()
    return configs


@pytest.mark.parametrize("name", sorted(deploy_configs()))
def test_every_deploy_configuration_passes_check_config(name, tmp_path):
    if not os.access(PLCEMUD, os.X_OK):
        pytest.skip(f"no plcemud at {PLCEMUD}")
    path = tmp_path / "plcemud.yaml"
    path.write_text(deploy_configs()[name])
    r = subprocess.run([PLCEMUD, "-c", path, "--check-config"], capture_output=True, text=True,
                       timeout=30, env={**os.environ, "STATE_DIRECTORY": str(tmp_path)})
    assert r.returncode == 0, r.stdout + r.stderr
    # Every listener on every address of the container, so that published ports reach it.
    for bind in re.findall(r"bind:\s*([0-9.:]+)", deploy_configs()[name]):
        assert bind == "0.0.0.0", (name, bind)


def on_loopback(config, ports):
    """The config with every listener on 127.0.0.1 and its ports mapped through `ports`."""
    config = copy.deepcopy(config)
    for plc in [config, *config.get("plcs", [])]:
        # New dicts, not edits: entries share sections through YAML aliases.
        if "http" in plc:
            plc["http"] = {"bind": "127.0.0.1", "port": ports[plc["http"]["port"]]}
        tcp = (plc.get("modbus") or {}).get("tcp")
        if tcp:
            plc["modbus"] = {**plc["modbus"],
                             "tcp": {**tcp, "bind": "127.0.0.1", "port": ports[tcp["port"]]}}
    return config


def test_the_compose_plant_runs_on_loopback_and_the_dryer_polls_the_oven(start_plcs,
                                                                         start_plcemud):
    """The three configurations of compose.yaml, moved to loopback: the oven line's ovens answer
    on their ports, the dryer's MBUS brings oven-1's R0-R9 into D2000-D2009, and the press
    line's shared port routes by unit ID."""
    if not os.access(PLCEMUD, os.X_OK):
        pytest.skip(f"no plcemud at {PLCEMUD}")
    ovens = yaml.safe_load((COMPOSE_CONFIGS / "oven-line.yaml").read_text())
    oven_ports = {5020: free_port(), 5021: free_port(), 8020: free_port()}
    start_plcs(yaml.safe_dump(on_loopback(ovens, oven_ports)), [oven_ports[5020], oven_ports[5021]],
               name="oven-line")

    dryer = yaml.safe_load((COMPOSE_CONFIGS / "dryer.yaml").read_text())
    compose = yaml.safe_load((REPO / "compose.yaml").read_text())
    oven_ip = compose["services"]["oven-line"]["networks"]["plant"]["ipv4_address"]
    assert dryer["mbus"]["tcp"] == {"host": oven_ip, "port": 5020}
    dryer = on_loopback(dryer, {5020: 0, 8020: free_port()})
    dryer["mbus"]["tcp"] = {"host": "127.0.0.1", "port": oven_ports[5020]}
    d = start_plcemud(yaml.safe_dump(dryer))  # --port gives its Modbus port
    c = d.client()

    from pymodbus.client import ModbusTcpClient
    oven = ModbusTcpClient("127.0.0.1", port=oven_ports[5020], timeout=3)
    assert oven.connect()
    try:
        # oven-1's temperatures (R0-R9, 0.1 degC; at 25.0 degC for the plant's first minute).
        deadline = time.monotonic() + 20
        while time.monotonic() < deadline:
            want = oven.read_holding_registers(0, 10, slave=1).registers
            got = c.read_holding_registers(2000, 10, slave=1).registers  # D2000-D2009
            if got == want and min(want) >= 200:  # the readings have come, and reached D
                break
            time.sleep(0.1)
        assert got == want and min(want) >= 200, (got, want, d.log_text())
        assert c.read_holding_registers(1100, 1, slave=1).registers == [0]  # S2+0: no failure
    finally:
        oven.close()

    presses = yaml.safe_load((COMPOSE_CONFIGS / "press-line.yaml").read_text())
    press_ports = {5020: free_port(), 8020: free_port()}
    start_plcs(yaml.safe_dump(on_loopback(presses, press_ports)), [press_ports[5020]],
               name="press-line")
    for unit in (1, 2, 3):
        assert raw_request(press_ports[5020], bytes([6, 0, 100, 0, unit]), unit=unit) == \
            bytes([6, 0, 100, 0, unit])
    for unit in (1, 2, 3):
        assert raw_request(press_ports[5020], bytes([3, 0, 100, 0, 1]), unit=unit) == \
            bytes([3, 2, 0, unit])
    assert raw_request(press_ports[5020], bytes([3, 0, 100, 0, 1]), unit=9) == bytes([0x83, 0x0B])


# --- the files agree with each other -----------------------------------------------------------

def test_the_containerfile_runs_a_fixed_non_root_user_with_a_state_volume_and_a_healthcheck():
    assert IMAGE_UID >= 1000
    assert containerfile("USER") == ["${PLCEMU_UID}:${PLCEMU_UID}"]
    assert VOLUMES == ["/var/lib/plcemu"]
    assert "STATE_DIRECTORY=/var/lib/plcemu" in containerfile("ENV")
    assert CONFIG_PATH == "/etc/plcemu/plcemud.yaml"
    assert EXPOSED == [5020, 8020]
    assert containerfile("HEALTHCHECK") and containerfile("STOPSIGNAL") == ["SIGTERM"]
    # The context is the package and deploy/container/, not the tree with its build directories.
    ignore = [l for l in (REPO / ".dockerignore").read_text().splitlines()
              if l and not l.startswith("#")]
    assert ignore == ["*", "!build/plcemu_*.deb", "!deploy/container/"]
    # The image's config: the package's default example on every address, same ports.
    head = (REPO / "deploy" / "container" / "plcemud.yaml.head").read_text()
    assert all(line.startswith("#") for line in head.splitlines())
    default = yaml.safe_load((REPO / "config" / "default.yaml").read_text())
    assert listen_ports(default) == set(EXPOSED)


def test_compose_yaml_names_the_image_its_volumes_and_ports_consistently():
    compose = yaml.safe_load((REPO / "compose.yaml").read_text())
    services = compose["services"]
    assert set(services) == {"oven-line", "dryer", "press-line"}
    subnet = ipaddress.ip_network(compose["networks"]["plant"]["ipam"]["config"][0]["subnet"])
    for name, service in services.items():
        assert service["image"] == "plcemu:latest"
        config_mounts = [v for v in service["volumes"] if f":{CONFIG_PATH}:" in v]
        assert len(config_mounts) == 1, name
        source = config_mounts[0].split(":")[0]
        assert (REPO / source).is_file(), source
        config = yaml.safe_load((REPO / source).read_text())
        state = [v for v in service["volumes"] if v.split(":")[1] == VOLUMES[0]]
        assert len(state) == 1 and state[0].split(":")[0] in compose["volumes"], name
        published = {int(str(p).split(":")[-1]) for p in service["ports"]}
        assert published == listen_ports(config), name
        # The consoles only on the host's loopback.
        for p in service["ports"]:
            if str(p).endswith(":8020"):
                assert str(p).startswith("127.0.0.1:"), (name, p)
        networks = service["networks"]
        assert "plant" in networks, name
        if isinstance(networks, dict) and networks["plant"]:
            assert ipaddress.ip_address(networks["plant"]["ipv4_address"]) in subnet
    # Each service's volume is its own.
    states = [v.split(":")[0] for s in services.values() for v in s["volumes"]
              if v.split(":")[1] == VOLUMES[0]]
    assert len(set(states)) == 3


def test_the_kubernetes_manifests_name_the_image_its_user_ports_and_volumes_consistently():
    sts = kube("StatefulSet", "plcemu")[0]
    pod = sts["spec"]["template"]
    labels = pod["metadata"]["labels"]
    assert sts["spec"]["selector"]["matchLabels"].items() <= labels.items()
    (container,) = pod["spec"]["containers"]
    assert container["image"] == f"plcemu:{VERSION}"
    assert container["args"] == ["-c", CONFIG_PATH]
    ports = {p["name"]: p["containerPort"] for p in container["ports"]}
    assert sorted(ports.values()) == EXPOSED
    # The ConfigMap's config listens on exactly those ports.
    assert listen_ports(yaml.safe_load(group_config())) == set(EXPOSED)
    security = pod["spec"]["securityContext"]
    assert security["runAsUser"] == security["runAsGroup"] == security["fsGroup"] == IMAGE_UID
    assert security["runAsNonRoot"] is True
    mounts = {m["name"]: m["mountPath"] for m in container["volumeMounts"]}
    assert mounts["state"] == VOLUMES[0]
    assert mounts["config"] == str(Path(CONFIG_PATH).parent)
    (claim,) = sts["spec"]["volumeClaimTemplates"]
    assert claim["metadata"]["name"] == "state"
    (config_volume,) = pod["spec"]["volumes"]
    assert config_volume["name"] == "config"
    assert "plcemud.yaml" in kube("ConfigMap", config_volume["configMap"]["name"])[0]["data"]
    for probe in ("startupProbe", "readinessProbe", "livenessProbe"):
        action = container[probe].get("httpGet") or container[probe]["tcpSocket"]
        assert action["port"] in ports, probe
    assert container["readinessProbe"]["httpGet"]["path"] == "/healthz"
    # The Services select these pods and name their ports.
    headless = kube("Service", sts["spec"]["serviceName"])[0]
    assert headless["spec"]["clusterIP"] == "None"
    for service in kube("Service"):
        selector = service["spec"]["selector"]
        assert {k: v for k, v in selector.items()
                if k != "statefulset.kubernetes.io/pod-name"}.items() <= labels.items()
        for p in service["spec"]["ports"]:
            assert p["targetPort"] in ports, (service["metadata"]["name"], p)
    assert kube("Service", "plcemu-0")[0]["spec"]["selector"][
        "statefulset.kubernetes.io/pod-name"] == "plcemu-0"
    # Requests are set, and memory has a limit.
    assert {"cpu", "memory"} <= container["resources"]["requests"].keys()
    assert "memory" in container["resources"]["limits"]


# --- podman-compose and the Kubernetes typed models ---------------------------------------------

def test_podman_compose_reads_compose_yaml(tmp_path):
    """`podman-compose config` passes where podman-compose has that command (1.1 and later).
    Debian 12's podman-compose 1.0.3 has none: there the file is parsed and resolved as every
    command does first (`ps` of a project nobody runs)."""
    if shutil.which("podman-compose") is None or shutil.which("podman") is None:
        pytest.skip("podman-compose is not installed (scripts/install-deps.sh test)")
    usage = subprocess.run(["podman-compose", "--help"], capture_output=True, text=True,
                           timeout=60).stdout
    compose = ["podman-compose", "-f", str(REPO / "compose.yaml")]
    if re.search(r"[{,]config[,}]", usage):
        r = subprocess.run([*compose, "config"], capture_output=True, text=True, timeout=60,
                           cwd=tmp_path)
        assert r.returncode == 0, r.stdout + r.stderr
        resolved = yaml.safe_load(r.stdout)
        assert set(resolved["services"]) == {"oven-line", "dryer", "press-line"}
    else:
        r = subprocess.run([*compose, "-p", f"plcemu-test-{os.getpid()}", "ps"],
                           capture_output=True, text=True, timeout=60, cwd=tmp_path)
        assert r.returncode == 0 and "Traceback" not in r.stderr, r.stdout + r.stderr


def _strict(data, type_name, models, path):
    """Loads `data` as the OpenAPI type `type_name` of the kubernetes client, refusing every key
    the model does not have (the client's own deserializer silently drops them)."""
    problems = []
    if type_name.startswith("list["):
        for i, item in enumerate(data or []):
            problems += _strict(item, type_name[5:-1], models, f"{path}[{i}]")
    elif type_name.startswith("dict("):
        value_type = type_name[5:-1].split(", ", 1)[1]
        for k, v in (data or {}).items():
            problems += _strict(v, value_type, models, f"{path}.{k}")
    elif hasattr(models, type_name):
        model = getattr(models, type_name)
        if not isinstance(data, dict):
            return [f"{path}: {type_name} expected, got {data!r}"]
        known = {v: k for k, v in model.attribute_map.items()}
        for key, value in data.items():
            if key not in known:
                problems.append(f"{path}.{key}: no such field in {type_name}")
            else:
                problems += _strict(value, model.openapi_types[known[key]], models,
                                    f"{path}.{key}")
    return problems


def load_typed(document):
    """The manifest as the kubernetes client's model object; AssertionError on unknown fields,
    ValueError on missing required ones (the models' own validation)."""
    kubernetes = pytest.importorskip(
        "kubernetes", reason="Debian's python3-kubernetes is not installed "
        "(scripts/install-deps.sh container)")
    from kubernetes import client

    group, _, version = document["apiVersion"].rpartition("/")
    prefix = "V1" if version == "v1" else version.capitalize()
    type_name = prefix + document["kind"]
    assert hasattr(client.models, type_name), type_name
    problems = _strict(document, type_name, client.models, document["kind"])
    assert not problems, problems
    api = client.ApiClient()
    return api._ApiClient__deserialize(document, type_name)


@pytest.mark.parametrize("name,index", [(n, i) for i, (n, _) in enumerate(kube_docs())])
def test_every_kubernetes_manifest_loads_into_the_typed_models(name, index):
    document = kube_docs()[index][1]
    obj = load_typed(document)
    assert obj.kind == document["kind"] and obj.metadata.name == document["metadata"]["name"]
    if document["kind"] == "StatefulSet":
        container = obj.spec.template.spec.containers[0]
        assert container.ports[0].container_port == 5020
        assert obj.spec.volume_claim_templates[0].spec.resources.requests["storage"]


def test_a_misspelt_field_is_caught():
    """The check above can fail: a field the model lacks, deep in a pod template, is named."""
    document = copy.deepcopy(kube("StatefulSet", "plcemu")[0])
    document["spec"]["template"]["spec"]["containers"][0]["ports"][0]["containerport"] = 5020
    with pytest.raises(AssertionError, match=r"containers\[0\]\.ports\[0\]\.containerport"):
        load_typed(document)
    document = copy.deepcopy(kube("StatefulSet", "plcemu")[0])
    del document["spec"]["template"]["spec"]["containers"][0]["name"]
    with pytest.raises(ValueError):
        load_typed(document)


# --- the image itself ----------------------------------------------------------------------------

needs_image = pytest.mark.skipif(
    not IMAGE, reason="no PLCEMU_TEST_IMAGE: scripts/container.sh --test builds and tests it")


def engine(*args, **kwargs):
    return subprocess.run([ENGINE, *args], capture_output=True, text=True, timeout=120, check=True,
                          **kwargs).stdout


@pytest.fixture(scope="module")
def image_root():
    """The image's root file system, mounted read-only by podman for the module."""
    path = Path(engine("image", "mount", IMAGE).strip())
    yield path
    engine("image", "unmount", IMAGE)


@pytest.fixture(scope="module")
def image_config():
    return json.loads(engine("image", "inspect", IMAGE))[0]


@needs_image
def test_the_image_runs_plcemud_as_its_user_with_a_state_volume_and_a_healthcheck(image_config):
    config = image_config["Config"]
    assert config["User"] == f"{IMAGE_UID}:{IMAGE_UID}"
    assert set(config["ExposedPorts"]) == {f"{p}/tcp" for p in EXPOSED}
    assert set(config["Volumes"]) == set(VOLUMES)
    assert "STATE_DIRECTORY=/var/lib/plcemu" in config["Env"]
    assert config["Entrypoint"] == ["/usr/libexec/plcemu/entrypoint"]
    assert config["Cmd"] == ["-c", CONFIG_PATH]
    assert config["StopSignal"] == "SIGTERM"
    assert config["Labels"]["org.opencontainers.image.version"] == VERSION
    health = image_config.get("Healthcheck") or config.get("Healthcheck")
    assert health and health["Test"] == ["CMD", "/usr/libexec/plcemu/healthcheck"], image_config
    # Tagged with the version and as latest: one image.
    ids = {json.loads(engine("image", "inspect", t))[0]["Id"]
           for t in (f"plcemu:{VERSION}", "plcemu:latest")}
    assert ids == {image_config["Id"]}


@needs_image
def test_the_image_holds_the_binary_the_config_and_the_examples_and_no_apt_lists(image_root):
    assert os.access(image_root / "usr/bin/plcemud", os.X_OK)
    for tool in ("entrypoint", "healthcheck"):
        assert os.access(image_root / "usr/libexec/plcemu" / tool, os.X_OK)
    for f in sorted((REPO / "config").glob("*.yaml")):
        assert (image_root / "usr/share/doc/plcemu/examples" / f.name).read_text() == f.read_text()
    config = (image_root / CONFIG_PATH.lstrip("/")).read_text()
    assert re.findall(r"bind:\s*(\S+)", config) == ["0.0.0.0", "0.0.0.0"]
    assert listen_ports(yaml.safe_load(config)) == set(EXPOSED)
    passwd = (image_root / "etc/passwd").read_text()
    assert re.search(rf"^plcemu:x:{IMAGE_UID}:{IMAGE_UID}:", passwd, re.M), passwd
    state = (image_root / "var/lib/plcemu").stat()
    assert (state.st_uid, state.st_gid, state.st_mode & 0o777) == (IMAGE_UID, IMAGE_UID, 0o750)
    assert not list((image_root / "var/lib/apt/lists").glob("*Packages*"))
    assert not (image_root / "usr/share/man/man8/plcemud.8.gz").exists()


@needs_image
def test_the_image_size_is_what_the_docs_say(image_config):
    """docs/operations.md states the image's size ("`plcemu:<version>` is about N MB"): within
    25 %."""
    text = " ".join((REPO / "docs" / "operations.md").read_text().split())
    stated = re.search(r"`plcemu:0\.1\.0` is about (\d+) MB", text.replace(VERSION, "0.1.0"))
    assert stated, "docs/operations.md states no image size"
    size = image_config["Size"] / 1e6
    assert 0.75 * int(stated[1]) <= size <= 1.25 * int(stated[1]), size


@pytest.fixture
def root_copy(image_root, tmp_path):
    """A writable copy of the image's root file system, with /proc and /dev mounted."""
    root = tmp_path / "root"
    subprocess.run(["cp", "-a", f"{image_root}/.", str(root)], check=True, timeout=120)
    mounted = []
    for what, where, args in (("proc", "proc", ["-t", "proc"]), ("/dev", "dev", ["--bind"])):
        subprocess.run(["mount", *args, what, str(root / where)], check=True)
        mounted.append(root / where)
    yield root
    for m in reversed(mounted):
        subprocess.run(["umount", "-l", str(m)], check=False)


def in_image(root, *command, env=None, **kwargs):
    """`command` run in the image's root as the image's user, with the image's environment."""
    base = {"PATH": "/usr/local/sbin:/usr/local/bin:/usr/sbin:/usr/bin:/sbin:/bin",
            "STATE_DIRECTORY": "/var/lib/plcemu"}
    return ["chroot", f"--userspec={IMAGE_UID}:{IMAGE_UID}", str(root), "/usr/bin/env", "-i",
            *[f"{k}={v}" for k, v in {**base, **(env or {})}.items()], *command]


@needs_image
def test_the_image_config_passes_check_config_as_the_image_user(root_copy):
    r = subprocess.run(in_image(root_copy, "/usr/bin/plcemud", "-c", CONFIG_PATH,
                                "--check-config"), capture_output=True, text=True, timeout=30)
    assert r.returncode == 0, r.stdout + r.stderr


@needs_image
def test_the_daemon_from_the_image_answers_modbus_and_exits_0_on_sigterm_with_its_state_synced(
        root_copy, tmp_path):
    # The image's config, moved to free ports on loopback (a config of one's own, as mounted),
    # laid out as a Kubernetes ConfigMap volume is: plcemud.yaml -> ..data/plcemud.yaml, and
    # ..data a link to a directory of this version, swapped whole when the ConfigMap changes.
    modbus, console = free_port(), free_port()
    config_dir = root_copy / Path(CONFIG_PATH).parent.relative_to("/")
    config_file = config_dir / Path(CONFIG_PATH).name
    text = config_file.read_text().replace("0.0.0.0", "127.0.0.1")
    text = text.replace("port: 5020", f"port: {modbus}").replace("port: 8020", f"port: {console}")

    def configmap_version(name, text):
        (config_dir / name).mkdir()
        (config_dir / name / config_file.name).write_text(text)
        (config_dir / "..data.new").symlink_to(name)
        (config_dir / "..data.new").rename(config_dir / "..data")

    config_file.unlink()
    configmap_version("..v1", text)
    config_file.symlink_to(f"..data/{config_file.name}")

    def start():
        out = open(tmp_path / "stdout", "ab")
        err = open(tmp_path / "stderr", "ab")
        proc = subprocess.Popen(in_image(root_copy, "/usr/libexec/plcemu/entrypoint", "-c",
                                         CONFIG_PATH), stdout=out, stderr=err,
                                stdin=subprocess.DEVNULL, cwd=root_copy / "var/lib/plcemu")
        deadline = time.monotonic() + 10
        while not (port_open(modbus) and port_open(console)):
            assert proc.poll() is None and time.monotonic() < deadline, \
                (tmp_path / "stdout").read_text()
            time.sleep(0.05)
        return proc

    def health(**env):
        return subprocess.run(in_image(root_copy, "/usr/libexec/plcemu/healthcheck", env=env),
                              capture_output=True, text=True, timeout=30)

    marker = tmp_path / "marker"
    marker.touch()
    time.sleep(0.01)
    proc = start()
    try:
        # R100: retentive. Written, then read back after a restart.
        assert raw_request(modbus, bytes([6, 0, 100, 0x04, 0xD2])) == bytes([6, 0, 100, 4, 0xD2])
        assert raw_request(modbus, bytes([3, 0, 100, 0, 1])) == bytes([3, 2, 4, 0xD2])
        # The HEALTHCHECK: the console's /healthz, else a Modbus request.
        r = health(PLCEMU_HEALTH_HTTP=f"127.0.0.1:{console}")
        assert r.returncode == 0, r.stderr
        r = health(PLCEMU_HEALTH_HTTP="", PLCEMU_HEALTH_MODBUS=f"127.0.0.1:{modbus}")
        assert r.returncode == 0, r.stderr
        r = health(PLCEMU_HEALTH_HTTP=f"127.0.0.1:{free_port()}",
                   PLCEMU_HEALTH_MODBUS=f"127.0.0.1:{free_port()}")
        assert r.returncode == 1 and "nothing listens" in r.stderr
        # A changed ConfigMap, then SIGHUP: the new version is read through the links.
        assert re.search(r"^station: 1$", text, re.M)
        configmap_version("..v2", re.sub(r"^station: 1$", "station: 2", text, flags=re.M))
        proc.send_signal(signal.SIGHUP)
        deadline = time.monotonic() + 10
        while "reload: station: 1 -> 2" not in (tmp_path / "stdout").read_text():
            assert time.monotonic() < deadline, (tmp_path / "stdout").read_text()
            time.sleep(0.05)
        assert raw_request(modbus, bytes([3, 0, 100, 0, 1]), unit=2) == bytes([3, 2, 4, 0xD2])
        proc.send_signal(signal.SIGTERM)
        assert proc.wait(timeout=10) == 0
    finally:
        if proc.poll() is None:
            proc.kill()
    state = root_copy / "var/lib/plcemu/plcemud.state"
    assert state.is_file() and state.stat().st_uid == IMAGE_UID
    # Nothing written outside the state directory (the config's new version is the test's):
    # a read-only root file system will do.
    written = subprocess.run(["find", str(root_copy), "-xdev", "-newer", str(marker),
                              "-not", "-type", "d", "-not", "-path", f"{config_dir}/*"],
                             capture_output=True, text=True).stdout.split()
    assert {str(Path(w).parent.relative_to(root_copy)) for w in written} <= {"var/lib/plcemu"}, \
        written
    # Logs on stdout, nothing on stderr.
    assert (tmp_path / "stderr").read_text() == ""
    log = (tmp_path / "stdout").read_text()
    assert "state file /var/lib/plcemu/plcemud.state closed" in log, log

    proc = start()
    try:
        assert raw_request(modbus, bytes([3, 0, 100, 0, 1]), unit=2) == bytes([3, 2, 4, 0xD2])
        proc.send_signal(signal.SIGTERM)
        assert proc.wait(timeout=10) == 0
    finally:
        if proc.poll() is None:
            proc.kill()
    second = (tmp_path / "stdout").read_text()[len(log):]
    assert "plcemud.state: reopened (closed cleanly last time)" in second, second
