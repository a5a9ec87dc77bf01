"""The element outputs of K states at once through the compiled kernels: the twin of
:meth:`mbd.System.outputs_batch` for the families whose compiled twin gives its outputs
(:data:`.registry.OUTPUT_NAMES`: the roller–race, pocket and guide-land contacts, the sliced roller–race contact),
the numpy kernels' (``System.outputs_batch``) for the others. An output is written by the compiled force law where it
computes that value for the residual (the sliced race's by the law of its evaluate kernel without the Jacobian:
:func:`.sliced.outputs_sliced_race`); ``System.outputs_batch`` stays the reference the tests hold this to
(tests/mbd/test_compiled_outputs.py, tests/mbd/test_compiled_sliced.py)."""
from __future__ import annotations

import numpy as np
from numba import literally, njit

from ..assembly import System
from .registry import call, groups_to_compile, kind_of, output_names, outputs_for
from .. import compiled as _compiled     # kernels_cached, compile_announced: read through the package when called

__all__ = ["CompiledOutputs", "family_outputs"]


@njit(cache=True)
def family_outputs(groups, kind, t, phi, omega, domega, qf, vf, dofs, P, G, Z, O):
    """One family's outputs at K states into O (n_outputs, n, K): ``qf``, ``vf`` (K, n_full) the full
    coordinates, ``phi``, ``omega``, ``domega`` (K,) the frame's state, ``Z`` (K, n, n_z) the internal states;
    ``groups`` (a literal) the family groups compiled (:func:`.registry.groups_of`)."""
    literally(groups)
    n, k = dofs.shape
    ql, vl = np.empty((n, k)), np.empty((n, k))
    # the kernels write a C-contiguous (n_outputs, n) buffer: O[:, :, s] (layout 'A') would compile them once more
    Os = np.empty((O.shape[0], n))
    for s in range(t.size):
        for i in range(n):
            for j in range(k):
                ql[i, j] = qf[s, dofs[i, j]]
                vl[i, j] = vf[s, dofs[i, j]]
        outputs_for(groups, kind, t[s], phi[s], omega[s], domega[s], ql, vl, Z[s], P, G, Os)
        for r in range(O.shape[0]):       # element-wise: a slice assignment from an array compiles numba's
            for i in range(n):            # shape-mismatch message (seconds of the first compile)
                O[r, i, s] = Os[r, i]


class CompiledOutputs:
    """``outputs_batch(t, q, v, z, families=None)`` as :meth:`mbd.System.outputs_batch` gives it (arrays (K, n)
    per family and output), the compiled families' outputs from their kernels: the names of
    :func:`.registry.output_names`, the reference's but the races' "angle" (not a by-product of the force law:
    an arctan2 per contact that the statistics do not read; the recorder's probes take the numpy kernels').
    :attr:`engines` says which path evaluates each family ("compiled" / "numpy")."""

    def __init__(self, system: System):
        self.system, self.model = system, system.model
        self._compiled, self.engines = [], {}
        self.groups = 0        # the kernel groups of the compiled families (registry.GROUPS): compiled for these only
        for e, parts in system._evals:
            names = output_names(e)
            packed = None
            if names is not None:
                try:
                    packed = kind_of(type(e)).pack(e)
                except NotImplementedError:     # a law variant without a compiled kernel: its outputs from numpy
                    packed = None
            for name, _ in parts:
                self.engines[name] = "numpy" if packed is None else "compiled"
            if packed is not None:
                z0 = e.init_internal()          # a family with internal state is never fused: parts[0] is it
                state = (parts[0][0], int(np.size(z0)) // e.n) if z0 is not None else (None, 0)
                self.groups |= kind_of(type(e)).group
                self._compiled.append((parts, kind_of(type(e)).id, np.ascontiguousarray(e.dofs, dtype=np.int64),
                                       *packed, names, state))
        self.groups = groups_to_compile(self.groups, _compiled.cached_groups("outputs.family_outputs"))
        self._compile()

    def _compile(self) -> None:
        """Compile (or load) the kernels now, on an empty block: a run that must compile them says so before its
        first step, as the engine does (:class:`.runner.CompiledRunner`)."""

        if not self._compiled:
            return
        empty = np.zeros((0, self.model.ndof))
        _compiled.compile_announced(
            lambda: self.outputs_batch(np.zeros(0), empty, empty, {},
                                       families={name for rec in self._compiled for name, _ in rec[0]}),
            cold=not _compiled.kernels_cached("outputs.family_outputs", self.groups), what="the element output kernels",
            done="output kernels", about="a few seconds of CPU")

    def outputs_batch(self, t, q, v, z, families=None, full=None) -> dict[str, dict[str, np.ndarray]]:
        """Every family's outputs at K states (those named in ``families``, when given), as
        :meth:`mbd.System.outputs_batch`: ``t`` (K,), ``q``, ``v`` (K, n_free), ``z`` {family: (K, ...)},
        ``full`` the full coordinates if the caller has them."""
        m = self.model
        t = np.ascontiguousarray(t, dtype=float)
        K = t.size
        wanted = lambda parts: families is None or any(name in families for name, _ in parts)
        todo = [rec for rec in self._compiled if wanted(rec[0])]
        rest = {name for name, how in self.engines.items() if how == "numpy"
                and (families is None or name in families)}
        res = {}
        if not (todo or rest):
            return res
        qf, vf = m.full_batch(t, q, v) if full is None else full
        if todo:
            fs = m.frame_batch(t)
            phi, omega, domega = (np.ascontiguousarray(np.broadcast_to(x, (K, 1))[:, 0], dtype=float)
                                  for x in (fs.phi, fs.omega, fs.domega))
        for parts, kind, dofs, P, G, names, (state, n_z) in todo:
            n = dofs.shape[0]
            # no internal state given: zeros, as the reference's kernels read a missing one (no stored approach)
            Z = (np.ascontiguousarray(np.reshape(z[state], (K, n, n_z)), dtype=float) if state in z
                 else np.zeros((K, n, n_z)))
            # instance-major, as the numpy kernels' (K, n) results lie: a fused family's slice [:, sl] is then one
            # contiguous block, and the statistics' numpy expressions over it run ≈ 1.5× faster than over strided rows
            O = np.empty((len(names), n, K))
            call(family_outputs, self.groups, kind, t, phi, omega, domega, qf, vf, dofs, P, G, Z, O)
            O = O.transpose(0, 2, 1)
            for name, sl in parts:
                res[name] = dict(zip(names, O if len(parts) == 1 else O[:, :, sl]))
        if rest:
            res.update(self.system.outputs_batch(t, q, v, z, families=rest, full=(qf, vf)))
        return res
