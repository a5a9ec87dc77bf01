"""scenarios.lubricant_study end to end on a tiny window (MODEL.md §3.8, the source's open question)."""
from __future__ import annotations

import csv

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
    assert all(float(r["h_min_m"]) > 0 and float(r["lambda_min"]) > 0 and r["cage_slip_pct"] for r in rows)
    # the film thickens with the oil as Pan–Hamrock's η^0.694 (10× the viscosity: ≈ 4.9×; loads differ a little)
    for d in ("forward", "reverse"):
        for b in ("inner", "outer"):
            h = {r["lubricant"]: float(r["h_min_m"]) for r in rows if (r["direction"], r["bearing"]) == (d, b)}
            assert 4.0 < h["100mPas"] / h["10mPas"] < 6.0
    text = (study / "answer.md").read_text()
    assert "condition 3, forward" in text and "condition 3, reverse" in text and "Λ" in text
    assert (study / "film_and_slip.png").stat().st_size > 10_000


def test_a_rerun_resumes_and_bad_oils_are_refused(study, capsys):
    before = (study / "summary.csv").read_text()
    assert lubricant_study.main(ARGS + ["--out", str(study)]) == 0    # every run finished: nothing recomputed
    assert (study / "summary.csv").read_text() == before
    assert lubricant_study.main(ARGS[:4] + ["--grades", "VG46", "--out", str(study)]) == 2
    assert "error: argument --grades: takes ISO VG grades" in capsys.readouterr().err


def test_a_thin_film_is_flagged_outside_the_ehl_laws_validity(study, capsys):
    """Λ_min < 1 with the EHL traction law: a warning names the bearing type and Λ; the dry laws, or a full
    film, give none. The study's own runs (condition 3, 10 and 100 mPa·s: Λ ≈ 2–7) carry no such warning."""
    import json

    from components.params import with_overrides
    from components.presets import reference_dpgt
    from scenarios.runner import validity_warnings

    ehl = with_overrides(reference_dpgt(1), {"bearing.traction_law": "ehl"}).si()
    thin = {"inner": {"lambda_min": 0.32, "film_min_m": 4.8e-8}, "outer": {"lambda_min": 1.7, "film_min_m": 2.6e-7}}
    w = validity_warnings(ehl, thin)
    assert len(w) == 1 and w[0].startswith("inner planet bearings") and "0.32" in w[0]
    assert validity_warnings(reference_dpgt(1).si(), thin) == []          # tanh law: not a film law
    for f in study.glob("*/summary.json"):
        assert not [x for x in json.loads(f.read_text())["warnings"] if "Λ_min" in x]
