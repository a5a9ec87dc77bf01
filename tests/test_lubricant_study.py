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
