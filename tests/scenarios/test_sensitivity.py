"""The sensitivity study (scenarios.sensitivity) against truths it does not compute: a linear toy model through the
study's own evaluation plumbing (parameters overridden from their declared ranges, built, read back in SI), whose
Morris μ* is |a_i| × range and whose Sobol first-order indices are a_i² var(x_i) / Σ a_j² var(x_j); a parameter the
static solution cannot see moves nothing; bad input is refused in one line."""
from __future__ import annotations

import math

import numpy as np
import pytest

from components.params import DPGTParams
from scenarios import cli, sensitivity
from scenarios.core.command import USAGE

# the toy's factors, named out of their declaration order, with ranges written out here from presets' declarations
# in SI (m, K, m²/s, log10 of N/m): the study must apply each range to its own parameter in its unit
TOY = {                                  # key: (SI low, SI high, log)
    "lubricant.temperature": (313.15, 363.15, False),          # 40–90 degC
    "bearing.clearance": (5e-6, 40e-6, False),                  # 5–40 um
    "support.sun_stiffness": (1e6, 1e10, True),                 # 1e6–1e10 N/m, over its decades
    "lubricant.viscosity_40": (61.2e-6, 74.8e-6, False),        # 61.2–74.8 mm²/s
}
# each factor's contribution over its whole range (design-space span × coefficient): distinct, one negative
CONTRIBUTION = {"lubricant.temperature": -1.0, "bearing.clearance": 3.0, "support.sun_stiffness": 1.5,
                "lubricant.viscosity_40": 2.0}


def _span(key):
    lo, hi, log = TOY[key]
    return (math.log10(hi) - math.log10(lo)) if log else hi - lo


COEF = {k: CONTRIBUTION[k] / _span(k) for k in TOY}


def toy(params: DPGTParams, snapshots: int) -> dict:
    """y = Σ a_i x_i with x_i the parameter's SI value (log10 of it for a log range), read from the built
    parameters; a second output z = 7 y + 1 (μ* scales by 7, indices do not)."""
    si = params.si()
    x = {"lubricant.temperature": si.lubricant.temperature, "bearing.clearance": si.bearing.clearance,
         "support.sun_stiffness": math.log10(si.support.sun_stiffness),
         "lubricant.viscosity_40": si.lubricant.viscosity_40}
    y = sum(COEF[k] * x[k] for k in TOY)
    return {"y": y, "z": 7.0 * y + 1.0}


def _study(tmp_path, *extra, evaluator=toy):
    a = sensitivity.parse_args(["--conditions", "3", "--directions", "forward", "--workers", "1", "--no-progress",
                                "--out", str(tmp_path / "out"), *extra])
    return sensitivity.SensitivityStudy(a, evaluator).run()


def test_a_linear_toy_model_gives_the_closed_form_morris_and_sobol_indices(tmp_path):
    r = _study(tmp_path, "--parameters", ",".join(TOY), "--trajectories", "4", "--sobol", "4",
               "--sobol-samples", "128", "--seed", "3")
    p = r["points"]["c3_forward"]
    assert {f.name for f in r["files"]} == {"ranking.csv", "ranking.md", "sensitivity.json", "morris.png", "sobol.png"}
    for key, c in CONTRIBUTION.items():
        m = p["morris"]["y"][key]
        assert m["mu_star"] == pytest.approx(abs(c), rel=1e-6)       # |a_i| × range, every elementary effect
        assert m["mu"] == pytest.approx(c, rel=1e-6)                  # its sign
        assert m["sigma"] == pytest.approx(0.0, abs=1e-6)             # linear: no interaction, no curvature
        assert p["morris"]["z"][key]["mu_star"] == pytest.approx(7.0 * abs(c), rel=1e-6)
    # uniform inputs (in the log for a log range): var = span² / 12, S1_i = c_i² / Σ c_j², ST_i = S1_i
    total = sum(c * c for c in CONTRIBUTION.values())
    assert set(r["sobol_parameters"]) == set(TOY)
    for key, c in CONTRIBUTION.items():
        s = p["sobol"]["y"][key]
        truth = c * c / total
        assert s["S1_ci95"][0] <= truth <= s["S1_ci95"][1], (key, s, truth)
        assert s["ST_ci95"][0] <= truth <= s["ST_ci95"][1], (key, s, truth)
        assert abs(s["S1"] - truth) < 0.05 and abs(s["ST"] - truth) < 0.05, (key, s, truth)
        assert p["sobol"]["z"][key]["S1"] == pytest.approx(s["S1"], rel=1e-9)     # indices of 7y + 1 are y's


def test_the_ranking_table_orders_by_mu_star_and_reuses_finished_evaluations(tmp_path):
    r = _study(tmp_path, "--parameters", ",".join(TOY), "--trajectories", "3", "--sobol", "0")
    rows = [x for x in sensitivity.ranking_rows(r["points"]) if x["output"] == "y"]
    assert [x["parameter"] for x in rows] == sorted(CONTRIBUTION, key=lambda k: -abs(CONTRIBUTION[k]))
    assert rows[0]["mu_star_pct"] == pytest.approx(100.0 * 3.0 / abs(r["points"]["c3_forward"]["nominal"]["y"]))
    again = _study(tmp_path, "--parameters", ",".join(TOY), "--trajectories", "3", "--sobol", "0")
    assert again["points"]["c3_forward"]["morris"] == r["points"]["c3_forward"]["morris"]
    made = (tmp_path / "out" / "sensitivity.json").read_text()
    assert '"evaluated": 0' in made and '"reused": 16' in made          # 3 × 5 + the nominal machine


def test_a_parameter_the_static_solution_cannot_see_moves_nothing(tmp_path):
    """The housing under the rig's accelerometer is read after a run, never by the machine's equations: with the
    real static evaluator its elementary effects on every output are zero, where the sun's support moves K_γ."""
    r = _study(tmp_path, "--parameters", "support.sun_stiffness,rig.sensor.housing.mass", "--range",
               "rig.sensor.housing.mass=30 kg,80 kg", "--trajectories", "2", "--snapshots", "2", "--sobol", "0",
               evaluator=sensitivity.static_outputs)
    p = r["points"]["c3_forward"]
    assert set(p["morris"]) == set(sensitivity.OUTPUTS)
    for out, res in p["morris"].items():
        assert res["rig.sensor.housing.mass"]["mu_star_ci95"][1] <= 1e-12 * abs(p["nominal"][out]), out
    assert p["morris"]["k_gamma_mesh"]["support.sun_stiffness"]["mu_star"] > 1e-3     # the machine does see the sun


def test_factors_convert_declared_ranges_to_si_in_their_own_units():
    from components.presets import reference_dpgt

    fs = {f.key: f for f in sensitivity.factors(reference_dpgt(3), list(TOY))}
    for key, (lo, hi, log) in TOY.items():
        f = fs[key]
        assert (f.low, f.high, f.log) == (pytest.approx(lo), pytest.approx(hi), log)
        assert f.value(f.bounds()[0]) == pytest.approx(lo) and f.value(f.bounds()[1]) == pytest.approx(hi)
    assert fs["lubricant.temperature"].nominal == pytest.approx(333.15)           # 60 degC, not 60 K
    assert fs["bearing.clearance"].override(20e-6) == "2e-05 meter"
    assert np.isclose(fs["support.sun_stiffness"].value(8.0), 1e8)


@pytest.mark.parametrize("argv,words", [
    (["--parameters", "support.sun_stifness"], "support.sun_stifness: has no range"),
    (["--parameters", "support.sun_stifness"], "(did you mean 'support.sun_stiffness'?)"),
    (["--parameters", "gears.sun.teeth"], "gears.sun.teeth: has no range"),
    (["--range", "bearing.clearance=30 um,10 um"], "bearing.clearance: empty range"),
    (["--range", "bearing.clearance=1 kg,2 kg"], "expected a length"),
    (["--range", "bearing.clearence=1 um,30 um"], "(did you mean 'bearing.clearance'?)"),
    (["--range", "bearing.clearance=30 um"], "--range: expects KEY=LOW,HIGH[,log]"),
    (["--range", "support.sun_stiffness=0 N/m,1e9 N/m,log"], "a log range needs low > 0"),
    (["--sobol-samples", "24"], "--sobol-samples: must be a power of 2"),
    (["--levels", "3"], "--levels: Morris needs an even number of levels"),
    (["--conditions", "4"], "condition 4 transmits no torque"),
    (["--sobol-outputs", "k_gama_mesh"], "(did you mean 'k_gamma_mesh'?)"),
])
def test_bad_input_is_refused_in_one_line(argv, words, tmp_path, capsys):
    assert cli.main(["sensitivity", *argv, "--out", str(tmp_path / "out")]) == USAGE
    err = capsys.readouterr().err
    assert err.startswith("error: ") and words in err and err.count("\n") == 1, err
    assert not list((tmp_path / "out").glob("**/*.json"))           # nothing was evaluated


def test_the_screening_picks_each_outputs_strongest_and_can_be_asked_for_one_output():
    """Shares of each output's largest μ*: a factor strongest for any output scores 1; ties go to the larger mean share;
    a factor that moves nothing is never picked; ``outputs`` restricts the screening to those outputs."""
    m = lambda **kw: {k: {"mu_star": v} for k, v in kw.items()}
    morris = {("c3", "forward"): {"k": m(a=4.0, b=2.0, c=0.0, d=1.0), "life": m(a=0.0, b=1.0, c=0.0, d=3.0)},
              ("c2", "forward"): {"k": m(a=1.0, b=2.5, c=0.0, d=0.1), "life": m(a=0.0, b=0.0, c=0.0, d=5.0)}}
    keys = ["a", "b", "c", "d"]
    assert sensitivity.screen(morris, keys, 2) == ["d", "b"]        # d: 1 twice; a and b: 1 once, b's mean larger
    assert sensitivity.screen(morris, keys, 4) == ["d", "b", "a"]   # c moves nothing
    assert sensitivity.screen(morris, keys, 2, ["k"]) == ["b", "a"]
