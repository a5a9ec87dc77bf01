"""scenarios.lubricant_study end to end on a tiny window (docs/model.md §9, the source's open question)."""
from __future__ import annotations

import csv
import json

import pytest

from scenarios import lubricant_study

ARGS = ["--settle", "0.002", "--window", "0.001", "--viscosities", "10,100 mPa*s", "--workers", "1",
        "--no-progress"]


@pytest.fixture(scope="module")
def study(tmp_path_factory):
    out = tmp_path_factory.mktemp("lubricant")
    assert lubricant_study.main(ARGS + ["--out", str(out)]) == 0
    return out


def test_the_study_writes_its_table_answer_and_plot(study, capsys):
    with open(study / "summary.csv") as fh:
        rows = list(csv.DictReader(fh))
    assert len(rows) == 2 * 2 * 2                               # 2 oils × 2 directions × 2 bearing types
    assert set(rows[0]) == set(lubricant_study.COLUMNS)
    assert all(float(r["h_min_m"]) > 0 and float(r["lambda_min"]) > 0 for r in rows)
    # every row is its run's summary (the column a number, the bearing kind's, not a string that merely exists)
    for r in rows:
        s = json.loads((study / f"c{r['condition']}_{r['direction']}_{r['lubricant']}" / "summary.json").read_text())
        for col in ("cage_slip_pct", "lambda_min", "roller_inner_race_rms_N", "heat_traction_W"):
            assert float(r[col]) == pytest.approx(s[r["bearing"]][col], rel=1e-12), (r["lubricant"], r["bearing"], col)
    # the isothermal film thickens with the oil as Pan–Hamrock's η^0.694 (10×: ≈ 4.9×; loads differ a little);
    # the thermal one less, L growing with η (10 mPa·s: L ≈ 0.6, φ_T ≈ 0.85; 100: L ≈ 6, φ_T ≈ 0.55)
    for d in ("forward", "reverse"):
        for b in ("inner", "outer"):
            sel = [r for r in rows if (r["direction"], r["bearing"]) == (d, b)]
            h_iso = {r["lubricant"]: float(r["h_min_isothermal_m"]) for r in sel}
            h = {r["lubricant"]: float(r["h_min_m"]) for r in sel}
            phi = {r["lubricant"]: float(r["thermal_factor_min"]) for r in sel}
            assert 4.0 < h_iso["100mPas"] / h_iso["10mPas"] < 6.0
            assert 0.8 < phi["10mPas"] < 0.9 and 0.5 < phi["100mPas"] < 0.6
            assert 2.5 < h["100mPas"] / h["10mPas"] < 4.0
            for r in sel:
                assert r["regime"] == lubricant_study.regime(float(r["lambda_min"]))
    text = (study / "answer.md").read_text()
    assert text.startswith("Machine: reference machine [")                 # the answer names the machine
    assert "condition 3, forward" in text and "condition 3, reverse" in text and "Λ" in text
    assert "Λ ≥ 1.5 from" in text and "full film (Λ ≥ 3) from" in text and "reverse needs against forward" in text
    assert (study / "film_and_slip.png").stat().st_size > 10_000


def test_a_rerun_resumes_and_bad_oils_are_refused(study, capsys):
    before = (study / "summary.csv").read_text()
    assert lubricant_study.main(ARGS + ["--out", str(study)]) == 0    # every run finished: nothing recomputed
    assert (study / "summary.csv").read_text() == before
    assert lubricant_study.main(ARGS[:4] + ["--oil", "VG47", "--out", str(study)]) == 2
    assert "error: argument --oil: takes ISO VG grades" in capsys.readouterr().err


def test_replot_redraws_the_figure_from_summary_csv_alone(study, tmp_path, capsys, monkeypatch):
    """--replot reads the study's summary.csv back (every value as the study wrote it, typed) and redraws
    film_and_slip.png from it without running anything; an option about runs beside it is refused in one line."""
    import shutil

    rows = lubricant_study.read_rows(study / "summary.csv")
    with open(study / "summary.csv") as fh:
        raw = list(csv.DictReader(fh))
    assert len(rows) == len(raw) == 8
    for r, w in zip(rows, raw):
        assert r["condition"] == int(w["condition"]) and r["bearing"] == w["bearing"] and r["regime"] == w["regime"]
        assert r["lambda_min"] == float(w["lambda_min"]) and isinstance(r["h_min_m"], float)
    shutil.copy(study / "summary.csv", tmp_path / "summary.csv")
    drawn = []
    monkeypatch.setattr(lubricant_study, "plot", lambda rr, out: drawn.append((rr, out)) or [out / "film_and_slip.png"])
    monkeypatch.setattr(lubricant_study.LubricantStudy, "run", lambda self: pytest.fail("--replot ran the study"))
    assert lubricant_study.main(["--replot", "--out", str(tmp_path)]) == 0
    assert drawn == [(rows, tmp_path)] and sorted(p.name for p in tmp_path.iterdir()) == ["summary.csv"]
    assert lubricant_study.main(["--replot", "--out", str(tmp_path), "--oil", "VG68"]) == 2
    assert "--replot redraws the figure from --out's summary.csv and runs nothing: --oil" in capsys.readouterr().err
    assert lubricant_study.main(["--replot", "--out", str(tmp_path / "empty")]) == 2
    assert "no summary.csv in" in capsys.readouterr().err


def test_a_thin_film_is_flagged_outside_the_ehl_laws_validity(study, capsys):
    """Λ_min < 1 with the EHL traction law: a warning names the bearing type and Λ; the dry laws, or a thicker
    film, give none. The study's own runs (condition 3, 10 and 100 mPa·s: Λ ≈ 1.5–4) carry no such warning."""
    import json

    from components.params import with_overrides
    from components.presets import reference_dpgt
    from scenarios.core.runner import validity_warnings

    ehl = with_overrides(reference_dpgt(1), {"bearing.traction_law": "ehl"}).si()
    thin = {"inner": {"lambda_min": 0.32, "film_min_m": 4.8e-8}, "outer": {"lambda_min": 1.7, "film_min_m": 2.6e-7}}
    w = validity_warnings(ehl, thin)
    assert len(w) == 1 and w[0].startswith("inner planet bearings") and "0.32" in w[0]
    assert validity_warnings(reference_dpgt(1).si(), thin) == []          # tanh law: not a film law
    for f in study.glob("*/summary.json"):
        assert not [x for x in json.loads(f.read_text())["warnings"] if "Λ_min" in x]


def test_regimes_are_named_as_the_literature_names_them():
    """Λ ≥ 3 full film; 1 ≤ Λ < 3 partial EHL (mixed); Λ < 1 boundary-dominated."""
    r = lubricant_study.regime
    assert (r(3.0), r(2.999), r(1.0), r(0.999)) == ("full film", "partial EHL (mixed)", "partial EHL (mixed)",
                                                     "boundary-dominated")
    assert lubricant_study.LAMBDA_LEVELS == (1.5, 3.0)


def test_the_least_viscosity_reaches_its_film():
    """Without thermal loading the least viscosity is the closed form η (Λ_target/Λ)^(1/0.694); with it, the
    film of that viscosity — Pan & Hamrock's film of a contact times Murch & Wilson's φ_T(L η'/η), computed
    from the film functions at η' — has exactly the target Λ."""
    from components.lubrication import line_contact_film, reduced_modulus
    from mbd.elements.ehl import thermal_factor, thermal_loading
    least = lubricant_study.least_viscosity
    assert least(0.02, 1.2, 0.0, 3.0) == pytest.approx(0.02 * (3.0 / 1.2) ** (1 / 0.694), rel=1e-10)
    E, R, u, w, sigma, beta, k = reduced_modulus(210e9, 0.3, 210e9, 0.3), 3e-3, 14.0, 5e5, 1.5e-7, 0.038, 0.13

    def lam(eta):
        return (line_contact_film(u, w, R, eta, 2.2e-8, E)[0]
                * thermal_factor(thermal_loading(u, eta, beta, k)) / sigma)
    eta0 = 0.024
    L0 = thermal_loading(u, eta0, beta, k)
    for target in (1.5, 3.0, 6.0):
        eta = least(eta0, lam(eta0), L0, target)
        assert lam(eta) == pytest.approx(target, rel=1e-9)
        # scaling up, the thicker oil also heats its inlet more (L ∝ η): more than η^0.694 alone asks; down, less
        assert (eta > least(eta0, lam(eta0), 0.0, target)) == (target > lam(eta0))
