"""Manufacturing errors and faults (docs/model.md §11): the parameters, the perfect machine, and each
error's signature."""
from __future__ import annotations

import dataclasses
import functools
import re
import warnings

import numpy as np
import pytest

import mbd
from components import faults
from components.dpgt import build_dpgt
from components.params import to_toml, with_overrides
from components.presets import load_toml, reference_dpgt
from components.units import ParameterError

from tests.support import DATA, dpgt_runs

REF = DATA / "perfect_machine_a223f98.npz"
# the machine of commit a223f98 had the typical mesh stiffness c_γα = 20 N/(mm·µm) with k_double/k_single = 1.5 of
# every mesh (before ISO 6336-1's per-mesh values became the default): its states are those of that machine
A223F98_MESH = {"mesh.c_gamma_alpha": "20 N/(mm*um)", "mesh.stiffness_ratio": 1.5}
PINHOLE_B1 = {"errors.pinhole": [{"planet": "b1", "radial": "0 um", "tangential": "30 um"}]}


def _build(params):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return build_dpgt(params)


@pytest.mark.parametrize("condition, direction", [(3, "forward"), (1, "reverse")])
def test_perfect_machine_reproduces_the_machine_before_errors_existed(condition, direction):
    """0.5 ms of the reference DPGT from its kinematic start, numpy engine, against the states the code
    gave before errors existed (commit a223f98): bit-identical on the machine that wrote them. Another CPU
    rounds differently, and the contacts amplify it: a 1e-15 relative change of the start velocities moves
    the end state by up to 3.7e-12 max|q| and 1.3e-10 max|v| (measured), so the bound is 100× that.
    The states were made with Newton's max-norm convergence test (the former convergence test, kept to compare against), so they are
    compared with a run of that test (``per_component=False``; bit-identical here). The per-DOF test accepts
    other iterates, which the contacts amplify far above round-off (measured after 0.5 ms: 7.7e-5 to
    2.5e-4 of max|q|, 1.2e-3 to 3.1e-3 of max|v|): that would test the convergence rule, not the machine."""
    ref = np.load(REF)
    sc = _build(with_overrides(reference_dpgt(condition, direction), A223F98_MESH))
    key = f"{condition}{direction}"
    assert np.array_equal(sc.q0, ref[f"q0_{key}"]) and np.array_equal(sc.v0, ref[f"v0_{key}"])
    stepper = dataclasses.replace(mbd.PRODUCTION.stepper(), per_component=False)
    res = mbd.simulate(sc.model, sc.q0, sc.v0, 5e-4, stepper=stepper,
                       controller=mbd.PRODUCTION.controller(), progress=False, engine="numpy")
    for name, x in (("q", res.state.q), ("v", res.state.v)):
        r = ref[f"{name}_{key}"]
        np.testing.assert_allclose(x, r, rtol=0, atol=1e-8 * np.max(np.abs(r)))


@pytest.mark.parametrize("condition, direction", [(3, "forward"), (1, "reverse")])
def test_perfect_machine_has_the_forces_it_had_before_errors_existed(condition, direction):
    """At the loaded state that run reached (every contact family active, stored with its internal states),
    the forces and their Jacobian equal those of commit a223f98: no chaos between, so only summation-order
    round-off is allowed, on any CPU (bit-identical here)."""
    ref = np.load(REF)
    key = f"{condition}{direction}"
    sc = _build(with_overrides(reference_dpgt(condition, direction), A223F98_MESH))
    z = {k[len(f"z_{key}_"):]: ref[k] for k in ref.files if k.startswith(f"z_{key}_")}
    ev = mbd.System(sc.model).evaluate(float(ref[f"t_{key}"]), ref[f"q_{key}"], ref[f"v_{key}"], z, jac=True)
    Jq = ev.Jq.toarray() if hasattr(ev.Jq, "toarray") else ev.Jq
    for got, want in ((ev.F, ref[f"F_{key}"]), (Jq, ref[f"Jq_{key}"])):
        np.testing.assert_allclose(got, want, rtol=0, atol=1e-13 * np.max(np.abs(want)))
    assert np.count_nonzero(ref[f"Jq_{key}"]) > 1000


def test_errors_round_trip_through_toml_and_name_what_is_wrong(tmp_path):
    p = with_overrides(reference_dpgt(), {**PINHOLE_B1, "errors.tooth_fault": [{"gear": "ring", "tooth": 5,
                                                                               "stiffness_factor": 0.0}]})
    f = tmp_path / "damaged.toml"
    f.write_text(to_toml(p))
    assert load_toml(f).errors == p.errors
    assert reference_dpgt().errors.perfect and not p.errors.perfect
    bad = {
        "errors.pinhole[0].planet": [{"planet": "c1", "radial": "1 um", "tangential": "0 um"}],
        "errors.pinhole[0].radial": [{"planet": "b1", "radial": "1 kg", "tangential": "0 um"}],
        "errors.spall[0]": [{"planet": "a1", "raceway": "inner", "position": "0 deg", "width": "1 mm"}],
    }
    for where, entries in bad.items():
        with pytest.raises(ParameterError, match="^" + re.escape(where)):
            with_overrides(reference_dpgt(), {f"errors.{where.split('.')[1].split('[')[0]}": entries})
    # names and sizes are checked against the machine when it is built
    for override, where in (({"errors.pinhole": [{"planet": "b4", "radial": "1 um", "tangential": "0 um"}]},
                             "errors.pinhole[0].planet"),
                            ({"errors.tooth_fault": [{"gear": "sun", "tooth": 31, "stiffness_factor": 0.5}]},
                             "errors.tooth_fault[0].tooth"),
                            ({"errors.roller_diameter": [{"planet": "a1", "roller": 0, "deviation": "1 mm"}]},
                             "errors.roller_diameter[0].deviation"),
                            ({"errors.spall": [{"planet": "a1", "raceway": "outer", "position": "0 deg",
                                                "width": "1 mm", "depth": "10 um", "edge": "2 mm"}]},
                             "errors.spall[0].edge")):
        with pytest.raises(ParameterError, match="^" + re.escape(where)):
            _build(with_overrides(reference_dpgt(), override))


def test_pinhole_error_moves_the_pin_and_the_planet():
    p = with_overrides(reference_dpgt(), {"errors.pinhole": [{"planet": "b2", "radial": "20 um",
                                                              "tangential": "-10 um"}]})
    si = p.si()
    psi = si.layout.psi_b[1]
    moved = faults.pin_position(si, "b2", si.layout.centres_b[1]) - si.layout.centres_b[1]
    expect = 20e-6 * np.array([np.cos(psi), np.sin(psi)]) - 10e-6 * np.array([-np.sin(psi), np.cos(psi)])
    np.testing.assert_allclose(moved, expect, rtol=1e-12, atol=0)
    assert np.array_equal(faults.pin_position(si, "b1", si.layout.centres_b[0]), si.layout.centres_b[0])


def _pinhole_run(tangential_um):
    """Condition 3, linear planet bearings: per-planet outer bearing loads, K_γ, the sun centre in R."""
    ov = {} if tangential_um == 0 else {"errors.pinhole": [{"planet": "b1", "radial": "0 um",
                                                             "tangential": f"{tangential_um} um"}]}
    sun = []

    def observers(bs, t0, t1):
        i = bs.model.body("sun").index
        xy = bs.model.full_to_free[[3 * i, 3 * i + 1]]

        class Sun(mbd.Observer):           # the sun's centre in R (the carrier frame) on every step
            def step(self, s0, s1):
                if s1.t >= t0:
                    sun.append(s1.q[xy].copy())
        return [Sun()]
    bs, stats, _, _ = dpgt_runs.run(3, "forward", ov, window=0.01, bearings="linear", extra=observers)
    s = stats.summary()["outer"]
    return np.array(s["bearing_load_mean_per_planet_N"]), s["load_sharing_factor"], np.array(sun).mean(axis=0)


def test_pinhole_error_shifts_load_between_planets_and_turns_with_the_carrier():
    """Condition 3, linear planet bearings (load sharing is the gears' business): a pinhole ±30 µm off
    tangentially on outer planet b1 changes b1's bearing load by opposite amounts (linear for such small
    errors) while the mean stays (the torque is the same); the planets no longer share equally (K_γ > 1),
    and the floating sun is pushed off centre by a force fixed in the carrier frame: in the fixed frame a
    carrier-rate (f_c) harmonic. The perfect machine shares equally and keeps the sun centred."""
    loads0, k0, sun0 = _pinhole_run(0)
    loads_p, k_p, sun_p = _pinhole_run(30)
    loads_m, k_m, sun_m = _pinhole_run(-30)
    dp, dm = loads_p[0] - loads0[0], loads_m[0] - loads0[0]
    assert abs(dp) > 20 * np.ptp(loads0) and abs(dm) > 20 * np.ptp(loads0)    # far above the perfect spread
    assert dp * dm < 0 and abs(dp + dm) < 0.2 * abs(dp)                        # opposite, nearly linear
    for loads, d in ((loads_p, dp), (loads_m, dm)):
        assert abs(loads.mean() - loads0.mean()) < 0.1 * abs(d)                # the mean stays
    assert min(k_p, k_m) - 1 > 10 * (k0 - 1)
    off0 = np.linalg.norm(sun0)
    assert np.linalg.norm(sun_p) > 10 * off0 and np.linalg.norm(sun_m) > 10 * off0
    assert np.dot(sun_p - sun0, sun_m - sun0) < 0                              # pushed the other way


def _mesh_history(overrides, family_key, window=0.03):
    """Condition 3, linear planet bearings: per accepted step of the window, pair 1's mesh of
    ``family_key``: t, both flanks' force, stiffness over the healthy wave's, and the angles of gear 1, gear 2 and the line of
    centres φ_e (internal: ring centre → planet centre) in R."""
    from components.families import MESH_FAMILY

    rec = []

    def extra(bs, t0, t1):
        fam = MESH_FAMILY[family_key]
        el = bs.model.element(fam)
        g1, g2 = bs.model.body_names.index(_GEARS[family_key][0]), bs.model.body_names.index(_GEARS[family_key][1])

        class Obs(mbd.Observer):
            def bind(self, model, system, state):
                self.system, self.model = system, model

            def step(self, s0, s1):
                if s1.t < t0:
                    return
                o = self.system.outputs(s1.t, s1.q, s1.v, s1.z, families={fam})[fam]
                X = self.model.full(s1.t, s1.q, s1.v)[0].reshape(-1, 3)
                d = X[g1, :2] - X[g2, :2] if family_key == "outer_ring" else X[g2, :2] - X[g1, :2]
                healthy = el.k_mean * el._factor(np.asarray(o["position"], float))   # the wave without the fault
                rec.append((s1.t, o["force_drive"][0] + o["force_coast"][0], o["stiffness"][0] / healthy[0],
                            X[g1, 2], X[g2, 2], np.arctan2(d[1], d[0])))
        return [Obs()]
    dpgt_runs.run(3, "forward", overrides, window=window, bearings="linear", extra=extra)
    return np.array(rec).T


_GEARS = {"sun_inner": ("sun", "a1"), "outer_ring": ("b1", "ring")}


@functools.lru_cache(maxsize=None)
def _perfect_mesh_history(family_key):
    return _mesh_history({}, family_key)


def _repeats(t, x, t_ref, x_ref, period):
    """Correlation of the deviation x − x_ref (on a uniform grid) with itself shifted by ``period``."""
    tu = np.linspace(max(t[0], t_ref[0]), min(t[-1], t_ref[-1]), 20000)
    d = np.interp(tu, t, x) - np.interp(tu, t_ref, x_ref)
    n = int(round(period / (tu[1] - tu[0])))
    a, b = d[:-n], d[n:]
    return float(np.dot(a, b) / np.sqrt(np.dot(a, a) * np.dot(b, b)))


def _line(t, x, f0):
    """Amplitude of x(t) (resampled uniformly, Hann window) at f0."""
    from scenarios.core.analysis import amplitude_spectrum

    tu = np.linspace(t[0], t[-1], 4096)
    f, a, _ = amplitude_spectrum(tu, np.interp(tu, t, x))
    return float(a[np.argmin(np.abs(f - f0))])


def test_sun_runout_modulates_its_meshes_once_per_sun_revolution():
    """A sun eccentric by 20 µm: the sun–planet mesh force gains a line at the sun's rotation relative to
    the carrier (185 Hz at condition 3) that the perfect machine does not have (> 100× its level there)."""
    from scenarios.fault_study import characteristic_frequencies

    f_s = characteristic_frequencies(reference_dpgt(3).si())["sun_rel"]
    t0, F0, *_ = _mesh_history({}, "sun_inner")
    t1, F1, *_ = _mesh_history({"errors.runout": [{"gear": "sun", "eccentricity": "20 um", "phase": "0 deg"}]},
                               "sun_inner")
    a0, a1 = _line(t0, F0, f_s), _line(t1, F1, f_s)
    assert a1 > 100 * a0 and a1 > 0.05 * F1.mean()


@pytest.mark.parametrize("gear, tooth, factor, period_of, mesh", [("b1", 0, 0.0, "outer_planet_rel", {}),
                                                                   ("ring", 5, 0.5, "f_c", A223F98_MESH)])
def test_tooth_fault_weakens_its_mesh_once_per_revolution_of_its_gear(gear, tooth, factor, period_of, mesh):
    """A missing tooth on outer planet b1 / a cracked ring tooth: the b1–ring mesh stiffness drops to the
    fault's share exactly once per revolution of the faulty gear relative to the carrier (b1: 4.18 ms; the
    ring, fixed, meets b1 once per carrier revolution: 14.3 ms) and nowhere else. The tooth index is the
    real tooth: whenever that tooth's centre line crosses the pitch point its pair is in contact (on the
    loaded flank it touches a quarter pitch from there, inside the path of contact), and the weak stretch
    is ε_α pitches of the tooth's travel. The mesh force's deviation from the perfect machine's repeats once
    per revolution of the faulty gear (correlation with itself one revolution later ≥ 0.9, seen 0.975–0.997;
    half a revolution later ≤ 0.5, seen ≈ −0.2).

    The cracked ring tooth runs on the machine with c_γα = 20 N/(mm·µm) and k_double/k_single = 1.5 on every mesh
    (``mesh``): with ISO 6336-1's stiffness (the default) the deviation from the perfect machine carries, besides the
    fault's once-per-revolution pulse (325 N RMS in the weak stretches), a part that does not repeat: one
    revolution's deviation differs from the next by ≈ 50 N RMS throughout (with the typical stiffness by 15 N, 1–3 N
    in most milliseconds; the ring mesh runs near its resonance, method B's N = 0.92), which brings the
    one-revolution correlation over 30 ms to 0.80 (half a revolution: 0.10; from 15 ms on over 38 ms: 0.94). The fault
    law this test holds — which tooth, how often, how long — does not depend on the stiffness."""
    from scenarios.fault_study import characteristic_frequencies

    p = with_overrides(reference_dpgt(3), mesh) if mesh else reference_dpgt(3)
    period = 1.0 / characteristic_frequencies(p.si())[period_of]
    t, F, k, th1, th2, phi = _mesh_history({"errors.tooth_fault": [{"gear": gear, "tooth": tooth,
                                                                     "stiffness_factor": factor}], **mesh},
                                           "outer_ring")
    low = k < 1.0 - 1e-9
    # the weak pair's share: down to the factor in single contact, (1 + c)/2 in double contact
    assert k.min() == pytest.approx(factor, abs=1e-12) and k.max() == pytest.approx(1.0, abs=1e-12)
    t0, F0, *_ = _mesh_history(mesh, "outer_ring") if mesh else _perfect_mesh_history("outer_ring")
    assert _repeats(t, F, t0, F0, period) >= 0.9 and _repeats(t, F, t0, F0, 0.5 * period) <= 0.5
    starts = t[1:][np.diff(low.astype(int)) == 1]
    assert starts.size >= 2
    np.testing.assert_allclose(np.diff(starts), period, atol=2e-5)         # one mesh-step resolution
    mg = p.si().layout.meshes["outer_ring"]
    z = mg.z1 if gear == "b1" else mg.z2
    theta = th1 if gear == "b1" else th2
    # the faulty tooth's centre line from the pitch point's direction (at angle φ_e from either gear of an
    # internal mesh), in pitches
    rel = np.angle(np.exp(1j * (theta + 2 * np.pi * tooth / z - phi))) * z / (2 * np.pi)
    assert np.all(low[np.abs(rel) < 0.1]) and np.any(np.abs(rel) < 0.1)
    smooth = p.si().mesh.smoothing_width
    assert abs(np.ptp(rel[low]) - mg.contact_ratio) < smooth + 0.02
    if gear == "b1":     # gear 1: the stretch is where geometry puts that tooth's pair, [−h, ε − h]
        h = mg.entry_shift(dpgt_runs.build(p).flanks["outer_ring"])
        assert rel[low].min() > -h - smooth and rel[low].max() < mg.contact_ratio - h + smooth


def _bearing_history(overrides, window=0.01):
    """Condition 3, roller bearings: per accepted step of the window, b1's pin reaction magnitude and the
    inner-raceway load of every roller of a1's bearing."""
    from components.outputs import FAMILY

    rec = []

    def extra(bs, t0, t1):
        pairs = bs.pairs
        b1, a1 = pairs[0].outer_bearing.race_inner, pairs[0].inner_bearing.race_inner
        fam = FAMILY["race_inner"]

        class Obs(mbd.Observer):
            def bind(self, model, system, state):
                self.system = system

            def step(self, s0, s1):
                if s1.t >= t0:
                    o = self.system.outputs(s1.t, s1.q, s1.v, s1.z, families={fam})[fam]
                    rec.append((s1.t, np.hypot(np.sum(o["fx"][b1]), np.sum(o["fy"][b1])), *o["load"][a1]))
        return [Obs()]
    dpgt_runs.run(3, "forward", overrides, window=window, extra=extra)
    r = np.array(rec)
    return r[:, 0], r[:, 1], r[:, 2:]


def test_pin_spall_and_an_oversize_roller_show_their_signatures():
    """A 20 µm deep, 2 mm spall on b1's pin in its load zone: the pin's load history gains the roller-pass
    frequency over the pin, Z·f_cage,rel (1711 Hz at condition 3) — > 20× the perfect machine's level there
    — and dips by the spall depth's share of the rollers' load. One roller of a1's bearing 5 µm oversize:
    its largest raceway load exceeds every other roller's, by less than rigid raceways would give (the perfect
    bearing's rollers stay within 10 % of each other)."""
    from scenarios.fault_study import characteristic_frequencies

    f_pass = characteristic_frequencies(reference_dpgt(3).si())["outer_roller_pass_pin"]
    damaged = {"errors.spall": [{"planet": "b1", "raceway": "inner", "position": "180 deg", "width": "2 mm",
                                 "depth": "20 um", "edge": "0.5 mm"}],
               "errors.roller_diameter": [{"planet": "a1", "roller": 0, "deviation": "5 um"}]}
    t0, F0, Q0 = _bearing_history({})
    t1, F1, Q1 = _bearing_history(damaged)
    a0, a1 = _line(t0, F0, f_pass), _line(t1, F1, f_pass)
    assert a1 > 20 * a0
    assert F1.min() < F0.min() - 1000.0                          # a roller over the spall gives way
    m0, m1 = Q0.max(axis=0), Q1.max(axis=0)
    assert np.ptp(m0) < 0.1 * m0.max()                           # perfect: the rollers alike
    # the oversize roller carries the most, but less than if its 2.5 µm extra interference per contact
    # were taken by rigid raceways with no relief from the others: ((δ + ΔD/2)/δ)^p (seen: 1.10 vs 1.20)
    b = reference_dpgt(3).si().bearing
    delta = (m1[1:].max() / b.contact_stiffness) ** (1.0 / b.contact_exponent)
    assert 1.0 < m1[0] / m1[1:].max() < ((delta + 2.5e-6) / delta) ** b.contact_exponent


EVERY_ERROR = {
    "errors.pinhole": [{"planet": "b2", "radial": "5 um", "tangential": "-10 um"}],
    "errors.runout": [{"gear": "sun", "eccentricity": "12 um", "phase": "30 deg"},
                      {"gear": "b1", "eccentricity": "8 um", "phase": "200 deg"}],
    "errors.roller_diameter": [{"planet": "a1", "roller": 3, "deviation": "-3 um"}],
    "errors.spall": [{"planet": "b1", "raceway": "inner", "position": "180 deg", "width": "2 mm", "depth": "20 um",
                      "edge": "0.5 mm"},
                     {"planet": "a2", "raceway": "outer", "position": "90 deg", "width": "1 mm", "depth": "10 um",
                      "edge": "0.2 mm"}],
    "errors.tooth_fault": [{"gear": "sun", "tooth": 4, "stiffness_factor": 0.3},
                           {"gear": "ring", "tooth": 40, "stiffness_factor": 0.0}],
}


def test_a_machine_with_every_error_runs_compiled_and_matches_the_reference():
    """Every error at once (mixed damaged and healthy instances in every family): the compiled engine runs it
    (no fallback) and its assembled forces and Jacobians equal the numpy reference's at a loaded state."""
    from mbd.compiled.system import CompiledSystem

    sc = _build(with_overrides(reference_dpgt(3), EVERY_ERROR))
    res = mbd.simulate(sc.model, sc.q0, sc.v0, 0.002, stepper=mbd.PRODUCTION.stepper(),
                       controller=mbd.PRODUCTION.controller(), progress=False, engine="compiled")
    assert res.engine == "compiled"
    s = res.state
    system = mbd.System(sc.model)
    ref = system.evaluate(s.t, s.q, s.v, s.z, jac=True)
    got = CompiledSystem(system).evaluate(s.t, s.q, s.v, s.z, jac=True)
    for name in ("F", "Jq", "Jv"):
        a, b = getattr(got, name), getattr(ref, name)
        assert np.abs(a - b).max() <= 1e-10 * np.abs(b).max(), name
