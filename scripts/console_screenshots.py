#!/usr/bin/python3
"""Takes the console's screenshots for docs/console.md: starts plcemud on config/default.yaml's
PLC (a copy in a temporary directory, on free ports: the config files are not touched), lets its
ten loops heat for a few simulated minutes (and eight more while the loops page is open, so that
its trends show them), polls it as a SCADA would over Modbus TCP (one client, connected while the
pages are taken, so the overview and the traffic page show it), and saves each page at 1280x800
as docs/images/console-<page>.png.

Usage: console_screenshots.py [PLCEMUD]       (default build-dev2/plcemud; needs Debian's
                                               chromium, chromium-driver and python3-selenium)
"""

import json
import re
import shutil
import signal
import socket
import struct
import subprocess
import sys
import tempfile
import time
import urllib.request
from pathlib import Path

try:
    from selenium import webdriver
    from selenium.webdriver.chrome.service import Service
    from selenium.webdriver.common.by import By
    from selenium.webdriver.support.ui import WebDriverWait
except ImportError:
    print("console_screenshots: needs python3-selenium", file=sys.stderr)
    sys.exit(2)

REPO = Path(__file__).resolve().parents[1]
PLCEMUD = Path(sys.argv[1] if len(sys.argv) > 1 else REPO / "build-dev2" / "plcemud").resolve()
OUT = REPO / "docs" / "images"
WIDTH, HEIGHT = 1280, 800


def free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def api(base, path, body=None):
    data = None if body is None else json.dumps(body).encode()
    rq = urllib.request.Request(base + path, data=data, method="GET" if body is None else "PUT",
                                headers={"Content-Type": "application/json"})
    with urllib.request.urlopen(rq, timeout=5) as r:
        return json.loads(r.read())


class Master:
    """A Modbus TCP master on one connection: what a SCADA polling the PLC asks."""

    def __init__(self, port):
        self.sock = socket.create_connection(("127.0.0.1", port), timeout=3)
        self.tid = 0

    def ask(self, unit, pdu):
        self.tid += 1
        self.sock.sendall(struct.pack(">HHHB", self.tid, 0, len(pdu) + 1, unit) + pdu)
        head = b""
        while len(head) < 7:
            head += self.sock.recv(7 - len(head))
        length = struct.unpack(">HHHB", head)[2] - 1
        body = b""
        while len(body) < length:
            body += self.sock.recv(length - len(body))
        return body

    def poll(self):
        """One polling cycle: the loops' readings and setpoints, their heater outputs and
        in-zone bits, channel 0's true temperature from the simulator unit, and a write the PLC
        refuses (R4136, a read-only scan register)."""
        self.ask(1, struct.pack(">BHH", 3, 0, 10))        # R0-R9: the readings
        self.ask(1, struct.pack(">BHH", 3, 100, 10))      # R100-R109: the setpoints
        self.ask(1, struct.pack(">BHH", 1, 30, 10))       # Y30-Y39: the heaters' PWM outputs
        self.ask(1, struct.pack(">BHH", 1, 2400, 10))     # M400-M409: in zone
        self.ask(247, struct.pack(">BHH", 3, 106, 2))     # channel 0: true temperature, power
        self.ask(1, struct.pack(">BHH", 6, 4136, 1))      # refused: read-only

    def close(self):
        self.sock.close()


def config_text(modbus_port: int, http_port: int) -> str:
    """config/default.yaml on other ports, with the console on."""
    text = (REPO / "config" / "default.yaml").read_text()
    text, n = re.subn(r"(?m)^(\s+port:) 5020\b", rf"\1 {modbus_port}", text)
    if n != 1:
        sys.exit("console_screenshots: config/default.yaml has no 'port: 5020' line to replace")
    if re.search(r"(?m)^http:", text):
        text, n = re.subn(r"(?m)^(\s+port:) 8020\b", rf"\1 {http_port}", text)
        if n != 1:
            sys.exit("console_screenshots: config/default.yaml's http: has no 'port: 8020' line")
        return text
    return text + f"\nhttp: {{port: {http_port}}}\n"


def main():
    if not PLCEMUD.is_file():
        sys.exit(f"console_screenshots: no plcemud at {PLCEMUD}")
    chromium = shutil.which("chromium") or "/usr/bin/chromium"
    chromedriver = shutil.which("chromedriver") or "/usr/bin/chromedriver"
    OUT.mkdir(parents=True, exist_ok=True)
    with tempfile.TemporaryDirectory(prefix="plcemu-shots-") as tmp:
        http_port = free_port()
        config = Path(tmp) / "default.yaml"
        modbus_port = free_port()
        config.write_text(config_text(modbus_port, http_port))
        log = open(Path(tmp) / "plcemud.log", "wb")
        proc = subprocess.Popen([str(PLCEMUD), "-c", str(config)], cwd=tmp,
                                stdin=subprocess.DEVNULL, stdout=log, stderr=log)
        driver = None
        master = None
        try:
            base = f"http://127.0.0.1:{http_port}"
            deadline = time.monotonic() + 10
            while True:
                try:
                    api(base, "/api/v1/plcs")
                    break
                except OSError:
                    if proc.poll() is not None or time.monotonic() > deadline:
                        sys.exit("console_screenshots: plcemud did not start:\n"
                                 + (Path(tmp) / "plcemud.log").read_text())
                    time.sleep(0.05)
            # Start the ten loops (M0, M800-M809: config/default.yaml) and let them heat for a
            # few simulated minutes; a fault on channel 2 shows a lit button.
            api(base, "/api/v1/plcs/0/devices/M800", {"values": [1] * 10})
            api(base, "/api/v1/plcs/0/devices/M0", {"values": [1]})
            api(base, "/api/v1/plcs/0/simulator",
                {"time_scale": 100, "channels": [{"channel": 2, "faults": {"heater_open": True}}]})
            time.sleep(4)
            api(base, "/api/v1/plcs/0/simulator", {"time_scale": 1})
            master = Master(modbus_port)
            for _ in range(4):
                master.poll()
                time.sleep(0.25)

            options = webdriver.ChromeOptions()
            options.binary_location = chromium
            for arg in ("--headless=new", "--no-sandbox", "--disable-gpu",
                        "--disable-dev-shm-usage", f"--window-size={WIDTH},{HEIGHT}",
                        "--force-color-profile=srgb", "--hide-scrollbars"):
                options.add_argument(arg)
            driver = webdriver.Chrome(service=Service(chromedriver), options=options)
            # The page's own area is 1280x800, whatever the window's frame takes.
            driver.execute_cdp_cmd("Emulation.setDeviceMetricsOverride",
                                   {"width": WIDTH, "height": HEIGHT, "deviceScaleFactor": 1,
                                    "mobile": False})
            pages = [
                ("overview", "/", '#clients tr[data-peer]'),
                ("devices", "/plcs/0/devices?from=R100&count=20",
                 'td[data-device="R100"][data-value]'),
                ("plant", "/plcs/0/plant", 'button[data-fault][aria-pressed="true"]'),
                ("loops", "/plcs/0/loops",
                 'article[data-loop] polyline[data-series="pv"]:not([data-points="0"])'),
                ("traffic", "/plcs/0/traffic", "#exchanges tbody tr[data-function]"),
            ]
            for name, path, ready in pages:
                master.poll()
                driver.get(base + path)
                WebDriverWait(driver, 10).until(
                    lambda d, sel=ready: d.find_elements(By.CSS_SELECTOR, sel))
                WebDriverWait(driver, 10).until(
                    lambda d: d.find_elements(By.CSS_SELECTOR, "#status.live")
                    or not d.find_elements(By.ID, "status"))
                if name == "loops":
                    # The trends are what the page has seen: eight simulated minutes at x30.
                    api(base, "/api/v1/plcs/0/simulator", {"time_scale": 30})
                    for _ in range(16):
                        master.poll()
                        time.sleep(1)
                    api(base, "/api/v1/plcs/0/simulator", {"time_scale": 1})
                    time.sleep(1.2)
                time.sleep(0.3)  # let the last values land
                target = OUT / f"console-{name}.png"
                driver.save_screenshot(str(target))
                print(target.relative_to(REPO))
            # The plant page's communication faults, one lit: a delay on R100-R109.
            api(base, "/api/v1/plcs/0/comm-faults",
                {"delay_ms": 300, "from": "R100", "count": 10})
            driver.get(base + "/plcs/0/plant")
            WebDriverWait(driver, 10).until(lambda d: d.find_elements(
                By.CSS_SELECTOR, 'button[data-comm-fault="delay"][aria-pressed="true"]'))
            time.sleep(0.3)
            target = OUT / "console-comm-faults.png"
            driver.find_element(By.ID, "comm").screenshot(str(target))
            print(target.relative_to(REPO))
        finally:
            if driver is not None:
                driver.quit()
            if master is not None:
                master.close()
            proc.send_signal(signal.SIGTERM)
            try:
                proc.wait(timeout=5)
            except subprocess.TimeoutExpired:
                proc.kill()
            log.close()


if __name__ == "__main__":
    main()
