"""A plcemud process running a `plcs:` config (docs/configuration.md, "Several PLCs"): Plcs
starts, restarts and reloads it; each of its PLCs is a PlcEntry with the PlcApi of a single
Plc, reached on that PLC's listener, station and simulator unit."""

import json
import re
from collections.abc import Mapping

from .errors import DaemonError
from .plc import PlcApi, _settings, config_text, connect, fatek_config, fatek_listener
from .process import Process, free_port
from .tags import read_tags
from .wire_map import WireMap

PLCS_KEY = re.compile(r'(?m)^(plcs|"plcs")\s*:')


def plcs_of(config):
    """The config as a dict when it holds `plcs:` (a dict, YAML or JSON text, or a path), else
    None. YAML text needs PyYAML (JSON, a dict, or a config holding one PLC do not)."""
    if isinstance(config, Mapping):
        return config if "plcs" in config else None
    text = config_text(config)
    if not PLCS_KEY.search(text):
        return None
    try:
        loaded = json.loads(text)
    except ValueError:
        try:
            import yaml
        except ImportError as e:
            raise DaemonError("a plcs: config as YAML needs PyYAML (python3-yaml) to give its "
                              "listeners free ports; or pass it as a dict") from e
        try:
            loaded = yaml.safe_load(text)
        except yaml.YAMLError:
            return None  # plcemud says what is wrong
    return loaded if isinstance(loaded, Mapping) and "plcs" in loaded else None


class PlcEntry(PlcApi):
    """One PLC of a Plcs: devices, tags and the simulator unit as a Plc has them, through its
    own listener (`port`), `station` and simulator unit. `daemon` is the Plcs (restart, reload,
    stop, log)."""

    def __init__(self, daemon, index):
        self.daemon = daemon
        self.index = index

    def _setting(key, doc):  # noqa: N805 (a property maker of the class body)
        return property(lambda self: self.daemon._entries[self.index][key], doc=doc)

    name = _setting("id", 'Its `name:`, or "plcs[i]" without one: the `plc` of the tag export.')
    port = _setting("port", "The port of its TCP listener on 127.0.0.1 (None: TCP is off).")
    station = _setting("station", "Its station: the unit ID of its devices.")
    scan_ms = _setting("scan_ms", "Its scan period, ms: what run(seconds=...) steps.")
    del _setting

    @property
    def console_url(self):
        """Its pages in the console that serves the config: "http://127.0.0.1:PORT/plcs/<its
        name, or its position>/" (add devices, loops, plant or traffic)."""
        key = str(self.index) if self.name.startswith("plcs[") else self.name
        return f"{self.daemon.console_url}plcs/{key}/"

    @property
    def client(self):
        clients = self.daemon._clients
        return clients[self.index] if self.index < len(clients) else None

    @property
    def map(self):
        return self.daemon._maps[self.name]

    @property
    def tags(self):
        """Its rows of the config's tag export, named with its prefix ("kiln.R100")."""
        return [t for t in self.daemon.tags if t["plc"] == self.name]

    @property
    def config_path(self):
        return self.daemon.config_path

    def _own_config(self):
        entries = fatek_config(self.config_path).get("plcs") or []
        return entries[self.index] if self.index < len(entries) else {}

    @property
    def log(self):
        return self.daemon.log

    def __repr__(self):
        return (f"<PlcEntry {self.name} of {self.config_path} on 127.0.0.1:{self.port}, "
                f"station {self.station}>")


class Plcs(Process):
    """A running plcemud holding the PLCs of a `plcs:` config: `plcs["kiln"]`, `plcs[1]`, one
    PlcEntry each, in file order. Each distinct TCP listener of the config (entries with the
    same bind and port share one) gets a free port of 127.0.0.1; each PLC keeps the state file
    plcemud names after it in `workdir` (plc-kiln.state, plc-2.state)."""

    def __init__(self, binary, workdir, config, name="plc"):
        super().__init__(binary, workdir, name)
        self._given = {}  # listener as written (bind, port) -> the port it got
        self._clients = []
        self._tags = None
        self._set_config(config)
        self.http_port = free_port(taken=set(self._given.values()))
        self._maps = WireMap.per_plc(self.binary, self.config_path)
        self.plcs = [PlcEntry(self, i) for i in range(len(self._entries))]
        self._start()

    # --- the config -------------------------------------------------------------------------

    def _set_config(self, config):
        source = plcs_of(config)
        if source is None:
            raise DaemonError("not a plcs: config (a reload cannot turn it into one PLC)")
        self._source = json.loads(json.dumps(source))  # a deep copy, with string keys
        self._write()

    def _write(self):
        """Writes the config with each listener on its free port, and reads its entries."""
        cfg = json.loads(json.dumps(self._source))
        entries = cfg["plcs"] if isinstance(cfg["plcs"], list) else []
        self._entries = []
        for i, e in enumerate(entries):
            e = e if isinstance(e, dict) else {}
            port = self._listen(e)
            fatek_listener(e, self._given)
            scan_ms, station = _settings(e)
            name = e.get("name")
            self._entries.append({
                "id": str(name) if name else f"plcs[{i}]", "port": port, "station": station,
                "scan_ms": scan_ms, "label": f"plcs[{i}]" + (f" ({name})" if name else "")})
        self.config_path.write_text(json.dumps(cfg, indent=1) + "\n")

    def _listen(self, entry):
        """Gives the entry's TCP listener its free port (bound to 127.0.0.1 unless it says
        otherwise); the port, or None when TCP is off."""
        modbus = entry.setdefault("modbus", {}) or {}
        entry["modbus"] = modbus
        tcp = modbus.setdefault("tcp", {}) or {}
        modbus["tcp"] = tcp
        if tcp.get("enabled", True) is False:
            return None
        key = (tcp.get("bind"), tcp.get("port"))
        if key not in self._given:
            self._given[key] = free_port(taken=set(self._given.values()))
        tcp.setdefault("bind", "127.0.0.1")
        tcp["port"] = self._given[key]
        return tcp["port"]

    # --- the process --------------------------------------------------------------------------

    def _args(self):
        # Each entry names its Modbus port (plcemud refuses --port with plcs:); one console
        # serves them all (docs/console.md).
        return ["--http-port", str(self.http_port)]

    def _ports(self):
        fatek = [fatek_listener(p._own_config()) for p in getattr(self, "plcs", ())]
        return sorted({e["port"] for e in self._entries if e["port"]}
                      | {f[2] for f in fatek if f and f[0] == "tcp"} | {self.http_port})

    @property
    def console_url(self):
        """The base URL of the console and REST API that serves every PLC of the config
        ("http://127.0.0.1:PORT/"; a PLC's pages at plcs/<name>/devices...)."""
        return f"http://127.0.0.1:{self.http_port}/"

    def _connect(self):
        self._clients = [connect(e["port"]) if e["port"] else None for e in self._entries]

    def _disconnect(self):
        for p in getattr(self, "plcs", ()):
            p._close_fatek()
            p._close_sim()
        for c in self._clients:
            if c is not None:
                c.close()
        self._clients = []

    def _new_ports(self):
        self._given = {}
        self._write()
        self.http_port = free_port(taken=set(self._given.values()))

    def _snapshot(self):
        return self._source, dict(self._given), self._entries

    def _restore(self, snapshot):
        self._source, self._given, self._entries = snapshot

    def _reload_done(self, new_log):
        # Said once the PLCs whose entry changed are rebuilt (the others run on untouched).
        return "reload: applied to " in new_log

    def _reloaded(self):
        self._maps = WireMap.per_plc(self.binary, self.config_path)
        self._tags = None
        self._disconnect()  # a listener may have moved to another port
        self._connect()

    # --- its PLCs -----------------------------------------------------------------------------

    def __getitem__(self, key):
        if isinstance(key, int):
            return self.plcs[key]
        for p in self.plcs:
            if p.name == key:
                return p
        raise KeyError(f"{key}: no such PLC in {self.config_path} (its PLCs: "
                       f"{', '.join(self.names)})")

    def __len__(self):
        return len(self.plcs)

    def __iter__(self):
        return iter(self.plcs)

    @property
    def names(self):
        return [p.name for p in self.plcs]

    @property
    def tags(self):
        """The whole tag export of the config (`--export-tags json`), every PLC's rows with their
        `plc` and `endpoint`."""
        if self._tags is None:
            self._tags = read_tags(self.binary, self.config_path)
        return self._tags

    def __repr__(self):
        return f"<Plcs {self.config_path}: {', '.join(self.names)}>"
