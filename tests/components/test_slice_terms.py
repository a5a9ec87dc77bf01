"""The ISO/TS 16281 slice terms of the sliced life (components.statistics.quantities.slice_quantities, compiled in
components.statistics.accumulate.power_terms): equal to numpy's power to round-off, and through the life's equivalent
loads (components.life) against closed forms — a uniform slice load Q/n_s is the roller load Q's life (ISO/TS 16281's
slice ratings q_c n_s^(−7/9) make the n_s terms sum to the roller's), a load present half the time has the equivalent
load 2^(−1/e) of it on each raceway (e = 9/2 on the pin, 4 on the bore), and loads scaled by s scale the life by
s^(−4). Each fails on a wrong exponent of the terms (the equivalent loads take the raceways' own)."""
from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pytest

from components.life import (ROTATING_EXPONENT, STATIONARY_EXPONENT, equivalent_load, lundberg_palmgren_life,
                             sliced_life, sliced_raceway_ratings)
from components.presets import reference_bearing
from components.statistics.accumulate import power_terms
from components.statistics.quantities import slice_quantities

N_S = 7              # slices per roller
ROLLERS = 4          # rollers of the one bearing


@pytest.mark.parametrize("exponent", [STATIONARY_EXPONENT, ROTATING_EXPONENT, 10.0 / 3.0, 1.0, 0.5, 2.7, 31.5])
def test_power_terms_are_numpys_power(exponent):
    """Whole and half-whole exponents by squaring (4, 9/2, 1, 1/2, 31.5), the others by ** (10/3, 2.7): numpy's
    (x/c)^e to a few ulp, zeros exactly zero."""
    rng = np.random.default_rng(7)
    x = np.concatenate([np.zeros(5), rng.uniform(0.0, 3e3, 400), rng.uniform(0.0, 1e-3, 50), [1e4, 2.5e3]])
    c = 1.37e3
    got = np.empty_like(x)
    power_terms(x, c, exponent, got)
    np.testing.assert_allclose(got, (x / c) ** exponent, rtol=1e-14, atol=0.0)
    assert np.all(got[:5] == 0.0)


@pytest.mark.parametrize("exponent", [STATIONARY_EXPONENT, ROTATING_EXPONENT])
def test_power_terms_of_a_multiple_of_the_rating(exponent):
    """x = s c gives s^e: 2^4 = 16, 2^(9/2) = 16 √2, 3^(9/2) = 81 √3."""
    got = np.empty(3)
    power_terms(np.array([2.0, 3.0, 0.5]) * 1.3e4, 1.3e4, exponent, got)
    want = {4.0: [16.0, 81.0, 1 / 16], 4.5: [16.0 * np.sqrt(2.0), 81.0 * np.sqrt(3.0), np.sqrt(0.5) / 16]}[exponent]
    np.testing.assert_allclose(got, want, rtol=2e-16 * 4)


def _plan(b):
    return SimpleNamespace(bearing=b, slices=N_S, roller_bearing=np.zeros(ROLLERS, np.int64), planet=np.zeros(1))


def _outputs(q):
    """A race family's outputs for slice loads q (K, rollers, n_s) [N]: what slice_quantities reads."""
    zero = np.zeros(q.shape[:2])
    out = {"max_slice_load": q.max(-1), "edge_load": np.maximum(q[..., 0], q[..., -1]), "mid_load": q[..., N_S // 2],
           "race_slope_x": zero, "race_slope_y": zero}
    out.update({f"slice_load_{k}": q[..., k] for k in range(N_S)})
    return out


def _life(b, pin, bore):
    """The sliced life [10^6 rev] from slice loads pin, bore (K, rollers, n_s) at equal steps, as the statistics take
    it (components.statistics.summaries._sliced_life): per slice the mean over the states and the rollers of the
    slice terms, each raceway's equivalent load with its exponent."""
    snap = slice_quantities(_plan(b), _outputs(pin), _outputs(bore))
    qc = sliced_raceway_ratings(b, N_S)
    q = [c * equivalent_load(snap[key].mean(axis=0).reshape(ROLLERS, N_S).mean(axis=0), e)
         for key, c, e in (("slice_inner_fatigue", qc[0], STATIONARY_EXPONENT),
                           ("slice_outer_fatigue", qc[1], ROTATING_EXPONENT))]
    return sliced_life(q[0], q[1], b)


def test_slice_terms_give_the_closed_form_lives():
    b = reference_bearing().si()
    Q_pin, Q_bore = 3.2e3, 1.1e3                 # roller loads [N], every slice Q/n_s
    uniform = lambda Q, K=6: np.full((K, ROLLERS, N_S), Q / N_S)                   # noqa: E731
    L = _life(b, uniform(Q_pin), uniform(Q_bore))
    assert L == pytest.approx(lundberg_palmgren_life(Q_pin, Q_bore, b), rel=1e-12)
    # loaded at half the states: each raceway's equivalent load 2^(−1/e) of the load, e its own exponent
    half = lambda Q: np.concatenate([uniform(Q, 3), np.zeros((3, ROLLERS, N_S))])  # noqa: E731
    L_half = _life(b, half(Q_pin), half(Q_bore))
    want = lundberg_palmgren_life(Q_pin * 2.0 ** (-1 / STATIONARY_EXPONENT), Q_bore * 2.0 ** (-1 / ROTATING_EXPONENT), b)
    assert L_half == pytest.approx(want, rel=1e-12)
    assert L_half / L > 1.5                      # (half the damage: 2^(8/9) = 1.85, were both exponents alike)
    # loads scaled by s: the life by s^(−4), with an uneven profile and changing loads
    rng = np.random.default_rng(3)
    pin, bore = rng.uniform(0.0, 900.0, (2, 6, ROLLERS, N_S))
    for s in (0.5, 3.0):
        assert _life(b, s * pin, s * bore) == pytest.approx(s ** -4 * _life(b, pin, bore), rel=1e-12)
