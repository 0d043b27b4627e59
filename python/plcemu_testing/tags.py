"""The daemon's tag export (`plcemud -c CONFIG --export-tags json`, docs/configuration.md,
"Tag export") read into dicts, and a tag's value read or written at the address it names."""

import json
import subprocess

from .errors import DaemonError

# The Modbus functions a table implies: (read, write) method names of a pymodbus client.
FUNCTIONS = {"coil": ("read_coils", "write_coils"),
             "discrete_input": ("read_discrete_inputs", None),
             "holding_register": ("read_holding_registers", "write_registers"),
             "input_register": ("read_input_registers", None)}
# Registers a value of each type takes.
WIDTH = {"bool": 1, "int16": 1, "uint16": 1, "int32": 2}


def read_tags(plcemud, config_path):
    """The tags of a config: a list of dicts with the export's keys (name, device, unit, table,
    address, address_1based, type, access, description)."""
    try:
        r = subprocess.run([str(plcemud), "-c", str(config_path), "--export-tags", "json"],
                           capture_output=True, text=True, timeout=30)
    except OSError as e:
        raise DaemonError(f"cannot run {plcemud}: {e}") from e
    if r.returncode != 0:
        raise DaemonError(f"plcemud --export-tags failed on {config_path}:\n{r.stderr}")
    return json.loads(r.stdout)


def from_registers(tag, registers):
    """The value of a register tag from its registers (int32: low word first), signed as its
    type says."""
    v = registers[0] | (registers[1] << 16 if tag["type"] == "int32" else 0)
    bits = 16 * WIDTH[tag["type"]]
    if tag["type"] in ("int16", "int32") and v >> (bits - 1) & 1:
        v -= 1 << bits
    return v


def to_registers(tag, value):
    """The registers a value of a register tag is written as."""
    bits = 16 * WIDTH[tag["type"]]
    lo = -(1 << (bits - 1)) if tag["type"] in ("int16", "int32") else 0
    if not isinstance(value, int) or not lo <= value < lo + (1 << bits):
        raise ValueError(f"{tag['name']}: {value!r} is not a {tag['type']}")
    v = value & ((1 << bits) - 1)
    return [v & 0xFFFF, v >> 16] if bits == 32 else [v]
