"""The quasi-static solution at idle (docs/model.md §16, "Gears floating in their backlash"): at 1500 r/min and no
power the sun transmits no torque and only the drag torques of the bearings and the oil load the meshes, a few
newtons; the gears start in the middle of their backlash and the static state has the planets' flanks closed on the
loss torque path. Held to a closed form (the pin carries the planet's centrifugal force) and to a dynamic run's
means (tests/components/test_load_path.py shows the same at conditions 3 and 4)."""
from __future__ import annotations

import numpy as np
import pytest

from components.outputs import MESH_FAMILY
from components.params import with_overrides
from components.presets import reference_dpgt
from components.static import static_statistics

from tests.support.dpgt_runs import assert_static_is_dynamic_mean, build, carrier_revolution, run

IDLE = {"operating.carrier_speed": "1500 rpm", "operating.output_power": "0 kW"}


def _idle(direction):
    return with_overrides(reference_dpgt(4, direction), IDLE)


def _centrifugal(si):
    """Per bearing (bearing-map order: pair by pair, inner then outer): m Ω² r of the planet, its rollers and its
    cage at the pin's radius r — the load a pin carries where nothing else pushes the planet."""
    b, lay, g = si.bearing, si.layout, si.gears
    carried = b.rollers * b.rows * b.roller_mass + b.cage.mass
    W = si.operating.carrier_speed
    out = []
    for n in range(si.gears.planets):
        for planet, c in ((g.inner_planet, lay.centres_a[n]), (g.outer_planet, lay.centres_b[n])):
            out.append((planet.mass + carried) * W ** 2 * float(np.hypot(*c)))
    return np.array(out)


@pytest.mark.parametrize("rpm, direction", [(1500, "forward"), (1500, "reverse"), (1000, "forward"), (500, "reverse")])
def test_at_idle_the_pins_carry_the_planets_centrifugal_force(rpm, direction):
    """The static state exists at no power and every pin's mean reaction is m Ω² r radially (planet 0.557 kg, its
    rollers and cage 0.077 kg, at 82.5 and 87 mm: 1291.5 and 1361.9 N at 1500 r/min, 574.0 and 605.3 N at 1000,
    143.5 and 151.3 N at 500) within 1 % and tangentially below 1 % of it. What else pushes a planet is the mesh
    forces of the loss torque path — the coast flanks of the inner–outer and outer–ring meshes carry 3.6 and 7.5 N
    at 1500 r/min, 0.4 and 0.8 N at 500 (measured), under 0.6 % of the pin load — and gravity, whose mean over the
    carrier revolution the snapshots span is nil (measured: radial within 0.37 %, tangential ≤ 9.8 N). The roller and
    cage mass left out would miss by 12 %, Ω in r/s or 2Ω by far more. The planets' flanks are closed where the loss
    torque passes (inner–outer and outer–ring coast flanks carry a force; at the start, in the middle of their
    backlash, they carried none, and the solver stalled there), the drive flanks open (the sun transmits nothing)."""
    p = with_overrides(reference_dpgt(4, direction), {**IDLE, "operating.carrier_speed": f"{rpm} rpm"})
    st, sols = static_statistics(build(p), 16)
    F = _centrifugal(p.si())
    radial, tangential = st.stats("load_radial")["mean"], st.stats("load_tangential")["mean"]
    np.testing.assert_allclose(radial, F, rtol=0.01)
    np.testing.assert_array_less(np.abs(tangential), 0.01 * F)
    for key in ("inner_outer", "outer_ring"):
        assert st.stats(f"{key}_coast_force")["mean"].min() > 1e-3 * F.max(), key
    for key in MESH_FAMILY:
        assert st.stats(f"{key}_drive_force")["mean"].max() < 1e-3, key


@pytest.mark.parametrize("direction", ["forward", "reverse"])
def test_at_idle_the_static_state_is_the_dynamic_runs_mean(direction):
    """16 static snapshots against a dynamic run's means over one carrier revolution after 8 ms (as at conditions 3
    and 4, tests/components/test_load_path.py): every pin's mean reaction as a vector within 1 % of its magnitude
    (measured 0.38 % forward, 0.30 % reverse), the bearings' mean roller loads on pin and bore within 1 % (measured
    ≤ 0.57 %), the planets' speeds relative to the carrier within 3e-4 (measured 1e-5) and the cages' within 1.2 %
    (measured 0.71–0.76 %, the static cages faster as at conditions 3 and 4). The meshes' coast flanks carry the loss
    torque in both, the static ones less (3.6 against 5.2–5.5 N inner–outer, 7.5 against 10.6–11.2 N outer–ring: the
    static state has no pocket contacts and its cage rides centred, so the bearings' drag on the planets is smaller,
    docs/model.md §16), asserted between half and all of the dynamic means."""
    p = _idle(direction)
    bs, dyn, _, _ = run(4, direction, IDLE, window=carrier_revolution(p))
    st, _ = static_statistics(bs, 16)
    assert_static_is_dynamic_mean(st, dyn, roller_rtol=0.01)
    for key in ("inner_outer", "outer_ring"):
        d, s = dyn.stats(f"{key}_coast_force")["mean"], st.stats(f"{key}_coast_force")["mean"]
        assert np.all(s > 0.5 * d) and np.all(s < d), (key, d, s)


def test_the_walk_is_tried_only_where_nothing_else_solves(monkeypatch):
    """Condition 4 forward has an instant that only a move of a few percent of a mesh period solves without the walk,
    and the walk would solve unmoved: tried last, it leaves that instant, and every state of the instants before it,
    as the solver without a walk finds them (bit for bit)."""
    import components.static as cs
    from components.dpgt import build_dpgt

    scene = build_dpgt(reference_dpgt(4, "forward"))
    _, sols = static_statistics(scene, 16)
    real = cs.solve_static
    monkeypatch.setattr(cs, "solve_static", lambda *a, **k: real(*a, **{**k, "walk": False}))
    _, without = static_statistics(scene, 16)
    assert [s.t for s in sols] == [s.t for s in without]
    assert all(np.array_equal(s.q, w.q) for s, w in zip(sols, without))
