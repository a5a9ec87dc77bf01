"""Vectorised forward-mode derivatives for element kernels.

An element family writes its force law once, on (n,) arrays. Called with plain arrays it returns
forces; called with :class:`Dual` inputs (one tangent direction per local coordinate and velocity)
it returns forces whose ``der`` holds the exact Jacobian rows, so every element's ∂F/∂q and ∂F/∂v
are exact to round-off and never drift from the force code (finite-difference tests check them).

A Dual holds ``val`` of shape (n,) and ``der`` of shape (n, m): m tangent directions per instance.
Only the operations the element kernels need are provided; each works on Duals and plain arrays.
"""
from __future__ import annotations

import numpy as np

__all__ = [
    "Dual", "seed", "value", "sin", "cos", "tanh", "exp", "sqrt", "abs_", "where", "pos", "power",
    "arctan2", "hypot", "sign", "wrap_angle", "clip_min", "repeat_each", "group_sum", "take", "spread",
]


class Dual:
    __slots__ = ("val", "der")
    __array_priority__ = 100  # make ndarray <op> Dual defer to Dual's reflected operators

    def __init__(self, val, der):
        self.val = val
        self.der = der

    # arithmetic -------------------------------------------------------------------------------
    def __add__(self, o):
        if isinstance(o, Dual):
            return Dual(self.val + o.val, self.der + o.der)
        return Dual(self.val + o, self.der)

    __radd__ = __add__

    def __sub__(self, o):
        if isinstance(o, Dual):
            return Dual(self.val - o.val, self.der - o.der)
        return Dual(self.val - o, self.der)

    def __rsub__(self, o):
        return Dual(o - self.val, -self.der)

    def __neg__(self):
        return Dual(-self.val, -self.der)

    def __mul__(self, o):
        if isinstance(o, Dual):
            return Dual(self.val * o.val, self.der * o.val[:, None] + o.der * self.val[:, None])
        return Dual(self.val * o, self.der * _col(o))

    __rmul__ = __mul__

    def __truediv__(self, o):
        if isinstance(o, Dual):
            inv = 1.0 / o.val
            return Dual(self.val * inv, (self.der - o.der * (self.val * inv)[:, None]) * inv[:, None])
        return Dual(self.val / o, self.der / _col(o))

    def __rtruediv__(self, o):
        inv = 1.0 / self.val
        return Dual(o * inv, self.der * (-o * inv * inv)[:, None])

    def __pow__(self, p):
        return power(self, p)

    # comparisons give plain boolean arrays (used for gating, which is piecewise-constant)
    def __gt__(self, o):
        return self.val > value(o)

    def __lt__(self, o):
        return self.val < value(o)

    def __ge__(self, o):
        return self.val >= value(o)

    def __le__(self, o):
        return self.val <= value(o)

    @property
    def shape(self):
        return self.val.shape

    def __repr__(self):
        return f"Dual(val={self.val!r}, der.shape={self.der.shape})"


def _col(c):
    """Broadcast a scalar or (n,) constant against an (n, m) derivative."""
    return c[:, None] if np.ndim(c) == 1 else c


def seed(columns: np.ndarray, offset: int, m: int) -> list[Dual]:
    """Duals for the columns of an (n, k) array, tangent directions offset..offset+k-1 of m."""
    n, k = columns.shape
    out = []
    for j in range(k):
        d = np.zeros((n, m))
        d[:, offset + j] = 1.0
        out.append(Dual(columns[:, j].copy(), d))
    return out


def value(x):
    return x.val if isinstance(x, Dual) else x


def _chain(x, f, df):
    if isinstance(x, Dual):
        return Dual(f, x.der * df[:, None])
    return f


def sin(x):
    v = value(x)
    return _chain(x, np.sin(v), np.cos(v)) if isinstance(x, Dual) else np.sin(v)


def cos(x):
    v = value(x)
    return _chain(x, np.cos(v), -np.sin(v)) if isinstance(x, Dual) else np.cos(v)


def tanh(x):
    v = value(x)
    t = np.tanh(v)
    return _chain(x, t, 1.0 - t * t) if isinstance(x, Dual) else t


def exp(x):
    v = value(x)
    e = np.exp(v)
    return _chain(x, e, e) if isinstance(x, Dual) else e


def sqrt(x):
    v = value(x)
    s = np.sqrt(v)
    if not isinstance(x, Dual):
        return s
    with np.errstate(divide="ignore", invalid="ignore"):
        ds = np.where(s > 0, 0.5 / np.where(s > 0, s, 1.0), 0.0)
    return _chain(x, s, ds)


def abs_(x):
    v = value(x)
    return _chain(x, np.abs(v), np.sign(v)) if isinstance(x, Dual) else np.abs(v)


def sign(x):
    """Sign as a plain array (its derivative is zero almost everywhere)."""
    return np.sign(value(x))


def power(x, p: float):
    """x**p for x >= 0 (p > 1 keeps the derivative finite at 0)."""
    v = value(x)
    r = np.power(v, p)
    if not isinstance(x, Dual):
        return r
    return _chain(x, r, p * np.power(v, p - 1.0))


def pos(x):
    """max(x, 0) with derivative 1 where x > 0 and 0 elsewhere."""
    return where(value(x) > 0.0, x, 0.0)


def clip_min(x, lo: float):
    return where(value(x) > lo, x, lo)


def where(cond, a, b):
    """Elementwise select between Duals or arrays; derivatives follow the selected branch."""
    if not isinstance(a, Dual) and not isinstance(b, Dual):
        return np.where(cond, a, b)
    m = (a.der if isinstance(a, Dual) else b.der).shape[1]
    n = cond.shape[0]
    av, bv = value(a), value(b)
    ad = a.der if isinstance(a, Dual) else np.zeros((n, m))
    bd = b.der if isinstance(b, Dual) else np.zeros((n, m))
    return Dual(np.where(cond, av, bv), np.where(cond[:, None], ad, bd))


def hypot(x, y):
    return sqrt(x * x + y * y)


def arctan2(y, x):
    yv, xv = value(y), value(x)
    r = np.arctan2(yv, xv)
    if not isinstance(y, Dual) and not isinstance(x, Dual):
        return r
    r2 = xv * xv + yv * yv
    m = (y.der if isinstance(y, Dual) else x.der).shape[1]
    d = np.zeros((len(r), m))
    if isinstance(y, Dual):
        d += y.der * (xv / r2)[:, None]
    if isinstance(x, Dual):
        d -= x.der * (yv / r2)[:, None]
    return Dual(r, d)


def wrap_angle(x):
    """Wrap to (-pi, pi]; the derivative is 1 (the wrap is a constant shift)."""
    v = value(x)
    w = v - 2.0 * np.pi * np.round(v / (2.0 * np.pi))
    if isinstance(x, Dual):
        return Dual(w, x.der)
    return w


# instances × sub-points (slices): a family that evaluates k points per instance flattens them into the instance axis
def repeat_each(x, k: int):
    """Each instance's value repeated k times: (n,) → (n·k,) (a Dual's derivative rows with it; scalars pass); an
    array of K states (K, n) → (K, n·k), the instances along the last axis."""
    if isinstance(x, Dual):
        return Dual(np.repeat(x.val, k), np.repeat(x.der, k, axis=0))
    return np.repeat(x, k, axis=-1) if np.ndim(x) else x


def group_sum(x, n: int, k: int):
    """The sum over each instance's k points: (n·k,) → (n,); (K, n·k) → (K, n) for an array of K states."""
    if isinstance(x, Dual):
        return Dual(x.val.reshape(n, k).sum(axis=1), x.der.reshape(n, k, x.der.shape[-1]).sum(axis=1))
    x = np.asarray(x)
    return x.reshape(x.shape[:-1] + (n, k)).sum(axis=-1)


def take(x, idx):
    """Instances ``idx`` of a Dual or an array (scalars pass)."""
    if isinstance(x, Dual):
        return Dual(x.val[idx], x.der[idx])
    return x[idx] if np.ndim(x) else x


def spread(x, idx, n: int, m: int):
    """Values over the instances ``idx`` put back on all n instances (0 elsewhere); m the derivative count (0: an
    array)."""
    if isinstance(x, Dual):
        val, der = np.zeros(n), np.zeros((n, m))
        val[idx], der[idx] = x.val, x.der
        return Dual(val, der)
    out = np.zeros(n)
    out[idx] = x
    return out
