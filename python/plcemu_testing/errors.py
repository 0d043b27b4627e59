"""The exceptions of plcemu_testing: each names the device (or the daemon) and what went wrong."""

# Modbus exception codes (Modbus Application Protocol v1.1b3, §7).
EXCEPTION_NAMES = {
    1: "illegal function",
    2: "illegal data address",
    3: "illegal data value",
    4: "server device failure",
    5: "acknowledge",
    6: "server device busy",
    8: "memory parity error",
    10: "gateway path unavailable",
    11: "gateway target device failed to respond",
}


class PlcemuError(Exception):
    """Base of every error of plcemu_testing."""


class DaemonError(PlcemuError):
    """plcemud could not be found, started, stopped or reloaded (the message has its log)."""


class DeviceError(PlcemuError, ValueError):
    """A device name this PLC's Modbus map cannot serve (unknown, out of range, wrong kind)."""

    def __init__(self, device, reason):
        super().__init__(f"{device}: {reason}")
        self.device = device
        self.reason = reason


class FatekError(PlcemuError):
    """A FATEK protocol reply with a non-zero error code (`code`, 2-15: the manual's digit
    2-9 or A), or a reply that is not a frame (`code` None, `detail` says why)."""

    NAMES = {2: "illegal value", 3: "write disabled",
             4: "illegal format, or command cannot be executed",
             5: "cannot RUN: ladder checksum error", 6: "cannot RUN: PLC ID differs from ladder ID",
             7: "cannot RUN: syntax error", 9: "cannot RUN: function not supported",
             10: "illegal address"}

    def __init__(self, operation, device, code=None, detail=None):
        self.operation = operation
        self.device = device
        self.code = code
        self.detail = detail
        self.error_name = self.NAMES.get(code, "unknown error") if code else None
        what = (f"FATEK error {code:X} ({self.error_name})" if code is not None else str(detail))
        super().__init__(f"{operation} {device}: {what}" if device else f"{operation}: {what}")


class FatekTimeout(FatekError, TimeoutError):
    """No FATEK reply within the client's timeout (a discarded frame, another station, a
    broadcast, or no listener)."""


class ModbusError(PlcemuError):
    """The daemon answered a request with a Modbus exception, or did not answer."""

    def __init__(self, operation, device, code=None, detail=None):
        self.operation = operation
        self.device = device
        self.code = code
        self.exception_name = EXCEPTION_NAMES.get(code, "unknown exception") if code else None
        what = (f"Modbus exception {code:02X}h ({self.exception_name})" if code is not None
                else str(detail))
        super().__init__(f"{operation} {device}: {what}")
