"""Timing of the compiled contact kernels against the reference (mbd.element.evaluate), one family call each:
72 race contacts (36 inner + 36 outer, fused) and 144 (72 + 72), 72 pockets, 6 guides, 72 drags, on random
states of the test scenes (about half the contacts closed). Median of interleaved repeats.

    python -m tests.support.bench_compiled_contact [--repeats 300]     (from the repository's root)

"compiled" includes gathering the local coordinates q_full[dofs] (as evaluate does); outputs preallocated.
"""
from __future__ import annotations

import argparse
import statistics
import time

import numpy as np

from mbd.compiled.registry import kind_of
from mbd.element import evaluate
from mbd.elements.contact import RaceContact
from mbd.model import FrameState

from tests.support.contact import C_G, C_P, EHL, drag_scene, guide_scene, pocket_scene, race_element, race_scene

FS = FrameState(0.3, 40.0, 0.0)


def race_family(n, rng):
    parts, qs, vs, off = [], [], [], 0
    for kind in ("inner", "outer"):
        m = n // 2
        pose = (1e-4, -2e-4, 0.3) if kind == "inner" else (0.0825, 0.0, 0.0)
        deltas = np.where(rng.random(m) < 0.5, rng.uniform(2e-6, 3e-5, m), -rng.uniform(2e-6, 1e-4, m))
        qf, vf, mk, R = race_scene(kind, pose, (0.1, -0.2, 30.0), 0.4, rng.uniform(-np.pi, np.pi, m), deltas,
                                   rng.uniform(-0.3, 0.3, m), rng.uniform(-5, 5, m), rng.uniform(-2, 2, m))
        e = race_element(kind, m, mk, R, EHL)
        e.dofs = e.dofs + 3 * off
        parts.append(e)
        qs.append(qf)
        vs.append(vf)
        off += m + 1
    return RaceContact.fuse(parts), np.concatenate(qs), np.concatenate(vs), None


def pockets(n, rng):
    off = np.where(rng.random(n) < 0.5, rng.uniform(0, C_P, n), C_P + rng.uniform(1e-6, 5e-5, n))
    qf, vf, e, _ = pocket_scene((0.08, 0.02, 0.3), (1.0, -2.0, 200.0), rng.integers(0, 12, n),
                                off * rng.choice([-1, 1], n), rng.uniform(-2e-4, 2e-4, n), rng.uniform(-0.05, 0.05, n),
                                rng.uniform(-0.5, 0.5, n), rng.uniform(-3000, 3000, n))
    z = np.zeros((n, 4))
    z[:, 0] = np.where(rng.random(n) < 0.5, 0.0, rng.uniform(0.02, 3.0, n))
    return e, qf, vf, z


def guides(n, rng):
    ecc = np.where(rng.random(n) < 0.5, rng.uniform(0, C_G, n), C_G + rng.uniform(1e-6, 5e-5, n))
    qf, vf, e = guide_scene((0.07, -0.04, 0.2), (1.0, 2.0, 1000.0), ecc, rng.uniform(-np.pi, np.pi, n),
                            rng.uniform(-0.05, 0.05, n), rng.uniform(-1, 1, n), rng.uniform(-500, 500, n))
    return e, qf, vf, np.zeros((n, 4))


def drags(n, rng):
    qf, vf, e, _ = drag_scene((0, 0, 0.2), (1.0, -2.0, 440.0), 0.3, rng.uniform(-np.pi, np.pi, n),
                              rng.uniform(-5e-5, 5e-5, n), 440.0 + rng.uniform(-800, 800, n), rng.uniform(-0.1, 0.1, n),
                              rng.uniform(-3000, 3000, n))
    return e, qf, vf, None


def bench(label, elem, qf, vf, z, repeats):
    twin = kind_of(type(elem))
    pack, kernel = twin.pack, twin.evaluate
    P, G = pack(elem)
    n, k = elem.dofs.shape
    F, Jq, Jv = np.empty((n, k)), np.empty((n, k, k)), np.empty((n, k, k))
    zz = np.zeros((n, 0)) if z is None else z

    def comp(jac):
        kernel(0.0, FS.phi, FS.omega, FS.domega, qf[elem.dofs], vf[elem.dofs], zz, P, G, F, Jq, Jv, jac)

    def ref(jac):
        evaluate(elem, 0.0, FS, qf, vf, z, jac)

    comp(True), comp(False)                    # compile / load the cache
    times = {key: [] for key in ("ref", "comp", "ref_jac", "comp_jac")}
    for _ in range(repeats):                  # interleaved
        for key, f, jac in (("ref", ref, False), ("comp", comp, False), ("ref_jac", ref, True), ("comp_jac", comp, True)):
            t0 = time.perf_counter()
            f(jac)
            times[key].append(time.perf_counter() - t0)
    med = {key: statistics.median(v) * 1e6 for key, v in times.items()}
    print(f"{label:<24}{n:>5}  {med['ref']:>9.1f} {med['comp']:>8.1f} {med['ref'] / med['comp']:>6.0f}x"
          f"  {med['ref_jac']:>9.1f} {med['comp_jac']:>8.1f} {med['ref_jac'] / med['comp_jac']:>6.0f}x")


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--repeats", type=int, default=300)
    args = ap.parse_args()
    rng = np.random.default_rng(1)
    print(f"{'family':<24}{'n':>5}  {'ref µs':>9} {'comp µs':>8} {'':>7}  {'ref+J µs':>9} {'comp+J':>8}")
    for label, make, n in (("race (inner+outer)", race_family, 72), ("race (inner+outer)", race_family, 144),
                           ("pocket", pockets, 72), ("guide", guides, 6), ("drag", drags, 72)):
        bench(label, *make(n, rng), args.repeats)


if __name__ == "__main__":
    main()
