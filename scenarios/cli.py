"""`dpgt` console command: list the scenarios and run one by name.

    dpgt                      # list scenarios
    dpgt NAME [options...]    # same as python -m scenarios.NAME [options...]
    dpgt animate RESULTS --out FILE
"""
from __future__ import annotations

import importlib
import sys

from components.names import did_you_mean

from .core import args
from .core.command import command

SCENARIOS = {
    "params": "every parameter key with its value, unit, source tag and meaning (--grep WORD)",
    "demo": "the default job: forward vs reverse study at condition 3 (what `make demo` runs)",
    "paper_study": "forward/reverse study over operating conditions, comparison tables and plots",
    "lubricant_study": "which oil for which direction: film, traction, cage slip and heat against viscosity",
    "skidding_study": "do the planet bearings skid? cage slip against load, oil temperature and direction, "
                      "held against the catalogue minimum load",
    "fault_study": "what errors and faults do to the planet bearings and the rig's sensor",
    "gear_quality": "the forward/reverse study with real teeth: ISO 1328-1 tooth classes and seeds against perfect teeth",
    "tolerance_study": "load sharing K_γ, bearing loads and lives of machines drawn from their tolerances (static + dynamic)",
    "duty_cycle": "bearing lives over a duty cycle (speed–torque bins or a time series), Palmgren–Miner per bearing and planet",
    "bearing_misalignment": "a planet bearing's sliced life and edge pressure against the pin's slope, per roller profile",
    "misalignment_study": "the planet bearings' sliced life and edge pressure against the pins' slope in the full "
                          "machine (quasi-static, planets free to tilt), per profile, forward and reverse",
    "sensitivity": "which assumed parameters move each headline output: Morris screening, then Sobol indices (static)",
    "spectrum": "fixed-frame carrier-housing acceleration spectrum (the source's test rig)",
    "bearing_rig": "one planet bearing on a rig: roller load distribution, load zone, Q_max",
    "modal": "natural frequencies and mode shapes (single planetary set, DPGT with linear bearings)",
    "work_precision": "error against run time for every integrator",
    "stability": "stiff and extreme cases: what completes, what breaks and why",
    "benchmark": "speed target of the full DPGT",
    "bench_engine": "engine benchmark: networks of stiff bodies, HHT vs solve_ivp(Radau)",
    "animate": "animate saved results (cage orbits, whole train)",
}


def module(name: str) -> str:
    """The module whose ``main`` the command ``dpgt NAME`` runs: a numerics script's in scenarios.numerics (its
    ``python -m scenarios.NAME`` is a shim importing the same ``main``), a study's scenarios.NAME."""
    if name == "animate":
        return "viz.cli"
    numerics = f"scenarios.numerics.{name}"
    return numerics if importlib.util.find_spec(numerics) is not None else f"scenarios.{name}"


def available() -> dict[str, str]:
    out = {}
    for name, doc in SCENARIOS.items():
        if importlib.util.find_spec(module(name)) is not None:
            out[name] = doc
    return out


def main(argv=None) -> int:
    argv = list(sys.argv[1:] if argv is None else argv)
    have = available()
    if not argv or argv[0] in ("-h", "--help", "list"):
        print("usage: dpgt SCENARIO [options]   (dpgt SCENARIO --help for its options)\n\nscenarios:")
        for name, doc in have.items():
            print(f"  {name:<15} {doc}")
        return 0
    name, rest = argv[0], argv[1:]
    if name not in have:
        print(f"dpgt: unknown scenario {name!r}{did_you_mean(name, have)}; available: {', '.join(have)}", file=sys.stderr)
        return 2
    mod = importlib.import_module(module(name))
    main = mod.main if hasattr(mod.main, "__wrapped__") else command(mod.main)   # viz's too: one-line errors
    with args.invoked_as("dpgt"):        # usage lines and examples say `dpgt NAME`
        return main(rest)


if __name__ == "__main__":
    raise SystemExit(main())
