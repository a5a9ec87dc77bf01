"""The element protocol: one object is a *family* of n force elements.

A family owns an (n, k) integer array ``dofs`` of indices into the full coordinate vector (3 per
body: x, y, θ; k = ``n_local``, the local coordinates of one instance), resolved when the scene is built, and a vectorised ``kernel``:

    kernel(t, fs, q, v, z) -> (forces, outputs)

``q`` and ``v`` are lists of k columns, each an (n,) array — or an :class:`mbd.ad.Dual` when the
assembler wants Jacobians. ``forces`` is a list of k generalized forces (force x, force y, torque
per body, in the reference frame R) *acting on* those coordinates. ``outputs`` is a dict of (n,)
quantities a recorder may store (contact loads, deflections...). Kernels use :mod:`mbd.ad`
functions so the same code yields values and exact derivatives.

Sign convention, stated once: the assembler returns J_q = ∂F/∂q and J_v = ∂F/∂v of the force; the
stiffness and damping matrices are K = −J_q and C = −J_v; the Newton matrix is c_M·M + c_C·C + c_K·K.

Newton's third law: every kernel applies equal and opposite forces on the bodies it couples, and the
torques balance about any point (tests check Σ forces = 0 and Σ moments about the origin = 0).
"""
from __future__ import annotations

import numpy as np

from . import ad
from .errors import ModelError

__all__ = ["Element", "evaluate", "marker", "point_force", "body_dofs"]


def body_dofs(*bodies) -> np.ndarray:
    """(n, 3·len(bodies)) dof array from per-instance body indices (ints or arrays of ints)."""
    cols = []
    for b in bodies:
        idx = np.atleast_1d(np.asarray([getattr(x, "index", x) for x in np.atleast_1d(b)], dtype=np.int64))
        cols.append(idx)
    n = max(c.size for c in cols)
    out = []
    for c in cols:
        if c.size not in (1, n):
            raise ModelError(f"body index arrays must have equal length or 1, got {[c.size for c in cols]}")
        c = np.broadcast_to(c, (n,))
        out.append(np.column_stack([3 * c, 3 * c + 1, 3 * c + 2]))
    return np.hstack(out)


class Element:
    """Base class. Subclasses set ``n_local`` (local coordinates per instance: 3 per body) and ``dofs``
    and implement ``kernel``."""

    n_local: int = 0
    name: str = "element"
    dofs: np.ndarray
    # the kernel is elementwise over its instances: (K, n) columns evaluate K states at once
    # (System.outputs_batch); False for kernels that call arbitrary functions of t
    batched: bool = False
    # the family's compiled twin: "module.name" of its kernels in mbd.compiled (pack_name, evaluate_name and,
    # with internal state, update_name), dispatched by mbd.compiled.registry; None: the numpy path only.
    # Not inherited (see __init_subclass__): a subclass may change the law its parent's kernel computes.
    compiled_twin: str | None = None

    def __init_subclass__(cls, **kwargs):
        super().__init_subclass__(**kwargs)
        if "compiled_twin" not in vars(cls):
            cls.compiled_twin = None

    @property
    def n(self) -> int:
        return self.dofs.shape[0]

    def check(self) -> None:
        """Validate per-instance parameters (called at build). Raise ModelError naming the parameter."""

    def _per_instance(self, name: str, value, positive=False, nonneg=False) -> np.ndarray:
        """Broadcast a parameter to (n,), checking finiteness and sign; name it in any error."""
        a = np.asarray(value, dtype=float)
        if a.ndim > 1 or (a.ndim == 1 and a.size not in (1, self.n)):
            raise ModelError(f"{self.name}: parameter {name!r} must be a scalar or have {self.n} entries, got shape {a.shape}")
        a = np.broadcast_to(a, (self.n,)).astype(float)
        if not np.all(np.isfinite(a)):
            raise ModelError(f"{self.name}: parameter {name!r} must be finite, got {value!r}")
        if positive and np.any(a <= 0):
            raise ModelError(f"{self.name}: parameter {name!r} must be > 0, got {value!r}")
        if nonneg and np.any(a < 0):
            raise ModelError(f"{self.name}: parameter {name!r} must be >= 0, got {value!r}")
        return a

    def _per_instance_xy(self, name: str, value) -> np.ndarray:
        """(n, 2) body-fixed offsets/points from a (2,) or (n, 2) value [m]; errors name the parameter."""
        a = np.asarray(value, dtype=float)
        if a.shape not in ((2,), (self.n, 2)):
            raise ModelError(f"{self.name}: parameter {name!r} must have shape (2,) or ({self.n}, 2) [m], got {a.shape}")
        if not np.all(np.isfinite(a)):
            raise ModelError(f"{self.name}: parameter {name!r} must be finite, got {value!r}")
        return np.broadcast_to(a, (self.n, 2)).copy()

    # fusion: families whose keys are equal (and not None) may be evaluated as one concatenated family
    # by the assembler (same results, fewer Python-level calls); outputs still go to each family's name
    def fuse_key(self):
        return None

    _FUSED: tuple = ()   # per-instance attributes a fused family concatenates (dofs among them)

    @classmethod
    def fuse(cls, parts):
        """One family holding the instances of ``parts`` (equal fuse keys): the per-instance attributes
        named in ``_FUSED`` are concatenated; subclasses add their family-level attributes."""
        f = cls.__new__(cls)
        f.name = "+".join(p.name for p in parts)
        for a in cls._FUSED:
            setattr(f, a, np.concatenate([getattr(p, a) for p in parts]))
        return f

    # internal state (e.g. the integral of a PI drive); None when the family has none
    def init_internal(self):
        return None

    def update_internal(self, z, t0, t1, fs0, fs1, q0, v0, q1, v1):
        """New internal state after an accepted step from (t0, q0, v0) to (t1, q1, v1) (local columns)."""
        return z

    def kernel(self, t, fs, q, v, z):  # pragma: no cover - abstract
        raise TypeError(f"{type(self).__name__} must define kernel(t, fs, q, v, z) -> (forces, outputs)")


def evaluate(elem: Element, t, fs, q_full, v_full, z, jac: bool):
    """Forces (n, k), outputs and, if ``jac``, J_q and J_v (n, k, k) of one family."""
    ql = q_full[elem.dofs]
    vl = v_full[elem.dofs]
    k = elem.n_local
    if not jac:
        f, out = elem.kernel(t, fs, list(ql.T), list(vl.T), z)
        F = np.empty((elem.n, k))
        for i, fi in enumerate(f):      # column assignment broadcasts scalars (hot path: no temporaries)
            F[:, i] = fi
        return F, out, None, None
    m = 2 * k
    f, out = elem.kernel(t, fs, ad.seed(ql, 0, m), ad.seed(vl, k, m), z)
    n = elem.n
    F = np.empty((n, k))
    D = np.zeros((n, k, m))
    for i, fi in enumerate(f):
        if isinstance(fi, ad.Dual):
            F[:, i] = fi.val
            D[:, i, :] = fi.der
        else:
            F[:, i] = fi
    out = {key: ad.value(val) for key, val in out.items()}
    return F, out, D[:, :, :k], D[:, :, k:]


def marker(qb, local):
    """World position P (in R) of a point fixed on a body, and its offset r = P − c.

    ``qb`` is the body's (x, y, θ) columns; ``local`` an (n, 2) or (2,) offset in body axes."""
    local = np.asarray(local, dtype=float)
    lx, ly = (local[..., 0], local[..., 1])
    c, s = ad.cos(qb[2]), ad.sin(qb[2])
    rx = c * lx - s * ly
    ry = s * lx + c * ly
    return (qb[0] + rx, qb[1] + ry), (rx, ry)


def marker_velocity(vb, r):
    """Velocity of a body point with offset r: v_c + θ̇ k × r."""
    return (vb[0] - vb[2] * r[1], vb[1] + vb[2] * r[0])


def point_force(r, F):
    """Generalized force (Fx, Fy, torque) on a body of a force F applied at offset r from its centre."""
    return [F[0], F[1], r[0] * F[1] - r[1] * F[0]]
