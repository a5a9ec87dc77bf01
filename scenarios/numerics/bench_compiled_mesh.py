"""The compiled GearMesh kernel (mbd.compiled.mesh) against mbd.element.evaluate on the DPGT's meshes:
3 sun–inner, 3 inner–outer, 3 outer–ring, rectangular stiffness; as the three families and as the
one fused family the System evaluates. Median of interleaved repeats, with and without Jacobians.
Then the cost of real teeth: the fused family of the perfect machine (the rectangular law) against the
same machine with ISO 1328-1 class-6 teeth (the tooth-pair law), compiled, interleaved.

    python -m scenarios.bench_compiled_mesh [--condition 3] [--repeats 31]

The state is the built nominal one with every gear turned by a few mrad (so that flanks carry load).
The compiled call includes the gather q[dofs], v[dofs] (as evaluate does); its output arrays are
allocated once, as an assembler would. Prints one line per case and the largest relative difference.
"""
from __future__ import annotations

import argparse
import statistics
import time
import warnings

import numpy as np
from numba import njit

from components.dpgt import build_dpgt
from components.params import with_overrides
from components.presets import reference_dpgt
from mbd.compiled.mesh import evaluate_gear_mesh, pack_gear_mesh
from mbd.element import evaluate
from mbd.elements import GearMesh


def _per_call(fn, inner):
    t = time.perf_counter()
    for _ in range(inner):
        fn()
    return (time.perf_counter() - t) / inner


def main(argv=None) -> int:
    p = argparse.ArgumentParser(prog="python -m scenarios.bench_compiled_mesh", description=__doc__.split("\n\n")[0])
    p.add_argument("--condition", type=int, default=3, choices=(1, 2, 3, 4))
    p.add_argument("--repeats", type=int, default=31)
    a = p.parse_args(argv)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        bs = build_dpgt(reference_dpgt(a.condition, "forward"))
    m = bs.model
    q, v = (x.copy() for x in m.full(0.0, bs.q0, bs.v0))
    fs = m.frame.at(0.0)
    meshes = [e for e in m.elements if isinstance(e, GearMesh)]
    rng = np.random.default_rng(0)
    for e in meshes:
        q[e.dofs[:, 2]] += rng.normal(0.0, 3e-3, e.n)

    def compiled_call(e, P, G, out, jac):
        F, Jq, Jv, z = out
        evaluate_gear_mesh(0.0, fs.phi, fs.omega, fs.domega, q[e.dofs], v[e.dofs], z, P, G, F, Jq, Jv, jac)

    for label, fams in (("3 families", meshes), ("fused (9)", [GearMesh.fuse(meshes)])):
        packed = [(e, *pack_gear_mesh(e), (np.empty((e.n, 6)), np.empty((e.n, 6, 6)), np.empty((e.n, 6, 6)),
                                             np.zeros((e.n, 0)))) for e in fams]
        for jac in (False, True):
            def ref():
                return [evaluate(e, 0.0, fs, q, v, None, jac) for e in fams]

            def comp():
                return [compiled_call(e, P, G, out, jac) for e, P, G, out in packed]
            ref(), comp()                       # compile / warm up
            tr, tc = [], []
            for _ in range(a.repeats):          # interleaved: a busy machine slows both alike
                tr.append(_per_call(ref, 50))
                tc.append(_per_call(comp, 500))
            mr, mc = statistics.median(tr), statistics.median(tc)
            print(f"{label:10s} jac={jac!s:5s}  reference {mr * 1e6:7.1f} µs   compiled {mc * 1e6:5.2f} µs   "
                  f"({mr / mc:.0f}x)")
        worst, loaded = 0.0, 0
        for e, P, G, out in packed:
            F, o, Jq, Jv = evaluate(e, 0.0, fs, q, v, None, True)
            compiled_call(e, P, G, out, True)
            loaded += int(np.sum(o["force_drive"] > 0) + np.sum(o["force_coast"] > 0))
            worst = max([worst] + [np.abs(A - B).max() / np.abs(B).max() for A, B in zip(out[:3], (F, Jq, Jv))])
        print(f"{label:10s} loaded flanks {loaded} of 18, largest relative difference {worst:.1e}")
    _teeth_cost(a, q, v, fs)
    return 0


def _teeth_cost(a, q, v, fs):
    """Compiled cost per evaluation of the DPGT's fused mesh family: rectangular law vs tooth-pair law."""
    grade = with_overrides(reference_dpgt(a.condition, "forward"), {"errors.flank_class": [
        {"gear": "all", "grade": 6, "seed": 1, "systematic_share": 0.5}]})
    fams = {}
    for label, params in (("perfect teeth (rectangular law)", reference_dpgt(a.condition, "forward")),
                          ("class-6 teeth (tooth-pair law)", grade)):
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            e = GearMesh.fuse([x for x in build_dpgt(params).model.elements if isinstance(x, GearMesh)])
        fams[label] = (q[e.dofs], v[e.dofs], *pack_gear_mesh(e),
                       (np.empty((e.n, 6)), np.empty((e.n, 6, 6)), np.empty((e.n, 6, 6)), np.zeros((e.n, 0))))

    @njit
    def loop(n, phi, omega, ql, vl, z, P, G, F, Jq, Jv, jac):   # as the compiled assembly calls it (no dispatch)
        for _ in range(n):
            evaluate_gear_mesh(0.0, phi, omega, 0.0, ql, vl, z, P, G, F, Jq, Jv, jac)

    inner = 2000
    for jac in (False, True):
        times = {k: [] for k in fams}
        for k, (ql, vl, P, G, (F, Jq, Jv, z)) in fams.items():
            loop(1, fs.phi, fs.omega, ql, vl, z, P, G, F, Jq, Jv, jac)      # compile
        for _ in range(a.repeats):              # interleaved; the kernel alone (its inputs gathered before)
            for k, (ql, vl, P, G, (F, Jq, Jv, z)) in fams.items():
                t0 = time.perf_counter()
                loop(inner, fs.phi, fs.omega, ql, vl, z, P, G, F, Jq, Jv, jac)
                times[k].append((time.perf_counter() - t0) / inner)
        med = {k: statistics.median(t) for k, t in times.items()}
        base = next(iter(med.values()))
        print("fused (9) jac=" + f"{jac!s:5s} " + "   ".join(f"{k} {m * 1e6:5.2f} µs ({m / base:.2f}x)"
                                                              for k, m in med.items()))


if __name__ == "__main__":
    raise SystemExit(main())
