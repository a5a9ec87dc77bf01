"""What every planet-bearing contact family shares (docs/model.md §8): objectivity (the same forces in any rotating
and translating frame), parameter errors that name the parameter (and no defaults for physics values), and
multiplicity — identical parallel contacts (a double-row bearing as one row) scale forces and Jacobians, keep the
outputs per physical contact, and survive the fusion of inner and outer raceways.
"""
from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings, strategies as st

from mbd.element import evaluate
from mbd.elements.contact import DryLand, ExactRestitution, GuideContact, LubricantDrag, PocketContact, RaceContact
from mbd.errors import ModelError

from tests.support.contact import (C_G, C_P, DM, DR, EHL, FS, K_G, K_HZ, K_P, LAW, LR, M_ROLLER, N, R_IN, R_LAND, R_OUT,
                                   SETTINGS, V_MIN, assert_balanced, assert_jacobians, assert_objective, drag_scene,
                                   drag_states, floats, guide_scene, guide_states, pocket_scene, pocket_states,
                                   race_element, race_scene, race_states, stored_speeds)


@pytest.mark.parametrize("elem_kind", ["race_inner", "race_outer", "pocket", "guide", "drag"])
@settings(max_examples=15, deadline=None)
@given(data=st.data(), alpha=floats(-np.pi, np.pi), w=floats(-300.0, 300.0),
       u=st.tuples(floats(-5.0, 5.0), floats(-5.0, 5.0)))
def test_objectivity(elem_kind, data, alpha, w, u):
    """Same physics in any rotating/translating frame: forces only depend on relative motion."""
    if elem_kind.startswith("race"):
        kind = elem_kind[5:]
        qf, vf, mk, R = race_scene(kind, *data.draw(race_states(kind)))
        elem = race_element(kind, N, mk, R, EHL)
    elif elem_kind == "pocket":
        qf, vf, elem, _ = pocket_scene(*data.draw(pocket_states()))
    elif elem_kind == "guide":
        qf, vf, elem = guide_scene(*data.draw(guide_states()))
    else:
        qf, vf, elem, _ = drag_scene(*data.draw(drag_states()))
    z = data.draw(stored_speeds()) if elem_kind in ("pocket", "guide") else None
    assert_objective(elem, qf, vf, alpha, w, u, z)


def test_parameter_errors_name_the_parameter():
    with pytest.raises(ModelError, match="kind"):
        RaceContact("r", [1], 0, kind="middle", race_marker=(0, 0), R_race=R_IN, D=DR, K=K_HZ, m_roller=M_ROLLER, **LAW)
    with pytest.raises(ModelError, match="race_marker"):
        RaceContact("r", [1, 2], 0, kind="inner", race_marker=np.zeros((3, 2)), R_race=R_IN, D=DR, K=K_HZ,
                    m_roller=M_ROLLER, **LAW)
    with pytest.raises(ModelError, match="'K'"):
        RaceContact("r", [1], 0, kind="inner", race_marker=(0, 0), R_race=R_IN, D=DR, K=-1.0, m_roller=M_ROLLER, **LAW)
    pocket = dict(pocket_angle=0.0, pitch_radius=DM / 2, clearance=C_P, K_p=K_P, restitution=0.8, v_min=V_MIN,
                  mu=0.1, v_mu=0.05, D=DR, impact_law=ExactRestitution())
    guide = dict(clearance=C_G, K_g=K_G, restitution=0.8, v_min=V_MIN, mu=0.1, v_mu=0.05, land_radius=R_LAND,
                 impact_law=ExactRestitution(), land=DryLand())
    PocketContact("p", [1], 0, **pocket)
    GuideContact("g", [1], 0, **guide)
    for e in (1.5, 0.0, -0.2):     # e = 0 (perfectly plastic) would need infinite damping
        with pytest.raises(ModelError, match="restitution"):
            PocketContact("p", [1], 0, **{**pocket, "restitution": e})
        with pytest.raises(ModelError, match="restitution"):
            GuideContact("g", [1], 0, **{**guide, "restitution": e})
    with pytest.raises(ModelError, match="v_min"):
        PocketContact("p", [1], 0, **{**pocket, "v_min": 0.0})
    with pytest.raises(ModelError, match="v_min"):
        GuideContact("g", [1], 0, **{**guide, "v_min": -1.0})
    with pytest.raises(ModelError, match="clearance"):
        GuideContact("g", [1], 0, **{**guide, "clearance": -1e-4})
    with pytest.raises(ModelError, match="impact_law.*exact"):
        PocketContact("p", [1], 0, **{**pocket, "impact_law": "exact"})
    # physics values have no defaults: leaving one out is an error
    for key in ("restitution", "impact_law", "v_min", "mu", "v_mu"):
        with pytest.raises(TypeError, match=key):
            PocketContact("p", [1], 0, **{k: v for k, v in pocket.items() if k != key})
        with pytest.raises(TypeError, match=key):
            GuideContact("g", [1], 0, **{k: v for k, v in guide.items() if k != key})
    with pytest.raises(ModelError, match="d_m"):
        LubricantDrag("d", [1], 0, race_marker=(0, 0), C_d=1.0, rho=45.0, D=DR, l=LR, d_m=0.0)
    for m in (0, 1.5, -2, [1, 0.5]):
        with pytest.raises(ModelError, match="multiplicity"):
            RaceContact("r", [1, 2], 0, kind="inner", race_marker=(0, 0), R_race=R_IN, D=DR, K=K_HZ,
                        m_roller=M_ROLLER, **LAW, multiplicity=m)
        with pytest.raises(ModelError, match="multiplicity"):
            PocketContact("p", [1, 2], 0, **pocket, multiplicity=m)
        with pytest.raises(ModelError, match="multiplicity"):
            LubricantDrag("d", [1, 2], 0, race_marker=(0, 0), C_d=1.0, rho=45.0, D=DR, l=LR, d_m=DM, multiplicity=m)


# multiplicity: identical parallel contacts (a double-row bearing as one row)
def _assert_multiplied(e1, e2, qf, vf, mult, z=None):
    F1, o1, Jq1, Jv1 = evaluate(e1, 0.0, FS, qf, vf, z, True)
    F2, o2, Jq2, Jv2 = evaluate(e2, 0.0, FS, qf, vf, z, True)
    m = np.asarray(mult, float)[:, None]
    np.testing.assert_array_equal(F2, m * F1)
    np.testing.assert_array_equal(Jq2, m[:, :, None] * Jq1)
    np.testing.assert_array_equal(Jv2, m[:, :, None] * Jv1)
    assert o1.keys() == o2.keys()
    for key in o1:                                     # outputs are per physical contact
        np.testing.assert_array_equal(o2[key], o1[key])
    F2_plain = evaluate(e2, 0.0, FS, qf, vf, z, False)[0]          # the value path scales the same way
    np.testing.assert_allclose(F2_plain, F2, rtol=1e-12, atol=1e-12 * np.abs(F2).max())
    assert_jacobians(e2, qf, vf, z=z)
    assert_balanced(e2, qf, vf, z)


MULTS = st.lists(st.integers(1, 3), min_size=N, max_size=N)


@pytest.mark.parametrize("kind", ["inner", "outer"])
@SETTINGS
@given(data=st.data(), mult=MULTS)
def test_race_multiplicity(kind, data, mult):
    qf, vf, mk, R = race_scene(kind, *data.draw(race_states(kind)))
    for m in (2, mult):
        mm = np.broadcast_to(m, (N,))
        _assert_multiplied(race_element(kind, N, mk, R), race_element(kind, N, mk, R, multiplicity=m), qf, vf, mm)


def test_race_multiplicity_survives_fusion():
    """Inner and outer families fuse into one; each keeps its multiplicity."""
    qf, vf, mk, R = race_scene("inner", (1e-4, -2e-4, 0.8), (0.1, 0.2, 30.0), -0.4, [0.1, 1.2, 2.5, -2.0],
                               [1e-6, 5e-6, -1e-6, 2e-5], [0.01, -0.02, 0, 0.1], [1, 2, 3, 4], [0.1, -0.2, 0.3, 0])
    a = race_element("inner", N, mk, R, multiplicity=[2, 1, 3, 2])
    b = RaceContact("race_o", np.arange(1, N + 1), 0, kind="outer", race_marker=(0, 0), R_race=R_OUT, D=DR, K=K_HZ,
                    m_roller=M_ROLLER, **LAW, multiplicity=2)
    b1 = RaceContact("race_o1", np.arange(1, N + 1), 0, kind="outer", race_marker=(0, 0), R_race=R_OUT, D=DR,
                     K=K_HZ, m_roller=M_ROLLER, **LAW)
    assert a.fuse_key() == b.fuse_key()
    f = RaceContact.fuse([a, b])
    np.testing.assert_array_equal(f.multiplicity, [2, 1, 3, 2, 2, 2, 2, 2])
    Ff, of, Jqf, Jvf = evaluate(f, 0.0, FS, qf, vf, None, True)
    # (to round-off: numpy's vectorised transcendental functions may differ by an ulp with the array length)
    close = lambda x, y: np.testing.assert_allclose(x, y, rtol=1e-13, atol=1e-13 * np.abs(y).max())  # noqa: E731
    for part, sl in ((a, slice(0, N)), (b, slice(N, 2 * N))):
        Fp, op, Jqp, Jvp = evaluate(part, 0.0, FS, qf, vf, None, True)
        close(Ff[sl], Fp)
        close(Jqf[sl], Jqp)
        for key in op:
            close(of[key][sl], op[key])
    Fb1, _, _, _ = evaluate(b1, 0.0, FS, qf, vf, None, False)
    close(Ff[N:], 2 * Fb1)
    # a fused family of multiplicity-1 members skips the scaling and gives the same forces
    g = RaceContact.fuse([race_element("inner", N, mk, R), b1])
    assert not g._multi


@SETTINGS
@given(state=pocket_states(), z=stored_speeds(), mult=MULTS)
def test_pocket_multiplicity(state, z, mult):
    qf, vf, e1, _ = pocket_scene(*state)
    for m in (2, mult):
        _, _, e2, _ = pocket_scene(*state, multiplicity=m)
        for zz in (None, z):
            _assert_multiplied(e1, e2, qf, vf, np.broadcast_to(m, (N,)), zz)


@SETTINGS
@given(state=drag_states(), mult=MULTS)
def test_drag_multiplicity(state, mult):
    qf, vf, e1, _ = drag_scene(*state)
    for m in (2, mult):
        _, _, e2, _ = drag_scene(*state, multiplicity=m)
        _assert_multiplied(e1, e2, qf, vf, np.broadcast_to(m, (N,)))
