"""The compiled engine path as :func:`mbd.simulate` drives it: a :class:`CompiledRunner` advances blocks of
accepted steps in compiled code and hands each block back as states, so that the recorder, the
observers, checkpoints and the progress bar work unchanged."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..assembly import System
from ..control import Adaptive, FixedStep
from ..hht import HHT, StepInfo
from ..model import TILT, State
from .. import compiled as _compiled     # kernels_cached, compile_announced: read through the package when called
from .registry import call
from .sparse_lu import FixedPatternLU
from .stepper import FAIL_REASONS, advance
from .system import CompiledSystem

__all__ = ["CompiledRunner", "Block"]


@dataclass
class Block:
    """What one compiled call did: the accepted steps as arrays (``log``: per step t₁, h, error, q₁, v₁, a₁,
    f₁, internal states), the state it started from, the work (counter increments), the state and h it
    ended with, and — when the step size fell below the controller's floor — the last failed step's
    StepInfo. :attr:`steps` gives (start state, end state, h, error) per step; :meth:`arrays` the states
    stacked, start first (for observers that take a block at once)."""
    log: np.ndarray
    start: State
    z_shapes: list
    counters: dict
    state: State
    h: float
    failed: StepInfo | None = None

    def __len__(self) -> int:
        return self.log.shape[0]

    def state_at(self, i: int) -> State:
        """End state of accepted step i."""
        row, n = self.log[i], self.start.q.size
        z, off = {}, 3 + 4 * n
        for name, shape in self.z_shapes:
            size = int(np.prod(shape))
            z[name] = row[off:off + size].reshape(shape).copy()
            off += size
        return State(float(row[0]), row[3:3 + n].copy(), row[3 + n:3 + 2 * n].copy(),
                     row[3 + 2 * n:3 + 3 * n].copy(), row[3 + 3 * n:3 + 4 * n].copy(), z)

    @property
    def steps(self) -> list:
        out, s0 = [], self.start
        for i in range(len(self)):
            s1 = self.state_at(i)
            out.append((s0, s1, float(self.log[i, 1]), float(self.log[i, 2])))
            s0 = s1
        return out

    def arrays(self):
        """(t, q, v, a, z) of the start state and every step's end, stacked: t (K+1,), q, v, a (K+1, n),
        z {family: (K+1, ...)} (no copies beyond the stacking)."""
        n, s = self.start.q.size, self.start
        L = self.log
        t = np.concatenate([[s.t], L[:, 0]])
        q, v, a = (np.vstack([x[None], L[:, 3 + j * n:3 + (j + 1) * n]]) for j, x in enumerate((s.q, s.v, s.a)))
        z, off = {}, 3 + 4 * n
        for name, shape in self.z_shapes:
            size = int(np.prod(shape))
            z[name] = np.concatenate([np.asarray(s.z[name], float).reshape(1, *shape),
                                      L[:, off:off + size].reshape(-1, *shape)])
            off += size
        return t, q, v, a, z


def _controller_array(controller) -> np.ndarray:
    if isinstance(controller, FixedStep):
        return np.array([0.0, controller.h, controller.reject_error, 0, 0, 0, 0, controller.h_min])
    if isinstance(controller, Adaptive):
        c = controller
        return np.array([1.0, c.h_max, c.safety, c.grow_max, c.shrink_min, c.fail_factor, c.hold, c.h_min])
    raise NotImplementedError(f"compiled path: controller {type(controller).__name__} is not compiled "
                              "(FixedStep and Adaptive are)")


def _tilts_late(model) -> tuple[np.ndarray | None, np.ndarray | None]:
    """The sparse LU's late columns and their bodies (:class:`.sparse_lu.FixedPatternLU`): the free tilt
    coordinates (a roller's tilt), each after its body's x, y, θ; none in a model without them (SuperLU's order
    as it is)."""
    free, nb3 = model.free, model.n_body_coords
    extra = np.clip(free - nb3, 0, None)
    is_extra = free >= nb3
    kinds = model.extra_kind[extra] if model.extra_kind.size else np.zeros(free.size, np.int64)
    late = is_extra & (kinds == TILT)
    if not late.any():
        return None, None
    group = np.where(is_extra, model.extra_owner[extra] if model.extra_owner.size else 0, free // 3)
    return late, group.astype(np.int64)


class CompiledRunner:
    """HHT-α (settings of ``stepper``) with ``controller`` on the compiled twin of ``system``. Raises
    NotImplementedError naming what the compiled path cannot do (the caller then uses the numpy path).
    ``threads`` > 1: the bearings' contact families evaluated on that many threads
    (:class:`.system.CompiledSystem`; the same steps and states to the bit)."""

    def __init__(self, system: System, stepper: HHT, controller, threads: int = 1):
        if type(stepper) is not HHT:
            raise NotImplementedError(f"compiled path: stepper {type(stepper).__name__} is not compiled")
        self.ctrl = _controller_array(controller)
        self.cs = CompiledSystem(system, threads)
        m, n, nnz = system.model, system.ndof, system.nnz
        self.n = n
        beta, gamma = stepper.beta_gamma
        self.prm = np.array([stepper.alpha, beta, gamma, stepper.error_constant(), stepper.newton_tol,
                             stepper.max_iter, stepper.rate_refresh, stepper.max_refresh, float(stepper.reuse),
                             float(stepper.per_component)])
        self.atol = np.where(m.angle_dofs, stepper.tol.atol_rot, stepper.tol.atol_pos).astype(float)
        self.rtol = float(stepper.tol.rtol)
        self.freeze = bool(system.freeze_internal)
        lu = FixedPatternLU(system._indptr, system._indices, n, *_tilts_late(m))
        # the zero-pivot fallback (dense partial pivoting) needs n² floats: kept for n ≤ 1000 (8 MB); a larger
        # model whose diagonal pivot vanishes fails that step instead, and the controller shrinks h
        dense = np.zeros((n, n)) if n <= 1000 else np.zeros((0, 0))
        self.lu = (lu.arrays, dense, np.zeros(n, np.int64))
        self.pat = (lu.indptr, lu.indices, np.ascontiguousarray(system._M, float), np.asarray(m.mdiag, float))
        self.cache = np.array([0.0, np.nan, 0.0])        # LU valid, its h, sparse (0) or dense (1)
        self.work = tuple(np.zeros(n) for _ in range(10)) + (np.zeros(nnz), np.zeros(nnz), np.zeros(nnz))
        self.out = tuple(np.zeros(n) for _ in range(4))
        self.z_shapes = list(zip(self.cs.state_names, self.cs.state_shapes))
        self.n_z = sum(int(np.prod(s)) for _, s in self.z_shapes)
        self._compile()

    def _compile(self) -> None:
        """Compile (or load) the step loop now, before any step: a progress bar's ETA then leaves the compile
        out, and a first run on a machine says what it is doing instead of looking stuck."""
        n = self.n
        z = np.zeros(n)
        _compiled.compile_announced(
            lambda: call(advance, self.cs.groups, 0.0, z.copy(), z.copy(), z.copy(), z.copy(), 1e-6, 0.0, 0, self.prm,
                         self.ctrl, self.atol, self.rtol, self.freeze, self.cs.fams, self.cs.zs, self.cs.sysd, self.pat,
                         self.lu, self.cache, self.work, np.zeros(6, np.int64), self.out,
                         np.empty((1, 3 + 4 * n + self.n_z))),
            cold=not _compiled.kernels_cached(groups=self.cs.groups), what="the engine's kernels", done="kernels",
            about="about half a minute of CPU")

    def drop_lu(self) -> None:
        """Forget the LU (the numpy path drops it at checkpoints: both refactorise at the same step)."""
        self.cache[0] = 0.0

    def advance(self, state: State, h: float, t_end: float, max_steps: int) -> Block:
        """Up to ``max_steps`` accepted steps from ``state`` (not modified) towards t_end."""
        self.cs.set_internal(state.z)
        q, v, a, f = (np.array(x, float) for x in (state.q, state.v, state.a, state.f))
        log = np.empty((max(int(max_steps), 1), 3 + 4 * self.n + self.n_z))
        counters = np.zeros(6, np.int64)
        with self.cs.threads_set():
            t, h, acc, status, it, rate, reason = call(
                advance, self.cs.groups, float(state.t), q, v, a, f, float(h), float(t_end), int(max_steps), self.prm,
                self.ctrl, self.atol, self.rtol, self.freeze, self.cs.fams, self.cs.zs, self.cs.sysd, self.pat,
                self.lu, self.cache, self.work, counters, self.out, log)
        keys = ("residual", "jacobian", "factor", "newton", "accepted", "rejected")
        failed = StepInfo(False, int(it), float(rate), reason=FAIL_REASONS[reason]) if status == 2 else None
        blk = Block(log[:acc], state, self.z_shapes, dict(zip(keys, (int(c) for c in counters))), state, float(h),
                    failed)
        if acc:
            blk.state = blk.state_at(acc - 1)
        return blk
