"""plcemu_testing: a pytest plugin that runs plcemud, the PLC emulator, for system tests.

    def test_heats(plcemud):
        plc = plcemud("config/default.yaml")
        plc.freeze()
        plc.write_bits("M800", [1] * 10)
        plc.write_bits("M0", [1])
        plc.run(seconds=600)
        assert plc.read("R0")[0] > 1000

Load it with `pytest -p plcemu_testing` (python/ on PYTHONPATH) or install the package, which
registers it. The API is in docs/testing.md.
"""

from .errors import DaemonError, DeviceError, FatekError, FatekTimeout, ModbusError, PlcemuError
from .fatek import Fatek
from .plc import Plc, PlcApi
from .plcs import PlcEntry, Plcs
from .process import find_plcemud
from .wire_map import WireMap, parse_device

__all__ = ["DaemonError", "DeviceError", "Fatek", "FatekError", "FatekTimeout", "ModbusError",
           "PlcemuError", "Plc", "PlcApi", "PlcEntry", "Plcs", "WireMap", "find_plcemud",
           "parse_device", "plcemud"]

try:
    import pytest  # noqa: F401
except ImportError:  # WireMap and Plc work without pytest (scripts/trace.py uses WireMap)
    pass
else:
    from .plugin import plcemud, pytest_runtest_makereport, pytest_unconfigure  # noqa: F401
