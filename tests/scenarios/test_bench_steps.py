"""bench_steps' error shares against hand-made steps: which DOF made the estimate is known by construction."""
from types import SimpleNamespace

import numpy as np
import pytest

from scenarios.numerics.bench_steps import _Tally, error_squares, roller_split


def test_error_squares_are_the_controllers_terms_by_hand():
    h = np.array([2e-6, 4e-6])
    a0 = np.zeros((2, 3))
    a1 = np.array([[1e3, 0.0, 0.0], [0.0, 0.0, 5e2]])
    atol = np.array([1e-8, 1e-8, 1e-6])
    e2 = error_squares(h, a0, a1, 0.1358, atol)
    assert e2[0, 0] == pytest.approx((0.1358 * 4e-12 * 1e3 / 1e-8) ** 2, rel=1e-14)
    assert e2[1, 2] == pytest.approx((0.1358 * 16e-12 * 5e2 / 1e-6) ** 2, rel=1e-14)
    assert e2[0, 1:].sum() == 0.0 and e2[1, :2].sum() == 0.0


@pytest.mark.parametrize("angle", [0.0, 0.7, 2.5, -1.9])
def test_roller_split_radial_and_tangential(angle):
    u = np.array([np.cos(angle), np.sin(angle)])
    t = np.array([-u[1], u[0]])
    for vec, radial_share in ((3.0 * u, 1.0), (2.0 * t, 0.0), (u + t, 0.5)):
        r, tg = roller_split(vec[0] ** 2, vec[1] ** 2, vec[0] * vec[1], u[0], u[1])
        total = vec @ vec
        assert r == pytest.approx(radial_share * total, abs=1e-12 * total)
        assert r + tg == pytest.approx(total, rel=1e-12)


def _fake(roller_at, da):
    """A planet 'a1' at the origin and its roller at ``roller_at``; one accepted step whose only acceleration change
    is ``da`` on the roller's (x, y)."""
    n = 6
    q = np.zeros(n); q[3:5] = roller_at
    a1 = np.zeros(n); a1[3:5] = da
    row = np.concatenate([[1e-6, 2e-6, 0.0], q, np.zeros(n), a1, np.zeros(n)])
    runner = SimpleNamespace(n=n, prm=np.array([0.0, 0.0, 0.0, 0.1358]), atol=np.full(n, 1e-8),
                             cs=SimpleNamespace(model=SimpleNamespace(body_names=("a1", "a1.pb.roller0"))))
    blk = SimpleNamespace(log=row[None, :], counters={"rejected": 1, "newton": 4})
    return runner, SimpleNamespace(a=np.zeros(n)), blk


@pytest.mark.parametrize("where, da, key", [((0.05, 0.0), (7.0, 0.0), "inner rollers radial"),
                                            ((0.0, 0.05), (7.0, 0.0), "inner rollers tangential"),
                                            ((0.03, 0.04), (3.0, 4.0), "inner rollers radial")])
def test_a_roller_moving_radially_is_called_radial(where, da, key):
    tally = _Tally()
    tally.take(*_fake(np.array(where), np.array(da)))
    out = tally.report(simulated=2e-6)
    assert out["error_share"] == {key: 1.0}
    assert out["accepted_per_simulated_s"] == pytest.approx(5e5)
    assert out["rejected_share"] == 0.5 and out["newton_per_step"] == 4.0


def test_roller_categories_by_construction():
    """Three rollers, two raceway contacts and one pocket each, over four steps whose contact states are set by hand:
    a sign change of a raceway deflection wins over a pocket's, a pocket's over a loaded raceway, loaded over free."""
    from scenarios.numerics.bench_steps import CATEGORIES, roller_categories

    race_roller, pocket_roller = np.array([0, 0, 1, 1, 2, 2]), np.array([0, 1, 2])
    d0 = np.array([[-1, 2, 3, -1, -1, -1],          # roller 0 loaded, 1 loaded, 2 free
                   [1, -1, 1, 1, -1, -1],           # roller 0 releases its first contact (1 → −1)
                   [-1, -1, 1, -1, -1, -1],
                   [0, 0, 0, 0, 0, 0]], float)
    d1 = np.array([[-1, 2, 3, -1, -1, -1],
                   [-1, -1, 1, 1, -1, 1],           # roller 2's second contact closes
                   [-1, -1, 1, -1, -1, -1],
                   [0, 0, 0, 0, 0, 1e-9]], float)   # δ = 0 is open: roller 2 closes from exactly zero
    p0 = np.array([[0, 0, 0], [0, 0, 0], [0, 1, 0], [0, 0, 0]], float)
    p1 = np.array([[0, 0, 0], [0, 0, 0], [0, 0, 0], [1, 0, 0]], float)   # step 2: roller 1's pocket opens
    got = roller_categories(d0, d1, p0, p1, race_roller, pocket_roller, 3)
    name = np.array(CATEGORIES)[got]
    assert name.tolist() == [["in race contact", "in race contact", "out of contact"],
                             ["race onset/release", "in race contact", "race onset/release"],
                             ["out of contact", "pocket onset/release", "out of contact"],
                             ["pocket onset/release", "out of contact", "race onset/release"]]
