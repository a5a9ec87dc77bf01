"""Family fusion in the assembler: same forces, Jacobians and per-family outputs as separate families."""
import warnings

import numpy as np

import mbd


def test_fused_families_match_separate_evaluation():
    from components.dpgt import build_dpgt
    from components.params import with_overrides
    from components.presets import reference_dpgt

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        sc = build_dpgt(with_overrides(reference_dpgt(3, "reverse"), {"bearing.rollers": 8}))
    r = mbd.simulate(sc.model, sc.q0, sc.v0, 0.0008, controller=mbd.FixedStep(4e-6), progress=False)
    s = r.state
    sep, fus = mbd.System(sc.model, fuse=False), mbd.System(sc.model, fuse=True)
    fused = [[n for n, _ in parts] for _, parts in fus._evals if len(parts) > 1]
    assert ["race_inner", "race_outer"] in fused and ["mesh_sa", "mesh_ab", "mesh_br"] in fused
    ea, eb = sep.evaluate(s.t, s.q, s.v, s.z, jac=True), fus.evaluate(s.t, s.q, s.v, s.z, jac=True)
    Fa, Fb = ea.F, eb.F
    np.testing.assert_allclose(Fb, Fa, rtol=0, atol=1e-12 * np.abs(Fa).max())
    Ma = sep.newton_matrix(ea, 1.0, 2e-6, 3e-12).toarray()
    Mb = fus.newton_matrix(eb, 1.0, 2e-6, 3e-12).toarray()
    np.testing.assert_allclose(Mb, Ma, rtol=0, atol=1e-12 * np.abs(Ma).max())
    oa, ob = sep.outputs(s.t, s.q, s.v, s.z), fus.outputs(s.t, s.q, s.v, s.z)
    assert sorted(oa) == sorted(ob)
    for fam in oa:
        assert sorted(oa[fam]) == sorted(ob[fam])
        for key in oa[fam]:
            np.testing.assert_allclose(ob[fam][key], oa[fam][key], rtol=1e-12, atol=1e-9, err_msg=f"{fam}.{key}")
