"""The plant behind its interface (docs/architecture.md, "Adding a plant model"): the daemon, the
simulator-control unit, the profiles, the tag export and a reload see a `plant::Plant`; only
`src/plant/` names the model, and `make_plant()` there chooses it."""

from conftest import REPO

MODEL = "ThermalPlant"


def test_only_the_plant_module_names_the_thermal_model():
    naming = sorted(
        str(p.relative_to(REPO))
        for top in ("src", "include")
        for p in (REPO / top).rglob("*.[ch]pp")
        if MODEL in p.read_text(encoding="utf-8")
    )
    assert "src/plant/plant.cpp" in naming, naming  # make_plant() chooses it
    outside = [
        n for n in naming
        if not n.startswith("src/plant/") and n != "include/plcemu/plant/thermal_plant.hpp"
    ]
    assert outside == [], outside


def test_the_interface_header_names_no_model():
    header = (REPO / "include" / "plcemu" / "plant" / "plant.hpp").read_text(encoding="utf-8")
    assert "class Plant " in header
    assert MODEL not in header
