"""Linearization about a state and modal analysis.

M, C = −∂F/∂v, K = −∂F/∂q come from the same element Jacobians the integrator uses (frame terms
included: in a rotating frame C holds the gyroscopic 2mΩ terms and K the centrifugal softening).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.linalg as sla

from .assembly import System
from .model import Model

__all__ = ["linearize", "modal_analysis", "ModalResult"]


def linearize(model: Model, t: float, q, v, z=None):
    """Dense (M, C, K) about (t, q, v)."""
    system = System(model)
    z = system.init_internal() if z is None else z
    ev = system.evaluate(t, np.asarray(q, float), np.asarray(v, float), z, jac=True)
    M, C, K = system.matrices(ev)
    return M.toarray(), C.toarray(), K.toarray()


@dataclass
class ModalResult:
    frequencies_hz: np.ndarray   # ascending, rigid-body modes as 0
    shapes: np.ndarray           # (ndof, nmodes), mass-normalised columns
    damping_ratio: np.ndarray | None = None


def modal_analysis(model: Model, t: float, q, v, z=None, damped: bool = False, rigid_tol: float = 1e-6) -> ModalResult:
    """Undamped modes from the symmetric part of K with M (``damped=False``), or the complex modes
    of the full first-order system with C (``damped=True``: frequencies |Im λ|/2π, ratios −Re λ/|λ|)."""
    M, C, K = linearize(model, t, q, v, z)
    Ks = 0.5 * (K + K.T)
    lam, X = sla.eigh(Ks, M)
    scale = max(np.max(np.abs(lam)), 1.0)
    lam = np.where(np.abs(lam) < rigid_tol * scale, 0.0, lam)
    f = np.sqrt(np.maximum(lam, 0.0)) / (2 * np.pi)
    order = np.argsort(f)
    if not damped:
        return ModalResult(f[order], X[:, order])
    n = M.shape[0]
    Minv = np.diag(1.0 / np.diag(M))
    A = np.block([[np.zeros((n, n)), np.eye(n)], [-Minv @ K, -Minv @ C]])
    ev, V = sla.eig(A)
    keep = ev.imag >= -1e-12 * scale
    ev, V = ev[keep], V[:n, keep]
    fr = np.abs(ev.imag) / (2 * np.pi)
    zeta = np.where(np.abs(ev) > 0, -ev.real / np.maximum(np.abs(ev), 1e-300), 0.0)
    o = np.argsort(fr)
    return ModalResult(fr[o], V[:, o], zeta[o])
