"""The web console in a real browser (headless Chromium through Selenium, docs/console.md): live
values, writes in place and their refusals, the loops' faceplates (trend, set point, switches),
the plant's fault buttons, text from the server shown as text, and the overview of every PLC.
Skipped when chromium, chromedriver or selenium is missing (scripts/install-deps.sh test
installs them)."""

import json
import os
import re
import shutil
import signal
import socket
import subprocess
import time
import urllib.error
import urllib.parse
import urllib.request

import pytest

from conftest import PLCEMUD, REPO, free_port, port_open

def _tool(path):
    return path if os.access(path, os.X_OK) else shutil.which(os.path.basename(path))


CHROMIUM = _tool("/usr/bin/chromium")
CHROMEDRIVER = _tool("/usr/bin/chromedriver")
if CHROMIUM is None or CHROMEDRIVER is None:
    pytest.skip("chromium and chromedriver are not installed", allow_module_level=True)
try:
    from selenium import webdriver
    from selenium.common.exceptions import (NoAlertPresentException,
                                            StaleElementReferenceException)
    from selenium.webdriver.chrome.service import Service
    from selenium.webdriver.common.by import By
    from selenium.webdriver.common.keys import Keys
    from selenium.webdriver.support.ui import WebDriverWait
except ImportError:
    pytest.skip("python3-selenium is not installed", allow_module_level=True)

VIEWS = ("devices", "loops", "plant", "traffic")


@pytest.fixture(scope="module")
def browser():
    """One headless Chromium for the whole module (starting one takes a second or two)."""
    options = webdriver.ChromeOptions()
    options.binary_location = CHROMIUM
    for arg in ("--headless=new", "--no-sandbox", "--disable-gpu", "--disable-dev-shm-usage",
                "--window-size=1280,800"):
        options.add_argument(arg)
    options.set_capability("goog:loggingPrefs", {"browser": "ALL"})
    driver = webdriver.Chrome(service=Service(CHROMEDRIVER), options=options)
    driver.set_page_load_timeout(15)
    yield driver
    driver.quit()


def forget_earlier_pages(driver):
    """Leave the page an earlier test left open, then drop what the log holds. Reading the log
    alone is not enough: the earlier page keeps refreshing until it is left, and its requests to
    that test's stopped daemon would be logged as failed after the log was read."""
    driver.get("about:blank")
    driver.get_log("browser")


def start_console(start_plcemud, modbus="", http=""):
    """A one-PLC fbs daemon with its console on a free port -> (Daemon, base URL)."""
    port = free_port()
    d = start_plcemud(
        "profile: fbs\n"
        f"modbus: {{tcp: {{bind: 127.0.0.1}}{modbus}}}\n"
        f"http: {{port: {port}{http}}}\n"
    )
    deadline = time.monotonic() + 5
    while not port_open(port):
        assert time.monotonic() < deadline, f"no console on port {port}\n{d.log_text()}"
        time.sleep(0.02)
    return d, f"http://127.0.0.1:{port}"


def start_config_file(start_plcemud, name, *args):
    """config/<name> as it is, but for its ports: Modbus on a free port (--port), the console on
    another (--http-port) -> (Daemon, base URL)."""
    port = free_port()
    d = start_plcemud((REPO / "config" / name).read_text(), "--http-port", str(port), *args)
    deadline = time.monotonic() + 5
    while not port_open(port):
        assert time.monotonic() < deadline, f"no console on port {port}\n{d.log_text()}"
        time.sleep(0.02)
    return d, f"http://127.0.0.1:{port}"


def api(base, path, method="GET", body=None, token=None):
    """One request to the REST API -> (status, JSON)."""
    headers = {"Accept": "application/json"}
    data = None
    if body is not None:
        headers["Content-Type"] = "application/json"
        data = json.dumps(body).encode()
    if token:
        headers["Authorization"] = f"Bearer {token}"
    rq = urllib.request.Request(base + path, data=data, method=method, headers=headers)
    try:
        with urllib.request.urlopen(rq, timeout=5) as r:
            return r.status, json.loads(r.read())
    except urllib.error.HTTPError as e:
        return e.code, json.loads(e.read())


def wait(driver, condition, timeout=5.0, what=""):
    """Waits until condition(driver) is truthy and returns it (a WebDriverWait, polled often).
    An element the page replaced while the condition read it (the loops page rebuilds its
    faceplates when a loop's PV source appears) is asked for again."""
    return WebDriverWait(driver, timeout, poll_frequency=0.02,
                         ignored_exceptions=[StaleElementReferenceException]).until(
                             condition, what)


def css(driver, selector):
    return driver.find_element(By.CSS_SELECTOR, selector)


def cell(driver, device):
    return css(driver, f'td[data-device="{device}"]')


def row_texts(driver, device):
    """The texts of a word's row: [decimal (the cell's value), signed, hex, bits]."""
    c = cell(driver, device)
    tds = c.find_element(By.XPATH, "..").find_elements(By.TAG_NAME, "td")
    return [c.get_attribute("data-value")] + [td.text for td in tds[1:]]


def holding(d, address, unit=1):
    r = d.client().read_holding_registers(address, 1, slave=unit)
    assert not r.isError(), r
    return r.registers[0]


def open_devices(driver, base, device, count=20):
    """Opens the devices page and waits until its values are live (the event stream is open)."""
    query = urllib.parse.urlencode({"from": device, "count": count})
    driver.get(f"{base}/plcs/0/devices?{query}")
    selector = f'td[data-device="{device}"][data-value]'
    wait(driver, lambda dr: dr.find_elements(By.CSS_SELECTOR, selector),
         what=f"no value cell for {device}")
    wait(driver, lambda dr: "live" in css(dr, "#status").get_attribute("class").split(),
         what="the live updates did not start")
    driver.execute_script("window.plcemuNotReloaded = true;")


def type_into(driver, device, text, enter=True):
    """Clicks the device's value input, replaces its text by `text` and presses Enter."""
    inp = css(driver, f'input[data-device="{device}"]')
    inp.click()
    inp.send_keys(Keys.CONTROL, "a")
    inp.send_keys(text + (Keys.ENTER if enter else ""))
    return inp


def not_reloaded(driver):
    return driver.execute_script("return window.plcemuNotReloaded === true;")


def message(driver):
    m = css(driver, "#message")
    return m.text, m.get_attribute("class").split(), m.is_displayed()


# ---- Devices ---------------------------------------------------------------------------------


def test_a_modbus_write_shows_in_the_devices_page_within_a_second(browser, start_plcemud):
    d, base = start_console(start_plcemud)
    open_devices(browser, base, "R100")
    assert row_texts(browser, "R100") == ["0", "0", "0x0000", "0000 0000 0000 0000"]
    c = d.client()
    # R100 is holding register 100 (docs/profile-fbs.md, "Modbus map").
    assert not c.write_register(100, 1234, slave=1).isError()
    wait(browser, lambda dr: cell(dr, "R100").get_attribute("data-value") == "1234", timeout=1.0,
         what="R100 did not show 1234 within 1 s")
    assert css(browser, 'input[data-device="R100"]').get_attribute("value") == "1234"
    assert row_texts(browser, "R100") == ["1234", "1234", "0x04D2", "0000 0100 1101 0010"]
    assert not c.write_register(119, 0xFFFF, slave=1).isError()
    wait(browser,
         lambda dr: row_texts(dr, "R119") == ["65535", "-1", "0xFFFF", "1111 1111 1111 1111"],
         timeout=1.0, what="R119 (the last row) did not show 65535 / -1")
    assert not_reloaded(browser)


def test_a_32_bit_counter_shows_and_takes_one_32_bit_value(browser, start_plcemud):
    """CTR200-CTR255 (two words each, low word first) showed as their low word, CTR200 twice,
    and a value typed in was cut to 16 bits."""
    d, base = start_console(start_plcemud)
    c = d.client()
    # C200-C201 current values: holding registers 9700-9703 (docs/profile-fbs.md).
    assert not c.write_registers(9700, [0xFFFE, 0xFFFF, 70000 & 0xFFFF, 70000 >> 16],
                                 slave=1).isError()
    open_devices(browser, base, "CTR199", count=3)
    names = [th.text for th in browser.find_elements(By.CSS_SELECTOR, "#devices th.device")]
    assert names == ["CTR199", "CTR200", "CTR201"], names
    assert row_texts(browser, "CTR200") == [
        "4294967294", "-2", "0xFFFFFFFE", "1111 1111 1111 1111 1111 1111 1111 1110"]
    assert row_texts(browser, "CTR201")[:3] == ["70000", "70000", "0x00011170"]
    assert row_texts(browser, "CTR199")[2] == "0x0000"  # a 16-bit counter beside them
    type_into(browser, "CTR201", "-100000")
    wait(browser, lambda _: c.read_holding_registers(9702, 2, slave=1).registers ==
         [(-100000) & 0xFFFF, ((-100000) >> 16) & 0xFFFF], what="CTR201 was not written")
    wait(browser, lambda dr: row_texts(dr, "CTR201")[1] == "-100000",
         what="CTR201 did not show -100000")
    assert not_reloaded(browser)


def test_editing_a_value_writes_the_register(browser, start_plcemud):
    d, base = start_console(start_plcemud)
    open_devices(browser, base, "R100")
    type_into(browser, "R101", "0x1F")
    wait(browser, lambda _: holding(d, 101) == 31, what="R101 was not written 0x1F")
    wait(browser, lambda dr: "ok" in message(dr)[1], what="no confirmation")
    assert "R101" in message(browser)[0]
    type_into(browser, "R102", "-2")
    wait(browser, lambda _: holding(d, 102) == 65534, what="R102 was not written -2")
    wait(browser, lambda dr: row_texts(dr, "R102")[:3] == ["65534", "-2", "0xFFFE"])
    # While the input has focus, live updates leave what is typed alone.
    inp = type_into(browser, "R103", "77", enter=False)
    assert not d.client().write_register(103, 555, slave=1).isError()
    wait(browser, lambda dr: row_texts(dr, "R103")[1] == "555", timeout=1.0,
         what="R103's other columns did not follow the Modbus write")
    assert inp.get_attribute("value") == "77"
    inp.send_keys(Keys.ENTER)
    wait(browser, lambda _: holding(d, 103) == 77, what="R103 was not written 77")
    # Not a number: said, nothing written.
    type_into(browser, "R104", "12abc")
    wait(browser, lambda dr: "error" in message(dr)[1])
    assert "12abc" in message(browser)[0]
    assert holding(d, 104) == 0
    assert not_reloaded(browser)


def test_a_write_to_a_protected_register_shows_the_refusal(browser, start_plcemud):
    d, base = start_console(start_plcemud, modbus=", write_protect: [R200-R209]")
    for device, address in (("R200", 200), ("R3840", 3840)):  # write_protect; IR: read-only
        status, expected = api(base, f"/api/v1/plcs/0/devices/{device}", "PUT", {"values": [42]})
        assert status == 403, expected
        before = holding(d, address)
        open_devices(browser, base, device, count=5)
        assert not message(browser)[2]
        type_into(browser, device, "42")
        wait(browser, lambda dr: "error" in message(dr)[1], what=f"no refusal shown for {device}")
        text, _, shown = message(browser)
        assert shown and text == expected["error"]
        assert holding(d, address) == before


def test_a_read_only_console_and_the_token(browser, start_plcemud):
    _, base = start_console(start_plcemud, http=", read_only: true")
    open_devices(browser, base, "R100", count=2)
    type_into(browser, "R100", "5")
    wait(browser, lambda dr: "error" in message(dr)[1])
    assert message(browser)[0] == "this console is read-only (http.read_only)"

    d, base = start_console(start_plcemud, http=", token: s3cret")
    open_devices(browser, base, "R100", count=2)
    type_into(browser, "R100", "5")
    wait(browser, lambda dr: "error" in message(dr)[1])
    assert "token" in message(browser)[0]
    assert holding(d, 100) == 0
    css(browser, "#token").send_keys("s3cret")
    type_into(browser, "R100", "5")
    wait(browser, lambda _: holding(d, 100) == 5, what="the write with the token failed")
    # Entered once: the next page of this console has it.
    open_devices(browser, base, "R110", count=2)
    assert css(browser, "#token").get_attribute("value") == "s3cret"
    type_into(browser, "R110", "6")
    wait(browser, lambda _: holding(d, 110) == 6, what="the token was not kept")


def test_text_from_the_server_is_shown_as_text(browser, start_plcemud):
    _, base = start_console(start_plcemud)
    for name in ("<script>alert(1)</script>", "<img src=x onerror=alert(2)>"):
        path = "/api/v1/plcs/0/devices/" + urllib.parse.quote(name, safe="")
        status, expected = api(base, path)
        assert status == 404, expected
        browser.get(f"{base}/plcs/0/devices?" + urllib.parse.urlencode({"from": name}))
        wait(browser, lambda dr: "error" in message(dr)[1], what=f"no error shown for {name}")
        text, _, shown = message(browser)
        assert shown and name in text and text == expected["error"]
        assert browser.find_elements(By.CSS_SELECTOR, "#message *") == []
        assert browser.find_elements(By.CSS_SELECTOR, "main img, main script") == []
        assert css(browser, "#from").get_attribute("value") == name
        with pytest.raises(NoAlertPresentException):
            browser.switch_to.alert.text  # noqa: B018 - raises when there is no alert


def test_an_unknown_plcs_page_says_so_as_text(browser, start_plcemud):
    # docs/console.md, "Pages": the page comes as a 404 and shows the API's words, never runs
    # what the address holds.
    _, base = start_console(start_plcemud)
    name = "<script>alert(1)</script>"
    status, expected = api(base, "/api/v1/plcs/" + urllib.parse.quote(name, safe=""))
    assert status == 404 and "there are: 0" in expected["error"], expected
    browser.get(f"{base}/plcs/{urllib.parse.quote(name, safe='')}/devices")
    wait(browser, lambda dr: "error" in message(dr)[1], what="no error shown")
    text, _, shown = message(browser)
    assert shown and text == expected["error"], text
    assert browser.find_elements(By.CSS_SELECTOR, "main script, #nav script") == []
    assert "PLC " + name in browser.title
    with pytest.raises(NoAlertPresentException):
        browser.switch_to.alert.text  # noqa: B018 - raises when there is no alert
    # A page that polls asks no more once it knows: nothing there will change.
    browser.get(f"{base}/plcs/nope/loops")
    wait(browser, lambda dr: "no PLC 'nope' here" in message(dr)[0], what="no error shown")
    asked = "return performance.getEntriesByType('resource')" \
            ".filter(e => e.name.includes('/api/')).length"
    before = browser.execute_script(asked)
    time.sleep(2.5)
    assert browser.execute_script(asked) == before


def test_a_message_cannot_be_reordered_by_the_address(browser, start_plcemud):
    # docs/console.md, "The API": a link whose PLC name holds U+202E (which would show
    # "no PLC 'knil' ..." as a reversed tail) shows the escape, as the log does.
    _, base = start_console(start_plcemud)
    browser.get(f"{base}/plcs/%E2%80%AEknil%3Cb%3E/devices")
    wait(browser, lambda dr: "error" in message(dr)[1], what="no error shown")
    text = message(browser)[0]
    assert "no PLC '\\u202Eknil<b>' here" in text and "\u202e" not in text, text
    assert browser.find_elements(By.CSS_SELECTOR, "#message *") == []


# ---- Plant -----------------------------------------------------------------------------------


def test_a_fault_button_switches_the_fault_as_the_simulator_unit(browser, start_plcemud):
    d, base = start_console(start_plcemud)
    browser.get(f"{base}/plcs/0/plant")
    selector = 'button[data-channel="0"][data-fault="heater_open"]'
    button = wait(browser, lambda dr: dr.find_element(By.CSS_SELECTOR, selector))
    wait(browser, lambda dr: "live" in css(dr, "#status").get_attribute("class").split())
    assert button.get_attribute("aria-pressed") == "false"
    button.click()
    wait(browser, lambda _: button.get_attribute("aria-pressed") == "true",
         what="the button does not show the fault on")
    _, sim = api(base, "/api/v1/plcs/0/simulator")
    assert sim["channels"][0]["faults"] == {"sensor_broken": False, "heater_open": True,
                                           "heater_shorted": False, "reading_frozen": False}
    assert not any(sim["channels"][1]["faults"].values())
    # The simulator unit (247) says the same: channel 0's fault bits, b1 heater open.
    assert holding(d, 100, unit=247) == 0b0010
    button.click()
    wait(browser, lambda _: button.get_attribute("aria-pressed") == "false")
    assert not api(base, "/api/v1/plcs/0/simulator")[1]["channels"][0]["faults"]["heater_open"]
    # A fault set elsewhere shows on the next refresh (once a second).
    # Channel 3's fault bits (register 130): b0 sensor broken.
    assert not d.client().write_register(130, 0b0001, slave=247).isError()
    wait(browser, lambda dr: css(dr, 'button[data-channel="3"][data-fault="sensor_broken"]')
         .get_attribute("aria-pressed") == "true", timeout=3)
    # Channels 0-7 are shown; the toggle shows all 32.
    last = css(browser, 'tr[data-channel="31"]')
    assert css(browser, 'tr[data-channel="7"]').is_displayed() and not last.is_displayed()
    css(browser, "#show-all").click()
    assert last.is_displayed()
    # Freeze from the page; the API says frozen.
    css(browser, "#frozen").click()
    wait(browser, lambda dr: css(dr, "#frozen").get_attribute("aria-pressed") == "true")
    assert api(base, "/api/v1/plcs/0/simulator")[1]["frozen"] is True


def comm_button(driver, key):
    return css(driver, f'button[data-comm-fault="{key}"]')


def pressed(element):
    return element.get_attribute("aria-pressed") == "true"


def timed_read_r0(d):
    """How long a pymodbus read of R0 (holding register 0) takes, in s, on a new connection."""
    c = d.client()
    start = time.monotonic()
    r = c.read_holding_registers(0, 1, slave=1)
    took = time.monotonic() - start
    assert not r.isError(), r
    c.close()
    return took


def refused_soon(port, within=1.0):
    """Whether a connect to `port` is refused within `within` s. The listener closes its socket
    at its next sweep, or at the first connection it accepts meanwhile (which it resets)."""
    deadline = time.monotonic() + within
    while time.monotonic() < deadline:
        try:
            socket.create_connection(("127.0.0.1", port), timeout=1).close()
        except ConnectionRefusedError:
            return True
        except ConnectionResetError:
            pass
        time.sleep(0.02)
    return False


def open_plant(driver, base):
    driver.get(f"{base}/plcs/0/plant")
    wait(driver, lambda dr: dr.find_elements(By.CSS_SELECTOR, 'button[data-comm-fault="delay"]'))
    wait(driver, lambda dr: "live" in css(dr, "#status").get_attribute("class").split())
    wait(driver, lambda dr: css(dr, '#comm-summary [data-field="scope"]').text != "—",
         what="the communication faults were not read")
    driver.execute_script("window.plcemuNotReloaded = true;")


def test_the_comm_fault_buttons_switch_the_faults(browser, start_plcemud):
    d, base = start_console(start_plcemud)
    open_plant(browser, base)
    keys = [b.get_attribute("data-comm-fault")
            for b in browser.find_elements(By.CSS_SELECTOR, "#comm-buttons button")]
    assert keys == ["delay", "drop", "exception", "offline", "refuse", "disconnect", "garble",
                    "stop"]
    assert not any(pressed(comm_button(browser, k)) for k in keys)
    assert css(browser, '#comm-summary [data-field="faults"]').text == "none"
    assert css(browser, '#comm-summary [data-field="scope"]').text == "every request"
    assert timed_read_r0(d) < 0.05

    delay = comm_button(browser, "delay")
    assert delay.text == "Delay 300 ms"
    delay.click()
    wait(browser, lambda _: pressed(delay), what="the delay button is not lit")
    assert api(base, "/api/v1/plcs/0/comm-faults")[1]["delay_ms"] == 300
    assert timed_read_r0(d) >= 0.28
    assert css(browser, '#comm-summary [data-field="faults"]').text == "delay 300 ms"
    assert "ok" in message(browser)[1]
    # A second fault keeps the first: the page PUTs the whole set it wants.
    comm_button(browser, "drop").click()
    wait(browser, lambda dr: pressed(comm_button(dr, "drop")))
    state = api(base, "/api/v1/plcs/0/comm-faults")[1]
    assert (state["delay_ms"], state["drop_every"]) == (300, 2), state
    assert pressed(delay)
    comm_button(browser, "drop").click()
    wait(browser, lambda dr: not pressed(comm_button(dr, "drop")))

    css(browser, "#comm-clear").click()
    wait(browser, lambda _: not pressed(delay), what="the delay button is still lit")
    assert timed_read_r0(d) < 0.05
    assert api(base, "/api/v1/plcs/0/comm-faults")[1]["active"] is False
    assert css(browser, '#comm-summary [data-field="faults"]').text == "none"

    # Refuse connections: the PLC as switched off, new connections refused and those open
    # answered nothing (Offline lights too); switched off, both go.
    comm_button(browser, "refuse").click()
    wait(browser, lambda dr: pressed(comm_button(dr, "refuse")))
    assert pressed(comm_button(browser, "offline"))
    state = api(base, "/api/v1/plcs/0/comm-faults")[1]
    assert (state["refuse_connections"], state["offline"]) == (True, True), state
    assert refused_soon(d.port), "new connections are not refused"
    comm_button(browser, "refuse").click()
    wait(browser, lambda dr: not pressed(comm_button(dr, "refuse")))
    assert not pressed(comm_button(browser, "offline"))
    # The listener opens its socket again at its next sweep.
    deadline = time.monotonic() + 2
    while not port_open(d.port):
        assert time.monotonic() < deadline, "the listener does not accept connections again"
        time.sleep(0.02)
    assert timed_read_r0(d) < 0.05

    # A fault switched elsewhere lights its button at the next refresh (once a second).
    status, _ = api(base, "/api/v1/plcs/0/comm-faults", "PUT",
                    {"exception": 4, "from": "R100", "count": 10})
    assert status == 200
    wait(browser, lambda dr: pressed(comm_button(dr, "exception")), timeout=3,
         what="a fault set through the API does not light its button")
    assert comm_button(browser, "exception").text == "Exception 04"
    assert css(browser, '#comm-summary [data-field="faults"]').text == "exception 04h"
    assert css(browser, '#comm-summary [data-field="scope"]').text == "R100-R109"
    assert css(browser, "#comm-from").get_attribute("value") == "R100"
    assert css(browser, "#comm-count").get_attribute("value") == "10"
    # Switched off from the page, the scope it had is kept.
    comm_button(browser, "exception").click()
    wait(browser, lambda dr: not pressed(comm_button(dr, "exception")))
    state = api(base, "/api/v1/plcs/0/comm-faults")[1]
    assert (state["exception"], state["from"], state["count"]) == (0, "R100", 10), state
    assert not_reloaded(browser)


def test_a_bad_comm_fault_scope_shows_the_refusal_as_text(browser, start_plcemud):
    _, base = start_console(start_plcemud)
    name = "<script>alert(1)</script>"
    status, expected = api(base, "/api/v1/plcs/0/comm-faults", "PUT", {"from": name})
    assert status == 400, expected
    open_plant(browser, base)
    field = css(browser, "#comm-from")
    field.send_keys(name)
    css(browser, "#comm-apply").click()
    wait(browser, lambda dr: "error" in message(dr)[1], what="no refusal shown")
    text, _, shown = message(browser)
    assert shown and name in text and text == expected["error"]
    assert browser.find_elements(By.CSS_SELECTOR, "#message *") == []
    assert browser.find_elements(By.CSS_SELECTOR, "main script, main img") == []
    with pytest.raises(NoAlertPresentException):
        browser.switch_to.alert.text  # noqa: B018 - raises when there is no alert
    # What was typed stays to be corrected, over the refreshes; nothing was switched.
    time.sleep(1.2)
    assert field.get_attribute("value") == name
    assert api(base, "/api/v1/plcs/0/comm-faults")[1]["active"] is False
    # A fault button with that scope is refused the same way and stays unlit.
    browser.execute_script("document.getElementById('message').textContent = '';")
    comm_button(browser, "offline").click()
    wait(browser, lambda dr: message(dr)[0] == expected["error"], what="no refusal shown")
    assert not pressed(comm_button(browser, "offline"))
    assert api(base, "/api/v1/plcs/0/comm-faults")[1]["offline"] is False
    assert not_reloaded(browser)


def test_the_comm_fault_buttons_need_the_token(browser, start_plcemud):
    _, base = start_console(start_plcemud, http=", token: s3cret")
    open_plant(browser, base)
    comm_button(browser, "stop").click()
    wait(browser, lambda dr: "error" in message(dr)[1], what="no refusal shown")
    assert "token" in message(browser)[0]
    assert api(base, "/api/v1/plcs/0/comm-faults")[1]["stop"] is False
    css(browser, "#token").send_keys("s3cret")
    comm_button(browser, "stop").click()
    wait(browser, lambda dr: pressed(comm_button(dr, "stop")), what="the write with the token")
    assert api(base, "/api/v1/plcs/0/comm-faults")[1]["stop"] is True
    # Clear all (a DELETE, without a body) sends the token too.
    css(browser, "#comm-clear").click()
    wait(browser, lambda dr: not pressed(comm_button(dr, "stop")), what="Clear all with the token")
    assert api(base, "/api/v1/plcs/0/comm-faults")[1]["active"] is False


# ---- Traffic ---------------------------------------------------------------------------------


def peer_of(client):
    """The "address:port" plcemud sees a pymodbus client as."""
    host, port = client.socket.getsockname()[:2]
    return f"{host}:{port}"


# The traffic page's request rows, newest first, read in one go (the page replaces its rows
# when the list changes): each row's data attributes, its cells' texts ("td.devices", ...)
# and whether it is marked refused.
ROWS_JS = """
return [...document.querySelectorAll('#exchanges tbody tr[data-function]')].map((tr) => {
  const o = {...tr.dataset, refused: tr.classList.contains('refused')};
  for (const td of tr.querySelectorAll('td[data-field]')) o['td.' + td.dataset.field] = td.textContent;
  return o;
});
"""


def request_rows(driver):
    return driver.execute_script(ROWS_JS)


def newest(driver):
    rows = request_rows(driver)
    return rows[0] if rows else None


def client_cell(driver, peer, field):
    """The text of a clients table's cell of `peer`, or None while it has no row."""
    return driver.execute_script(
        "const td = document.querySelector("
        "`#clients tr[data-peer=\"${arguments[0]}\"] td[data-field=\"${arguments[1]}\"]`);"
        "return td ? td.textContent : null;", peer, field)


def test_the_traffic_page_lists_modbus_requests_and_pauses(browser, start_plcemud):
    d, base = start_console(start_plcemud, modbus=", write_protect: [R200-R209]")
    browser.get(f"{base}/plcs/0/traffic")
    wait(browser, lambda dr: "live" in css(dr, "#status").get_attribute("class").split(),
         what="the traffic page did not start refreshing")
    browser.execute_script("window.plcemuNotReloaded = true;")
    assert newest(browser) is None
    c = d.client()
    peer = peer_of(c)
    assert not c.read_holding_registers(100, 10, slave=1).isError()
    wait(browser, lambda dr: newest(dr), timeout=2.0, what="the FC03 request did not show within 2 s")
    first = newest(browser)
    assert first["function"] == "03h" and first["td.devices"] == "R100-R109", first
    assert (first["client"], first["td.client"], first["td.unit"], first["td.protocol"]) == (
        peer, peer, "1", "modbus-tcp"), first
    assert first["td.function"].startswith("03h") and not first["refused"], first
    assert first["error"] == "" and first["td.error"] == "", first
    # A refused write: on top (newest first), marked, with its exception code.
    assert c.write_register(205, 1, slave=1).isError()
    wait(browser, lambda dr: (newest(dr) or {}).get("function") == "06h", timeout=2.0,
         what="the refused FC06 did not show on top")
    rows = request_rows(browser)
    assert [(r["function"], r["td.devices"], r["error"], r["refused"]) for r in rows] == [
        ("06h", "R205", "02h", True), ("03h", "R100-R109", "", False)], rows
    assert "02h" in rows[0]["td.error"], rows[0]
    assert browser.find_elements(By.CSS_SELECTOR, 'tr[data-function="03h"] td[data-field="devices"]')
    # The client, counted.
    wait(browser, lambda dr: client_cell(dr, peer, "refusals") == "1",
         what="the client's refusal is not counted")
    assert client_cell(browser, peer, "requests") == "2"
    assert client_cell(browser, peer, "protocol") == "modbus-tcp"
    # Paused: a new request does not show, however long; the clients stay live.
    pause = css(browser, "#pause")
    assert pause.get_attribute("aria-pressed") == "false"
    pause.click()
    assert pause.get_attribute("aria-pressed") == "true" and pause.text == "Resume"
    time.sleep(0.2)  # a refresh already asked for is not shown either
    before = newest(browser)
    assert not c.read_holding_registers(300, 2, slave=1).isError()
    wait(browser, lambda dr: client_cell(dr, peer, "requests") == "3", timeout=2.0,
         what="the clients table stopped while paused")
    time.sleep(1.5)
    assert newest(browser) == before
    assert "R300-R301" not in [r["td.devices"] for r in request_rows(browser)]
    # Resumed: it shows.
    pause.click()
    assert pause.get_attribute("aria-pressed") == "false" and pause.text == "Pause"
    wait(browser, lambda dr: (newest(dr) or {}).get("td.devices") == "R300-R301", timeout=2.0,
         what="the request made while paused did not show after Resume")
    assert not_reloaded(browser)


# ---- Loops -----------------------------------------------------------------------------------


def open_loops(driver, base, count):
    """Opens the loops page and waits for its `count` faceplates and its first refresh."""
    driver.get(f"{base}/plcs/0/loops")
    wait(driver, lambda dr: len(dr.find_elements(By.CSS_SELECTOR, "article[data-loop]")) == count,
         what=f"not {count} faceplates")
    wait(driver, lambda dr: "live" in css(dr, "#status").get_attribute("class").split(),
         what="the loops page did not start refreshing")
    driver.execute_script("window.plcemuNotReloaded = true;")


def faceplate(driver, index, selector):
    return css(driver, f'article[data-loop="{index}"] {selector}')


def trend_points(driver, index, series="pv"):
    line = faceplate(driver, index, f'polyline[data-series="{series}"]')
    return int(line.get_attribute("data-points"))


def test_the_loops_page_shows_a_faceplate_per_loop_and_its_trend_grows(browser, start_plcemud):
    # At x10 the trend's 10 simulated minutes take a real minute to fill: it can still grow.
    _, base = start_config_file(start_plcemud, "default.yaml", "--time-scale", "10")
    forget_earlier_pages(browser)
    open_loops(browser, base, 10)
    cards = browser.find_elements(By.CSS_SELECTOR, "article[data-loop]")
    assert [c.get_attribute("data-loop") for c in cards] == [str(i) for i in range(10)]
    assert [c.find_element(By.TAG_NAME, "h2").text for c in cards] == [
        f"TPCTL point {i} (channel {i})" for i in range(10)]
    # Point 3: its set point in °C, editable in place; its lamps, its parameters; no switch.
    assert faceplate(browser, 3, 'input[data-device="R103"]').get_attribute("value") == "150.0"
    lamps = faceplate(browser, 3, ".lamps").find_elements(By.CSS_SELECTOR, "[data-alarm]")
    assert [(x.get_attribute("data-alarm"), x.get_attribute("data-on")) for x in lamps] == [
        ("in zone", "false"), ("warning", "false"), ("over temperature", "false"),
        ("heater open", "false")]
    for device in ("R123", "R133", "R143", "R113"):
        assert faceplate(browser, 3, f'input[data-device="{device}"]')
    assert browser.find_elements(By.CSS_SELECTOR, "button[data-switch]") == []
    # The loops started as a SCADA does (M800-M809, then M0): the heaters come on, and the
    # trend of point 0's PV grows by one point a refresh (ten simulated seconds at x10).
    assert api(base, "/api/v1/plcs/0/devices/WM800", "PUT", {"values": [1023]})[0] == 200
    assert api(base, "/api/v1/plcs/0/devices/M0", "PUT", {"values": [1]})[0] == 200
    first = trend_points(browser, 0)
    wait(browser, lambda dr: trend_points(dr, 0) >= first + 3, timeout=10,
         what="point 0's PV trend did not grow")
    assert trend_points(browser, 0, "sv") >= first + 3
    wait(browser, lambda dr: faceplate(dr, 0, '[data-field="output"]').text != "0.0 %",
         timeout=5, what="point 0's output stays at 0 %")
    assert re.fullmatch(r"\d+\.\d %", faceplate(browser, 0, '[data-field="output"]').text)
    assert int(faceplate(browser, 0, 'polyline[data-series="output"]').get_attribute(
        "data-points")) > 0
    assert not_reloaded(browser)
    # No CSP violation, no failed request, no script error.
    severe = [e for e in browser.get_log("browser") if e["level"] == "SEVERE"]
    assert severe == [], severe


def test_a_trend_opens_with_what_the_plc_kept_of_the_last_minutes(browser, start_plcemud):
    # Once its loops were looked at, the PLC keeps a sample a simulated second: a page opened
    # a simulated minute later draws about 60 points at once, where its own polls would draw one.
    _, base = start_config_file(start_plcemud, "default.yaml", "--time-scale", "60")

    def simulated():
        status, body = api(base, "/api/v1/plcs/0")
        assert status == 200, body
        return body["time"]["simulated_s"]

    assert api(base, "/api/v1/plcs/0/loops")[0] == 200  # someone looked: the PLC keeps them
    watched = simulated()
    deadline = time.monotonic() + 20
    while simulated() < watched + 60:
        assert time.monotonic() < deadline, "simulated time does not advance"
        time.sleep(0.1)
    open_loops(browser, base, 10)
    wait(browser, lambda dr: trend_points(dr, 0) >= 55, timeout=3,
         what="point 0's trend to open with the kept samples")
    assert trend_points(browser, 0, "sv") >= 55


def test_editing_a_loops_set_point_writes_its_register(browser, start_plcemud):
    d, base = start_config_file(start_plcemud, "default.yaml")
    open_loops(browser, base, 10)
    # In °C: 123.4 is R103 = 1234 (0.1 °C).
    type_into(browser, "R103", "123.4")
    wait(browser, lambda _: holding(d, 103) == 1234, what="R103 was not written 1234")
    wait(browser, lambda dr: "ok" in message(dr)[1], what="no confirmation")
    assert "R103 = 1234" in message(browser)[0]
    assert api(base, "/api/v1/plcs/0/devices/R103")[1]["values"] == [1234]
    browser.execute_script("document.activeElement.blur();")  # the field shows the live value
    wait(browser, lambda dr: css(dr, 'input[data-device="R103"]').get_attribute("value")
         == "123.4", what="R103's field does not show 123.4")
    # A parameter is raw: Kc of point 3.
    type_into(browser, "R123", "250")
    wait(browser, lambda _: holding(d, 123) == 250, what="R123 was not written 250")
    # A set point the register cannot hold: the server's refusal, in its own words.
    status, expected = api(base, "/api/v1/plcs/0/devices/R103", "PUT", {"values": [999990]})
    assert status == 400, expected
    type_into(browser, "R103", "99999")
    wait(browser, lambda dr: "error" in message(dr)[1], what="no refusal shown")
    assert message(browser)[0] == expected["error"]
    assert holding(d, 103) == 1234
    # Not a number: said, nothing written.
    type_into(browser, "R103", "12abc")
    wait(browser, lambda dr: "12abc" in message(dr)[0])
    assert "error" in message(browser)[1] and holding(d, 103) == 1234
    assert not_reloaded(browser)


def test_the_tuning_button_and_the_manual_switch_set_their_bits(browser, start_plcemud):
    # config/vb-pid.yaml: D201 = 31h, auto-tuning (bit 4) pending until M0 runs the PID.
    _, base = start_config_file(start_plcemud, "vb-pid.yaml")
    assert api(base, "/api/v1/plcs/0/devices/D201", "PUT", {"values": [0x21]})[0] == 200
    open_loops(browser, base, 1)
    button = faceplate(browser, 0, 'button[data-switch="tuning"]')
    assert button.text == "Start auto-tuning" and button.get_attribute("aria-pressed") == "false"
    assert faceplate(browser, 0, '[data-field="mode"]').text == "auto"
    button.click()
    wait(browser, lambda _: api(base, "/api/v1/plcs/0/devices/D201")[1]["values"] == [0x31],
         what="D201 bit 4 was not set")
    wait(browser, lambda _: button.get_attribute("aria-pressed") == "true", timeout=5,
         what="the button does not show the tuning")
    assert button.text == "Auto-tuning…" and not button.is_enabled()
    assert faceplate(browser, 0, '[data-field="mode"]').text == "tuning"
    assert "ok" in message(browser)[1]
    # config/vb-tpid.yaml: channel 0's manual bit is D103 bit 0.
    _, base = start_config_file(start_plcemud, "vb-tpid.yaml")
    open_loops(browser, base, 1)
    switch = faceplate(browser, 0, 'button[data-switch="manual"]')
    assert switch.get_attribute("aria-pressed") == "false"
    switch.click()
    wait(browser, lambda _: api(base, "/api/v1/plcs/0/devices/D103")[1]["values"] == [1],
         what="D103 bit 0 was not set")
    wait(browser, lambda _: switch.get_attribute("aria-pressed") == "true", timeout=5)
    assert faceplate(browser, 0, '[data-field="mode"]').text == "manual"
    switch.click()
    wait(browser, lambda _: api(base, "/api/v1/plcs/0/devices/D103")[1]["values"] == [0],
         what="D103 bit 0 was not cleared")
    wait(browser, lambda _: switch.get_attribute("aria-pressed") == "false", timeout=5)
    # Its output has a full scale (1000 = 100 %): a bar.
    assert faceplate(browser, 0, "progress").is_displayed()


# ---- Overview and the pages' frame -----------------------------------------------------------


def test_the_overview_shows_the_plc_and_its_scans_grow(browser, start_plcemud):
    _, base = start_console(start_plcemud)
    browser.get(base + "/")
    field = lambda name: css(browser, f'tr[data-plc="0"] td[data-field="{name}"]')  # noqa: E731
    wait(browser, lambda _: field("profile").text == "fbs", what="no row for PLC 0")
    assert field("model").text == "FBs-24MC"
    assert field("running").text == "RUN"
    browser.execute_script("window.plcemuNotReloaded = true;")
    first = int(field("scans").text)
    wait(browser, lambda _: int(field("scans").text) > first, timeout=3,
         what="the scans count did not grow")
    assert not_reloaded(browser)
    links = [a.get_attribute("href") for a in
             browser.find_elements(By.CSS_SELECTOR, 'tr[data-plc="0"] td a')]
    assert links == [f"{base}/plcs/0/{view}" for view in VIEWS]


def test_the_overview_shows_the_connected_clients_and_the_lateness(browser, start_plcemud):
    d, base = start_console(start_plcemud)
    c = d.client()
    peer = peer_of(c)
    assert not c.read_holding_registers(0, 1, slave=1).isError()
    assert c.read_holding_registers(9999, 1, slave=1).isError()
    browser.get(base + "/")
    row = f'#clients tr[data-plc="0"][data-peer="{peer}"]'
    wait(browser, lambda dr: dr.find_elements(By.CSS_SELECTOR, row), timeout=3,
         what=f"the client {peer} is not listed")
    field = lambda name: css(browser, f'{row} td[data-field="{name}"]').text  # noqa: E731
    assert (field("peer"), field("protocol"), field("requests"), field("refusals")) == (
        peer, "modbus-tcp", "2", "1")
    assert re.fullmatch(r"\d\d:\d\d:\d\d\.\d{3}", field("last")), field("last")
    lateness = css(browser, 'tr[data-plc="0"] td[data-field="lateness"]').text
    assert re.fullmatch(r"\d+ / \d+ µs", lateness), lateness
    p99, worst = map(int, re.findall(r"\d+", lateness))
    assert p99 <= worst
    # Live: more requests count up, and the client goes when it closes.
    browser.execute_script("window.plcemuNotReloaded = true;")
    assert not c.read_coils(0, 8, slave=1).isError()
    wait(browser, lambda _: field("requests") == "3", timeout=3, what="requests did not count up")
    c.close()
    wait(browser, lambda dr: not dr.find_elements(By.CSS_SELECTOR, row), timeout=3,
         what="the closed client is still listed")
    assert css(browser, "#clients tbody").text == "No client connected."
    assert not_reloaded(browser)


def test_every_page_has_the_nav_bar_and_a_title(browser, start_plcemud):
    _, base = start_console(start_plcemud)
    forget_earlier_pages(browser)
    for view in ("", *VIEWS):
        browser.get(f"{base}/plcs/0/{view}" if view else base + "/")
        wait(browser, lambda dr: dr.execute_script("return document.readyState") == "complete")
        nav = [a.text for a in browser.find_elements(By.CSS_SELECTOR, "#nav a")]
        current = [a.text for a in
                   browser.find_elements(By.CSS_SELECTOR, '#nav a[aria-current="page"]')]
        if view:
            assert nav == ["Overview", "Devices", "Loops", "Plant", "Traffic"]
            assert current == [view.capitalize()]
            assert browser.title.startswith(view.capitalize()) and "PLC 0" in browser.title
        else:
            assert nav == ["Overview"] and current == ["Overview"]
            assert browser.title.startswith("Overview")
        if view == "loops":
            # A program without loops: the page says so, and shows no faceplate.
            wait(browser, lambda dr: css(dr, "#no-loops").is_displayed(),
                 what="the loops page does not say there is no loop")
            assert browser.find_elements(By.CSS_SELECTOR, "article[data-loop]") == []
        assert "Not available yet" not in css(browser, "main").text
        # No CSP violation, no failed request, no script error.
        severe = [e for e in browser.get_log("browser") if e["level"] == "SEVERE"]
        assert severe == [], severe


def test_two_named_plcs_show_in_the_overview(browser, tmp_path):
    http = free_port()
    config = tmp_path / "two.yaml"
    config.write_text(
        f"http: {{port: {http}}}\n"
        "plcs:\n"
        "  - name: kiln\n"
        "    profile: fbs\n"
        f"    modbus: {{tcp: {{bind: 127.0.0.1, port: {free_port()}}}}}\n"
        "  - name: press\n"
        "    profile: fbs\n"
        "    station: 2\n"
        f"    modbus: {{tcp: {{bind: 127.0.0.1, port: {free_port()}}}}}\n"
    )
    env = {k: v for k, v in os.environ.items() if k != "STATE_DIRECTORY"}
    with open(tmp_path / "two.log", "wb") as log:
        proc = subprocess.Popen([PLCEMUD, "-c", str(config)], stdin=subprocess.DEVNULL,
                                stdout=log, stderr=log, cwd=tmp_path, env=env)
    try:
        deadline = time.monotonic() + 10
        while not port_open(http):
            assert proc.poll() is None, (tmp_path / "two.log").read_text()
            assert time.monotonic() < deadline, "the console did not listen"
            time.sleep(0.02)
        base = f"http://127.0.0.1:{http}"
        browser.get(base + "/")
        for name, station in (("kiln", "1"), ("press", "2")):
            row = f'tr[data-plc="{name}"]'
            wait(browser, lambda dr, r=row: dr.find_elements(By.CSS_SELECTOR, r),
                 what=f"no row for {name}")
            assert css(browser, f'{row} td[data-field="profile"]').text == "fbs"
            assert css(browser, f'{row} td[data-field="station"]').text == station
        rows = browser.find_elements(By.CSS_SELECTOR, "#plcs tbody tr")
        assert [r.get_attribute("data-plc") for r in rows] == ["kiln", "press"]
        css(browser, 'tr[data-plc="press"] a[href="/plcs/press/devices"]').click()
        wait(browser,
             lambda dr: dr.find_elements(By.CSS_SELECTOR, 'td[data-device="R0"][data-value]'))
        assert "PLC press" in browser.title
    finally:
        proc.send_signal(signal.SIGTERM)
        try:
            proc.wait(timeout=5)
        except subprocess.TimeoutExpired:
            proc.kill()
            proc.wait()
