"""docs/tour.ipynb — what researchers open first — runs end to end (nbclient), so it never rots."""
from __future__ import annotations

from pathlib import Path

import pytest

nbformat = pytest.importorskip("nbformat", reason="nbformat is part of the test extras (pyproject.toml)")
nbclient = pytest.importorskip("nbclient", reason="nbclient is part of the test extras (pyproject.toml)")

ROOT = Path(__file__).resolve().parent.parent


@pytest.mark.slow
def test_tour_notebook_runs_and_shows_a_load_zone_and_a_cage_orbit(tmp_path, monkeypatch):
    monkeypatch.setenv("MPLBACKEND", "Agg")
    monkeypatch.setenv("PYTHONPATH", str(ROOT))
    nb = nbformat.read(ROOT / "docs" / "tour.ipynb", as_version=4)
    nbclient.NotebookClient(nb, timeout=600, kernel_name="python3",
                            resources={"metadata": {"path": str(tmp_path)}}).execute()
    outputs = [o for c in nb.cells if c.cell_type == "code" for o in c.get("outputs", [])]
    assert not [o for o in outputs if o.get("output_type") == "error"]
    results = [o["data"]["text/plain"] for o in outputs if o.get("output_type") == "execute_result"]
    peak, radius = float(results[1]), float(results[2])      # the load zone's peak roller load, the orbit
    assert 100.0 < peak < 2e4                               # N: a loaded roller at condition 3
    assert 0.0 < radius < 250.0                             # µm: inside the guide clearance + contact
    assert any("a1.pb.roller" in r for r in results)       # the rollers are named by the file itself
