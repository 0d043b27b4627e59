"""The FATEK FB profile (docs/profile-fb.md) through Modbus TCP against the real daemon: the map
of docs/profile-fb.md, "Modbus map" (FATEK's table without the R3968 remap, D2999–D3071
unmapped, IR read-only), the special registers' power-up values, R4167, the identity, --print-map, and the
config errors of the profile and of `temperature.modules` at file:line:col (docs/profile-fb.md,
"Temperature modules")."""

import time

import pytest

from conftest import raw_request, run_plcemud
from test_vb import check_config, exc, expect_config_error, regs, write

ILLEGAL_FUNCTION = 1
ILLEGAL_ADDRESS = 2

FB = "profile: fb\nscan_ms: 10\nmodbus: {tcp: {bind: 127.0.0.1}}\n"

# R4004–R4023 after a start (docs/profile-fb.md, "Special registers").
R4004_DEFAULTS = [333, 0x0000, 90, 600, 350, 0, 0xFFFF, 0xFFFF, 0xFFFF, 0xFFFF, 500, 0, 248, 286,
                  240, 280, 0x0001, 8000, 1024, 1024]


def running(client):
    """Waits until a scan has run (M1926 RUN, coil 2000+1926, is ON); returns the client."""
    deadline = time.monotonic() + 10
    while True:
        r = client.read_coils(2000 + 1926, 1, slave=1)
        if not r.isError() and r.bits[0]:
            return client
        assert time.monotonic() < deadline, "no scan"
        time.sleep(0.01)


# --- map -----------------------------------------------------------------------------------


def test_s1_raw_readings_are_plain_holding_registers_and_a55ah_remaps_nothing(start_plcemud):
    """docs/profile-fb.md, "Modbus map": FC03 3968 qty 32 answers; R3968 = A55Ah is accepted and
    changes nothing: R0 stays at 0, Y0 at coil 0, and FC02/FC04 get exception 01 at any address."""
    d = start_plcemud(FB + "init: {R0: 1234, R3969: 0, R3970: 0, R3971: 5, R3974: 5, R3977: 5}\n")
    c = running(d.client())
    assert len(regs(c, 3968, 32)) == 32
    write(c, 3968, 0xA55A)
    assert regs(c, 3968) == [0xA55A]
    assert regs(c, 0) == [1234]  # R0, not the FBs remap
    assert exc(c.write_coil(0, True, slave=1)) == 0
    assert c.read_coils(0, 1, slave=1).bits[0] is True  # Y0
    assert regs(c, 0) == [1234]
    for addr in (0, 3968, 9999):
        assert exc(c.read_discrete_inputs(addr, 1, slave=1)) == ILLEGAL_FUNCTION
        assert exc(c.read_input_registers(addr, 1, slave=1)) == ILLEGAL_FUNCTION
    # A read across the rows R0-R3967, R3968-R3999, R4000-R4167 is one range.
    assert len(regs(c, 3960, 50)) == 50


def test_s1_d_ends_at_d2998_on_the_wire_and_d3071_in_the_plc(start_plcemud):
    """docs/profile-fb.md, "Modbus map": FC03 8998 answers (D2998), 8999 is exception 02 (D2999
    exists, not mapped); D3071 exists (an init: preset is accepted and a MOV copies it to a mapped
    register)."""
    d = start_plcemud(FB + "init: {D3071: 4321}\nprogram:\n  - MOV: {s: D3071, d: D0}\n")
    c = running(d.client())
    assert len(regs(c, 8998)) == 1
    assert exc(c.read_holding_registers(8999, 1, slave=1)) == ILLEGAL_ADDRESS
    deadline = time.monotonic() + 5
    while regs(c, 6000) != [4321]:
        assert time.monotonic() < deadline, "D0 never took D3071"
        time.sleep(0.01)


def test_s1_ir_is_read_only(start_plcemud):
    """docs/profile-fb.md, "Modbus map": FC06 3842 (IR R3842) gets exception 02."""
    d = start_plcemud(FB)
    c = running(d.client())
    assert exc(c.write_register(3842, 1, slave=1)) == ILLEGAL_ADDRESS
    assert exc(c.write_register(3839, 1, slave=1)) == 0  # R3839, the last HR
    assert exc(c.write_register(3904, 1, slave=1)) == 0  # R3904, the first OR


def test_s1_special_registers_after_start_and_model_code(start_plcemud):
    """docs/profile-fb.md, "Special registers": FC03 4004 qty 20 after start gives the defaults of
    R4004-R4023, and R4167 = 0128h (FB-40MC, the default model)."""
    d = start_plcemud(FB)
    c = running(d.client())
    assert regs(c, 4004, 20) == R4004_DEFAULTS
    assert regs(c, 4167) == [0x0128]
    d2 = start_plcemud(FB + "model: FB-20MA\n")
    assert regs(running(d2.client()), 4167) == [0x0014]


def test_special_registers_are_free_after_start_and_init_wins(start_plcemud):
    """docs/profile-fb.md, "Special registers": set at every start, then free; init: wins."""
    d = start_plcemud(FB + "init: {R4014: 250, R4016: 258}\n")
    c = running(d.client())
    assert regs(c, 4014) == [250]
    assert regs(c, 4016) == [258]
    write(c, 4021, 5000)
    assert regs(c, 4021) == [5000]


# --- identity, --print-map --------------------------------------------------------------------


def test_identity(start_plcemud):
    """docs/profile-fb.md, "Identity": FC17 "FATEK FB-40MC plcemu <version>", FC43/14 vendor
    FATEK and the model."""
    d = start_plcemud(FB)
    version = run_plcemud("--version").stdout.split()[1]
    report = raw_request(d.port, bytes([0x11]))
    assert report[4:].decode() == f"FATEK FB-40MC plcemu {version}"
    reply = raw_request(d.port, bytes([0x2B, 0x0E, 0x01, 0x00]))
    objects, k = {}, 7
    for _ in range(reply[6]):
        oid, n = reply[k], reply[k + 1]
        objects[oid] = reply[k + 2 : k + 2 + n].decode()
        k += 2 + n
    assert objects[0] == "FATEK" and objects[1] == "FB-40MC"


def test_print_map(tmp_path):
    """docs/profile-fb.md, "Modbus map": no image-held maps, one line for R3968-R3999 instead;
    D0-D2998 mapped."""
    p, _ = check_config(tmp_path, "profile: fb\n")
    r = run_plcemud("-c", p, "--print-map")
    assert r.returncode == 0, r.stderr
    assert "profile fb (FATEK FB-40MC)" in r.stdout
    assert "Maps held in the image" not in r.stdout
    assert "A55A" not in r.stdout
    raw = [ln for ln in r.stdout.splitlines()
           if "R3968-R3999: raw temperature readings (no user remap in profile fb)" in ln]
    assert len(raw) == 1 and "3968-3999" in raw[0]
    ir = [ln for ln in r.stdout.splitlines() if "R0-R3967" in ln]
    assert len(ir) == 1 and "R3840-R3903 (read-only)" in ir[0]
    assert any("D0-D2998" in ln and "6000-8998" in ln for ln in r.stdout.splitlines())


# --- config ----------------------------------------------------------------------------------


@pytest.mark.parametrize(
    "text",
    [
        "profile: fb\n",
        "{profile: fb}\n",
        "profile: fb\nmodel: FB-60MA\n",
        "profile: fb\ntemperature: {modules: [FB-2AK4, FB-2AJ4, FB-2AH4, FB-2AT4, FB-2AH4-3, "
        "FB-2AT4-3, FB-2AK4, FB-2AK4]}\n",
        "profile: fb\ntemperature: {modules: [FB-4AJ18]}\n",
        "profile: fb\ninit: {D3071: 1}\n",
    ],
    ids=["plain", "flow", "model", "eight-slim", "fb-4a", "d3071"],
)
def test_valid_configs(tmp_path, text):
    _, r = check_config(tmp_path, text)
    assert r.returncode == 0, r.stderr


@pytest.mark.parametrize(
    "text,line,col,needle",
    [
        ("profile: fb\nmodel: FBs-24MC\n", 2, 8, "an FB model such as FB-40MC"),
        ("profile: fb\nmodel: FB-44MN\n", 2, 8, "an FB model such as FB-40MC"),
        ("profile: fb\ninit:\n  D3072: 1\n", 3, 3, "D3072 is outside this PLC's D area (3072 devices)"),
        ("profile: fb\ntemperature:\n  table: D0\n", 3, 10, "temperature.table is not valid in "
         "profile fb"),
        ("profile: fb\ntemperature:\n  scan_rate: fast\n", 3, 14,
         "temperature.scan_rate is not valid in profile fb"),
        ("profile: fb\ntemperature:\n  modules: [FB-2AK4, TC6]\n", 3, 22,
         "unknown module 'TC6'"),
        ("profile: fb\ntemperature:\n  modules: [FB-4AK20]\n", 3, 13, "unknown module 'FB-4AK20'"),
        ("profile: fb\ntemperature:\n  modules: [FB-2AK4, FB-2AK4, FB-2AK4, FB-2AK4, FB-2AK4, "
         "FB-2AK4, FB-2AK4, FB-2AK4, FB-2AK4]\n", 3, 85, "at most 8"),
        ("profile: fb\ntemperature:\n  modules: [FB-4AK24, FB-4AJ12]\n", 3, 23,
         "FB-4AJ12 cannot be used together with the FB-4AK24"),
        ("profile: fb\ntemperature:\n  modulez: []\n", 3, 3, "modulez"),
    ],
    ids=["fbs-model", "mn", "D3072", "table", "scan_rate", "unknown", "fb-4ak20", "nine",
         "two-fb-4a", "typo"],
)
def test_config_errors_name_file_line_col(tmp_path, text, line, col, needle):
    expect_config_error(tmp_path, text, line, col, needle)


def test_s12_mixed_modules_exit_2_naming_both(tmp_path):
    """FB manual FUN73 (docs/profile-fb.md, "Temperature modules"): `temperature.modules:
    [FB-2AK4, FB-4AK24]` exits with status 2, naming both modules and where each stands."""
    text = "profile: fb\ntemperature:\n  modules: [FB-2AK4, FB-4AK24]\n"
    err = expect_config_error(tmp_path, text, 3, 22, "FB-4AK24 cannot be used together with "
                              "the FB-2AK4")
    assert f"{tmp_path / 'vb.yaml'}:3:13" in err
