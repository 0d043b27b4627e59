"""scripts/trace.py and scripts/plot_trace.py (docs/simulator-and-plant.md, "Tracing a closed
loop") against the real daemon: config/vb-pid.yaml's auto-tuning from cold (docs/profile-vb.md,
"FNC88 PID"), also under a modbus.map that moves every device, so the addresses must come from
the daemon's own map; and config/default.yaml's TPCTL columns."""

import csv
import subprocess
import sys

import pytest
import yaml

from conftest import PLCEMUD, REPO

TRACE = REPO / "scripts" / "trace.py"
PLOT = REPO / "scripts" / "plot_trace.py"
PID_COLUMNS = ["pv", "sv", "mv", "at", "kp", "ti", "td", "power"]


def trace(config, out, minutes, *writes):
    r = subprocess.run(
        [sys.executable, TRACE, "--plcemud", PLCEMUD, "--config", config, "--minutes",
         str(minutes), "--out", out, *writes],
        capture_output=True, text=True, timeout=120)
    assert r.returncode == 0, r.stderr
    with open(out, newline="") as f:
        return list(csv.DictReader(f))


def remapped(tmp_path):
    """config/vb-pid.yaml with a modbus.map that puts D and M elsewhere than the default map."""
    cfg = yaml.safe_load((REPO / "config" / "vb-pid.yaml").read_text())
    cfg["modbus"]["map"] = [
        {"table": "holding", "start": 0x4000, "device": "D0", "count": 8000},
        {"table": "coils", "start": 0x1000, "device": "M0", "count": 3072},
    ]
    path = tmp_path / "remapped.yaml"
    path.write_text(yaml.safe_dump(cfg))
    return path


@pytest.mark.parametrize("variant", ["as shipped", "remapped"])
def test_vb_pid_auto_tuning_trace(tmp_path, variant):
    """Setting M0 starts the PID with D201 = 0031h: the relay heats at full power (D102 = 500,
    the plant channel at ~100 %), AT ends at ~100 s (1 s samples) with Kp 223 +/- 15 %, TI 130
    and TD 325 +/- 20 %, the PV peaking at 162.4 +/- 1.5 degC meanwhile."""
    config = REPO / "config" / "vb-pid.yaml" if variant == "as shipped" else remapped(tmp_path)
    rows = trace(config, tmp_path / "t.csv", 3)
    assert list(rows[0]) == ["time_s"] + [f"pid0_{c}" for c in PID_COLUMNS]
    assert len(rows) == 181
    first = rows[0]
    assert float(first["pid0_sv"]) == 150.0
    assert 24.0 <= float(first["pid0_pv"]) <= 26.0  # the module reads the ambient
    assert first["pid0_at"] == "1"
    heating = rows[10]
    assert int(heating["pid0_mv"]) == 500
    assert float(heating["pid0_power"]) > 95

    end = next(r for r in rows[1:] if r["pid0_at"] == "0")
    t = float(end["time_s"])
    assert 90 <= t <= 111, t
    kp, ti, td = (int(end[f"pid0_{k}"]) for k in ("kp", "ti", "td"))
    assert 223 * 0.85 <= kp <= 223 * 1.15, kp
    assert 130 * 0.8 <= ti <= 130 * 1.2, ti
    assert 325 * 0.8 <= td <= 325 * 1.2, td
    assert all(r["pid0_at"] == "0" for r in rows if float(r["time_s"]) >= t)
    peak = max(float(r["pid0_pv"]) for r in rows if float(r["time_s"]) <= t)
    assert 160.9 <= peak <= 163.9, peak
    # The tuned loop brings PV back to SV: within +/- 2 degC at the end of the 3 minutes.
    assert abs(float(rows[-1]["pid0_pv"]) - 150.0) <= 2.0


def test_vb_pid_no_start_leaves_m0_off(tmp_path):
    """--no-start: nothing sets M0, so the PID never runs: D102 stays 0, D201 keeps b4."""
    rows = trace(REPO / "config" / "vb-pid.yaml", tmp_path / "t.csv", 0.5, "--no-start")
    assert all(r["pid0_mv"] == "0" and r["pid0_at"] == "1" for r in rows)
    assert float(rows[-1]["pid0_pv"]) <= 26.0


def test_vb_pid_writes_come_first(tmp_path):
    """D201=0x21 (no auto-tuning) with Kp/TI/TD written before M0: the tuned step, no relay."""
    rows = trace(REPO / "config" / "vb-pid.yaml", tmp_path / "t.csv", 1, "D201=0x21",
                 "D203=223", "D204=130", "D206=325")
    assert all(r["pid0_at"] == "0" for r in rows)
    assert int(rows[-1]["pid0_kp"]) == 223
    # The PID's first sampling comes 2 s after M0; the output then follows the error.
    assert 0 < int(rows[5]["pid0_mv"]) <= 500


def test_fbs_tpctl_trace_columns(tmp_path):
    """config/default.yaml: the ten TPCTL points' columns, SP 150.0, heating starts."""
    rows = trace(REPO / "config" / "default.yaml", tmp_path / "t.csv", 2)
    head = ["time_s"] + [f"c{c}_{k}" for c in range(10) for k in ("pv", "sp", "or", "duty")]
    assert list(rows[0]) == head
    assert len(rows) == 121
    assert all(float(r["c0_sp"]) == 150.0 for r in rows)
    assert float(rows[-1]["c0_duty"]) > 50
    assert float(rows[-1]["c9_pv"]) > float(rows[30]["c9_pv"]) >= 24.0


def test_plot_of_a_pid_trace(tmp_path):
    pytest.importorskip("matplotlib")
    trace(REPO / "config" / "vb-pid.yaml", tmp_path / "t.csv", 2)
    r = subprocess.run([sys.executable, PLOT, tmp_path / "t.csv", tmp_path / "t.png"],
                       capture_output=True, text=True, timeout=120)
    assert r.returncode == 0, r.stderr
    assert (tmp_path / "t.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
