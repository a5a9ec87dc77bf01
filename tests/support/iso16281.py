"""The project's own transcription of ISO/TS 16281:2008's laminae of a radial cylindrical roller bearing (its §5.2,
written from the standard's equations, not from the production code): the truth that the quasi-static sliced bearing
(components.sliced_bearing), the sliced rig (components.rig) and their rows are held to, with its own small solver.

For roller j at ψ_j, row i at axial station ζ_i and lamina k at x_k from the roller's centre, the approach of the
rings is δ_ijk = ((ζ_i + x_k) s − u)·e_j − P_d/2 − 2 p(x_k) (the pin's slope s against the bore, the bore displaced
u, the roller's profile p on both its contacts) and the lamina load q_ijk = c ⟨δ_ijk⟩^(10/9), c the constant of a
lamina's two contacts in series: Palmgren's K (each contact at half the approach, K (δ/2)^(10/9)) or the standard's
own c_L = 35948 L^(8/9) N/mm^(10/9) per roller, over n_s. Its kinematics is linear in u and s (the standard's): the
exact-norm geometry of the production code differs from it by terms (u_t² − ζ² s_t²)/(2r) of the offsets across a
roller's radial line, which vanish as the pitch diameter grows.
"""
from __future__ import annotations

import numpy as np
from scipy.optimize import fsolve

from components.profiles import roller_drop

__all__ = ["PALMGREN", "iso_laminae", "iso_solve"]

PALMGREN = 10.0 / 9.0


def iso_laminae(b, u, slope, cage_angle, rows=None):
    """(q, e): the lamina loads q (Z, n_s) of a one-row bearing, or (rows, Z, n_s) at the row stations ``rows`` [m]
    (ζ_i), at the bore displacement ``u`` (2,) [m] and pin slope ``slope`` (2,) [rad]; e (Z, 2) the rollers' radial
    unit vectors (roller j at ``cage_angle`` + 2πj/Z)."""
    n = b.slicing.slices
    width = b.roller_length / n
    x = -0.5 * b.roller_length + width * (np.arange(n) + 0.5)
    psi = cage_angle + 2 * np.pi * np.arange(b.rollers) / b.rollers
    e = np.stack([np.cos(psi), np.sin(psi)], 1)
    if b.slicing.stiffness == "palmgren":
        K = 8.06e4 * (b.roller_length * 1e3) ** (8 / 9) * 1e3 ** PALMGREN          # N/m^(10/9), one contact
        lam = lambda d: K / n * (0.5 * d) ** PALMGREN                             # noqa: E731
    else:
        cL = 35948.0 * (b.roller_length * 1e3) ** (8 / 9)                        # N/mm^(10/9), two contacts in series
        lam = lambda d: cL / n * (1e3 * d) ** PALMGREN                            # noqa: E731
    drop = roller_drop(b, x)
    zeta = np.zeros(1) if rows is None else np.asarray(rows, float)
    st = zeta[:, None, None] + x[None, None, :]                                   # (rows, 1, n_s) stations on the pin
    d = ((e @ -np.asarray(u))[None, :, None] + st * (e @ np.asarray(slope))[None, :, None]
         - 0.5 * b.clearance - 2 * drop[None, None, :])
    q = lam(np.clip(d, 0.0, None))
    return (q[0] if rows is None else q), e


def iso_solve(b, load, slope, cage_angle, rows=None):
    """The standard's bore displacement under ``load`` (2,) [N] on the bore: F + Σ_ijk q_ijk e_j = 0 (its own small
    solver)."""
    def res(u):
        q, e = iso_laminae(b, u, slope, cage_angle, rows)
        per_roller = q.sum(-1) if rows is None else q.sum(axis=(0, 2))
        return (load + per_roller @ e) / np.hypot(*load)
    u0 = 3e-5 * np.asarray(load) / np.hypot(*load)
    return fsolve(res, u0, xtol=1e-13)
