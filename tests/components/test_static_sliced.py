"""Static states of the sliced machine at instants where the continuation with the rollers' tilts among its unknowns
stalls on a roller's tilt, so that mbd.static solves them again with each roller's tilt in its local group (with its
radius and spin): the four cases of the elastic pins and wind-up study that had no state (docs/misalignment.md,
condition 1, straight rollers, two snapshots) and the double-row bearing at 10′ tangential (condition 3 forward).

Truths: the solution is an equilibrium — every solved unknown's residual at the solver's tolerance and, without the
solver's residual, each planet's balance summed element family by element family: the bearing's load (the roller
slices on the bore) balances the meshes' forces, the cage's guide force, the planet's centrifugal load m Ω² r and its
weight seen in R (Rot(−φ) g), and the slices' tilting moment balances the meshes' on the planet's slope with the
slope's frame term J_d Ω² s (docs/model.md §2.4). A state moved off the solution by a tenth of an arcminute fails the
same balance (the check has teeth)."""
from __future__ import annotations

import warnings

import numpy as np
import pytest

import mbd
from components import static
from components.dpgt import build_dpgt
from components.params import with_overrides
from components.presets import reference_dpgt
from mbd.element import evaluate

ARCMIN = np.pi / 10800.0
PLANETS = ("a1", "a2", "a3", "b1", "b2", "b3")


def _slopes(gamma: float) -> list[dict]:
    """Every pin sloped by |γ| arcmin tangentially (90° from its planet's radial line; γ < 0: 270°)."""
    chi = 90.0 + (180.0 if gamma < 0 else 0.0)
    return [{"planet": p, "slope": f"{abs(gamma):g} arcmin", "direction": f"{chi:g} deg"} for p in PLANETS]


ONE_PLATE = {"bearing.pin.model": "elastic", "bearing.pin.mounting": "one_plate"}
CASES = {
    "c1 reverse, one-plate pins, aligned": (1, "reverse", ONE_PLATE),
    "c1 forward, wind-up, -4' tangential": (1, "forward", {"gears.carrier_windup": True, "errors.pin_slope": _slopes(-4)}),
    "c1 forward, one-plate pins, wind-up, -4' tangential": (1, "forward", {**ONE_PLATE, "gears.carrier_windup": True,
                                                                           "errors.pin_slope": _slopes(-4)}),
    "c1 reverse, wind-up, +4' tangential": (1, "reverse", {"gears.carrier_windup": True, "errors.pin_slope": _slopes(4)}),
    "c3 forward, double row, 10' tangential": (3, "forward", {"bearing.rows": 2, "errors.pin_slope": _slopes(10)}),
}


def _solve(condition, direction, overrides):
    ov = {"bearing.model": "sliced", "bearing.profile.shape": "straight", **overrides}
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        sc = build_dpgt(with_overrides(reference_dpgt(condition, direction), ov))
    t = static.snapshot_times(sc, 2)[0]          # the study's first instant: the one without a state before
    motion = static.steady_motion(sc)
    sol = mbd.static.solve_static(sc.model, motion, t, hold=static.held_dofs(sc), rates=static.rate_groups(sc),
                                  max_rate_step=static.RATE_STEP)
    return sc, sol


def _balance(m, t, q, v, z):
    """Per planet: (Σ of every family's force on its centre + m Ω² r + m Rot(−φ) g, the bore's force) and (Σ of every
    family's moment on its slope pair + J_d Ω² s, the bore's moment), each family evaluated on its own."""
    qf, vf = m.full(t, q, v)
    fs = m.frame.at(t)
    total, bore = np.zeros(m.n_full), np.zeros(m.n_full)
    for el in m.elements:
        F = np.asarray(evaluate(el, t, fs, qf, vf, z.get(el.name), False)[0])
        acc = np.zeros(m.n_full)
        np.add.at(acc, el.dofs.ravel(), F.ravel())
        total += acc
        if el.name == "race_outer":
            bore += acc
    c, s = np.cos(-fs.phi), np.sin(-fs.phi)
    g_r = np.array([c * m.gravity[0] - s * m.gravity[1], s * m.gravity[0] + c * m.gravity[1]])
    pairs = {m.body_names[m.extra_owner[i - m.n_body_coords]]: np.array([i, j]) for i, j in m.slope_pairs}
    out = []
    for name in PLANETS:
        b = m.body(name).index
        xy = slice(3 * b, 3 * b + 2)
        f = total[xy] + m.mass[b] * fs.omega ** 2 * qf[xy] + m.mass[b] * g_r
        sp = pairs[name]
        J_d = m.extra_inertia[sp - m.n_body_coords]
        mom = total[sp] + J_d * fs.omega ** 2 * qf[sp]
        out.append((f, bore[xy], mom, bore[sp]))
    return out


@pytest.mark.slow
@pytest.mark.parametrize("case", list(CASES))
def test_a_case_without_a_static_state_before_solves_to_an_equilibrium(case):
    sc, sol = _solve(*CASES[case])
    m = sc.model
    names = [m.coordinate_name(int(f)) for f in m.free]
    r = np.abs(sol.residual)
    # the solver's tolerance: 1e-11 m against stiffnesses of 1e9–1e10 N/m, 1e-11 m over a roller's radius of gyration
    # against its tilt stiffness; a tilt resting on a slice's damping jump would leave that jump (newtons·metres)
    planet_xy = [i for i, n in enumerate(names) if n.split(".")[0] in PLANETS and n.count(".") == 1
                 and n.endswith((".x", ".y"))]
    slopes = [i for i, n in enumerate(names) if n.endswith((".s_x", ".s_y"))]
    tilts = [i for i, n in enumerate(names) if n.endswith(".tilt")]
    assert len(planet_xy) == 12 and len(slopes) >= 6 and len(tilts) >= 72
    assert r[planet_xy].max() < 0.1, r[planet_xy].max()
    assert r[slopes].max() < 1e-3 and r[tilts].max() < 1e-3, (r[slopes].max(), r[tilts].max())
    for f, bore, mom, bore_mom in _balance(m, sol.t, sol.q, sol.v, sol.z):
        assert np.linalg.norm(bore) > 1e3                        # kN: the bearing carries the planet
        assert np.linalg.norm(f) < 1e-6 * np.linalg.norm(bore), (f, bore)
        assert np.linalg.norm(mom) < 1e-6 * max(np.linalg.norm(bore_mom), np.linalg.norm(bore) * 1e-3), (mom, bore_mom)


@pytest.mark.slow
def test_the_balance_fails_off_the_solution():
    """The same check on the first case's solution with planet a1 moved by 1 µm and its slope by 0.1′: both
    balances are off by far more than their bounds."""
    sc, sol = _solve(*CASES["c1 reverse, one-plate pins, aligned"])
    m = sc.model
    q = sol.q.copy()
    f2f = m.full_to_free
    b = m.body("a1").index
    q[f2f[3 * b]] += 1e-6
    sx = next(i for i, _ in m.slope_pairs if m.body_names[m.extra_owner[i - m.n_body_coords]] == "a1")
    q[f2f[sx]] += 0.1 * ARCMIN
    f, bore, mom, bore_mom = _balance(m, sol.t, q, sol.v, sol.z)[0]
    assert np.linalg.norm(f) > 1e-3 * np.linalg.norm(bore)
    assert np.linalg.norm(mom) > 1e-3 * max(np.linalg.norm(bore_mom), np.linalg.norm(bore) * 1e-3)
