#!/usr/bin/python3
"""A pymodbus 3.0 asyncio Modbus TCP server: the yardstick for a Python-based simulator.

Run with /usr/bin/python3 (Debian's python3-pymodbus 3.0.0rc1). Unit IDs are not checked
(single context), and holding registers 0..9999 exist, so any FC03 of up to 125 registers at
address 0 is answered.
"""

import argparse
import asyncio
import logging

from pymodbus.datastore import (
    ModbusSequentialDataBlock,
    ModbusServerContext,
    ModbusSlaveContext,
)
from pymodbus.server import StartAsyncTcpServer


def main():
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--port", type=int, required=True)
    args = parser.parse_args()

    # Per-request logging would dominate what is measured.
    logging.getLogger("pymodbus").setLevel(logging.ERROR)

    def block():
        return ModbusSequentialDataBlock(0, [0] * 10000)

    # zero_mode: wire address n is register n, as in the other servers.
    slave = ModbusSlaveContext(di=block(), co=block(), hr=block(), ir=block(), zero_mode=True)
    context = ModbusServerContext(slaves=slave, single=True)
    asyncio.run(StartAsyncTcpServer(context=context, address=("127.0.0.1", args.port)))


if __name__ == "__main__":
    main()
