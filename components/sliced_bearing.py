"""The quasi-static sliced planet bearing (docs/model.md §8.8, §14): one cylindrical roller bearing under a given
radial load and a given misalignment of the pin against the planet bore, every roller sliced
(:class:`mbd.elements.sliced.SlicedContact`), the case ISO/TS 16281:2008 covers.

Frame and inputs. The pin (inner raceway) is fixed, its centre at the origin; the bore (outer raceway) centre is
displaced by u (solved). ``load`` is the force F on the planet [N] (its mesh forces and centrifugal force, in the
frame of the bearing), carried by the pin; the rollers on the far side of the pin from F carry it
(ψ = arg F + π). The misalignment is the slope of the pin's axis against the bore's, γ [rad] in direction β:
``"radial"`` β = arg F (in the load plane), ``"tangential"`` β = arg F + 90°. The bore's slope is held at zero
(the ring's tilt is given, not solved: the bearing's tilting moment is an output, the reaction the planet needs).

Rollers. Roller j sits at the cage angle ψ_j = φ + 2πj/Z, its centre on its radial line (the cage holds it
there: a roller's tangential forces are the cage's), its radius r_j and its tilt τ_j in its radial–axial plane
(slope τ_j e_j) free: each roller is in force and moment equilibrium between its two raceways, Σ_k (F_i,k + F_o,k)
·e_j = 0 and Σ_k z_k (F_i,k + F_o,k)·e_j = 0 (rollers' centrifugal load, traction and skew left out, as ISO/TS
16281 does; Harris & Kotzalas vol. 2 ch. 1: a free roller takes the tilt that balances its moments). Roller and
raceways being of one material and the line contact's constant independent of the curvature, a free roller takes
half the misalignment and both its contacts the same slice loads, so that the two contacts act as one lamina of
the series constant K 2^(−10/9), ISO/TS 16281's form; the exact-norm geometry keeps the second-order terms the
standard's linear kinematics leaves out. Rows sit at ζ_row = (i − (rows − 1)/2) e_r, e_r = ``bearing.row_spacing``
(:func:`components.bearing.row_stations`).

Solution. For a bore displacement u every roller's (r_j, τ_j) is solved by Newton's method on its own 2×2 system
(exact Jacobian of the slice law, vectorised over rollers, steps halved until the roller's residual falls); the
bore's force balance F + Σ (contact forces on the bore) = 0 is solved for u by scipy's ``root`` (Powell hybrid)
with the exact Jacobian of the Schur complement (the rollers condensed out).

Outputs (:class:`SlicedBearingState`): slice loads per raceway, the contact pressure p = sqrt(w E*/(π R)),
w = q/Δ, 1/R = 2/D ± 2/d_race (Hertz line contact per slice), the pressure profile along the most loaded roller
and its edge indicators (the end slices' pressure over the middle slice's; the loaded length fraction).
:func:`sliced_bearing_life` averages the slice loads over cage positions (one roller pitch) and feeds
:func:`components.life.sliced_life`.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.optimize import root

from mbd.elements.sliced import SlicedContact, iso_16281_stiffness, slice_stations

from . import life
from .bearing import row_stations
from .profiles import reduced_modulus, roller_drop

__all__ = ["ARCMIN", "MISALIGNMENT_DIRECTIONS", "SlicedBearing", "SlicedBearingState", "sliced_bearing_life",
           "misalignment_sweep", "pressure_scales"]

ARCMIN = math.pi / (180.0 * 60.0)
MISALIGNMENT_DIRECTIONS = ("radial", "tangential")


@dataclass(frozen=True)
class SlicedBearingState:
    """The solved bearing at one cage position: ``u`` bore displacement [m]; ``psi`` (Z,) roller angles [rad];
    ``radius``, ``tilt`` (rows, Z) roller centre radii [m] and tilts [rad]; ``q_pin``, ``q_bore`` (rows, Z, n_s)
    slice loads [N]; ``p_pin``, ``p_bore`` the slices' Hertz pressures [Pa]; ``moment`` (2,) the tilting
    moment the bore's contacts put on the planet, as the generalised force on its slope −Σ ζ_k F_k [N m];
    ``z`` (n_s,) slice stations [m]."""
    u: np.ndarray
    psi: np.ndarray
    radius: np.ndarray
    tilt: np.ndarray
    q_pin: np.ndarray
    q_bore: np.ndarray
    p_pin: np.ndarray
    p_bore: np.ndarray
    moment: np.ndarray
    z: np.ndarray

    def most_loaded(self) -> tuple[int, int]:
        """(row, roller) of the roller with the largest pin load."""
        i = int(np.argmax(self.q_pin.sum(axis=2)))
        return divmod(i, self.q_pin.shape[1])

    @property
    def max_pressure(self) -> float:
        """The largest slice pressure of either raceway [Pa]."""
        return float(max(self.p_pin.max(), self.p_bore.max()))

    def pressure_profile(self) -> np.ndarray:
        """(n_s,) pin pressure along the most loaded roller [Pa] (the pin: the convex raceway, the higher
        pressure)."""
        r, j = self.most_loaded()
        return self.p_pin[r, j]

    def edge_ratio(self) -> float:
        """The most loaded roller's larger end-slice pin pressure over its middle slice's (the mean of the two
        middle slices when n_s is even); inf when the middle is unloaded."""
        p = self.pressure_profile()
        n = p.size
        mid = p[n // 2] if n % 2 else 0.5 * (p[n // 2 - 1] + p[n // 2])
        end = max(p[0], p[-1])
        return float(end / mid) if mid > 0 else math.inf

    def loaded_length(self) -> float:
        """The fraction of the most loaded roller's slices in contact with the pin."""
        r, j = self.most_loaded()
        return float(np.count_nonzero(self.q_pin[r, j] > 0.0) / self.q_pin.shape[2])


def pressure_scales(b, slices: int) -> tuple[float, float]:
    """(pin, bore) factors c of a slice's Hertz line-contact pressure p = c √q [Pa] from its load q [N]:
    p = √(w E*/(π R)), w = q/Δ, Δ = l/n_s, 1/R = 2/D ± 2/d_race (pin +, bore −)."""
    E, D, width = reduced_modulus(b), b.roller_diameter, b.roller_length / slices
    return tuple(math.sqrt(E / (math.pi * width) * (2.0 / D + s / R))
                 for s, R in ((1.0, b.inner_raceway_radius), (-1.0, b.outer_raceway_radius)))


class SlicedBearing:
    """The quasi-static sliced bearing ``b`` (:class:`~components.params.BearingSI`; profile and slicing from
    ``b.profile``, ``b.slicing``; ``slices`` overrides the slice count). See the module docstring."""

    def __init__(self, b, slices: int | None = None):
        self.b = b
        n_s = b.slicing.slices if slices is None else int(slices)
        self.z, self.width = slice_stations(b.roller_length, n_s)
        self.n_s = n_s
        K = b.contact_stiffness if b.slicing.stiffness == "palmgren" else iso_16281_stiffness(b.roller_length)
        self.K = K
        self._load_scale = K * b.roller_diameter ** b.contact_exponent * 1e-3   # N: a roller load's scale (δ = D/1000)
        Z, rows = b.rollers, b.rows
        self.Z, self.rows = Z, rows
        zeta_row = np.repeat(row_stations(b), Z)
        drop = roller_drop(b, self.z)
        common = dict(D=b.roller_diameter, K=K, exponent=b.contact_exponent, z=self.z, drop=drop,
                      row_offset=zeta_row)
        self.inner = SlicedContact(kind="inner", R_race=b.inner_raceway_radius, **common)
        self.outer = SlicedContact(kind="outer", R_race=b.outer_raceway_radius, **common)
        E = reduced_modulus(b)
        D = b.roller_diameter
        self._p_scale = list(pressure_scales(b, self.z.size))

    # ------------------------------------------------------------------ the rollers for a given bore pose
    def _contacts(self, e, r, tau, u, s_pin):
        p = r[:, None] * e
        sig = tau[:, None] * e
        ri = self.inner.evaluate(p, sig, np.zeros(2), s_pin, jacobian=True)
        ro = self.outer.evaluate(p, sig, u, np.zeros(2), jacobian=True)
        return ri, ro

    def _roller_residual(self, e, ri, ro):
        """(g (n, 2), J_yy (n, 2, 2), J_yu (n, 2, 2)): e·(Σ F), e·(Σ z F) and their derivatives w.r.t. (r, τ), u."""
        F = ri.force + ro.force
        M = ri.roller_moment + ro.roller_moment
        g = np.stack([np.einsum("ni,ni->n", e, F), np.einsum("ni,ni->n", e, M)], axis=1)
        J = ri.jacobian + ro.jacobian
        Jyy = np.empty((len(e), 2, 2))
        for a, rows_ in enumerate((slice(0, 2), slice(2, 4))):
            for c, cols in enumerate((slice(0, 2), slice(2, 4))):
                Jyy[:, a, c] = np.einsum("ni,nij,nj->n", e, J[:, rows_, cols], e)
        Jo = ro.jacobian
        Jyu = np.stack([np.einsum("ni,nij->nj", e, Jo[:, 0:2, 4:6]), np.einsum("ni,nij->nj", e, Jo[:, 2:4, 4:6])],
                       axis=1)
        return g, Jyy, Jyu

    def _solve_rollers(self, e, u, s_pin, r, tau):
        """Every roller's (r, τ) in equilibrium for the bore displacement ``u`` (vectorised Newton, halving)."""
        lscale = self.b.roller_length
        scale = np.array([1.0, 1.0 / lscale])

        def res(r_, t_):
            ri, ro = self._contacts(e, r_, t_, u, s_pin)
            return (ri, ro, *self._roller_residual(e, ri, ro))

        ri, ro, g, Jyy, Jyu = res(r, tau)
        tol = 1e-12 * self._load_scale
        for _ in range(100):
            norm = np.abs(g * scale).max(axis=1)
            active = norm > tol
            if not active.any():
                break
            reg = 1e-12 * np.abs(Jyy).max(axis=(1, 2), keepdims=True) + 1e-300
            dy = -np.linalg.solve(Jyy - reg * np.eye(2), g[:, :, None])[:, :, 0]
            # a step at the round-off of the roller's radius: the residual is as small as the positions allow
            active &= np.maximum(np.abs(dy[:, 0]), np.abs(dy[:, 1]) * lscale) > 64.0 * np.finfo(float).eps * r
            if not active.any():
                break
            dy[~active] = 0.0
            alpha = np.ones(len(e))
            for _h in range(30):
                r1, t1 = r + alpha * dy[:, 0], tau + alpha * dy[:, 1]
                ri1, ro1, g1, Jyy1, Jyu1 = res(r1, t1)
                worse = active & (np.abs(g1 * scale).max(axis=1) > norm * (1.0 - 1e-4 * alpha))
                if not worse.any():
                    break
                alpha = np.where(worse, 0.5 * alpha, alpha)
            r, tau, ri, ro, g, Jyy, Jyu = r1, t1, ri1, ro1, g1, Jyy1, Jyu1
        else:
            raise RuntimeError(f"sliced bearing: a roller found no equilibrium (residual {norm.max():.3g} N)")
        return r, tau, ri, ro, g, Jyy, Jyu

    def _directions(self, cage_angle):
        psi = cage_angle + 2.0 * math.pi * np.arange(self.Z) / self.Z
        return psi, np.tile(np.stack([np.cos(psi), np.sin(psi)], axis=1), (self.rows, 1))

    def _state(self, u, psi, r, tau, ri, ro) -> SlicedBearingState:
        shape = (self.rows, self.Z, self.n_s)
        q_pin, q_bore = ri.load.reshape(shape), ro.load.reshape(shape)
        return SlicedBearingState(u=np.asarray(u, float), psi=psi, radius=r.reshape(self.rows, self.Z),
                                  tilt=tau.reshape(self.rows, self.Z), q_pin=q_pin, q_bore=q_bore,
                                  p_pin=self._p_scale[0] * np.sqrt(q_pin), p_bore=self._p_scale[1] * np.sqrt(q_bore),
                                  moment=ro.race_moment.sum(axis=0), z=self.z)

    def rollers_at(self, u, slope, cage_angle: float = 0.0) -> SlicedBearingState:
        """The rollers in equilibrium at a given bore displacement ``u`` (2,) [m] and pin slope ``slope`` (2,) [rad]
        against the bore (the bore's force balance not imposed)."""
        _, _, rollers = self.bore_balance(u, np.zeros(2), slope, cage_angle)
        return self._state(u, self._directions(cage_angle)[0], *rollers)

    def bore_balance(self, u, load, slope, cage_angle: float = 0.0):
        """(G, ∂G/∂u, rollers): the bore's force balance G = F + Σ (contact forces on the bore) [N] at the bore
        displacement ``u`` with every roller in equilibrium, its exact derivative through the rollers (the Schur
        complement ∂G/∂u − ∂G/∂y (∂g/∂y)⁺ ∂g/∂u), and the rollers' (r, τ, pin and bore contacts)."""
        psi, e = self._directions(cage_angle)
        u, s_pin = np.asarray(u, float), np.asarray(slope, float)
        R_m = 0.5 * (self.b.inner_raceway_radius + self.b.outer_raceway_radius)
        r, tau, ri, ro, g, Jyy, Jyu = self._solve_rollers(e, u, s_pin, R_m + 0.5 * (e @ u), 0.5 * (e @ s_pin))
        G = np.asarray(load, float) + ro.race_force.sum(axis=0)
        Jo = ro.jacobian
        JGu = Jo[:, 4:6, 4:6].sum(axis=0)
        JGy = np.stack([np.einsum("nij,nj->ni", Jo[:, 4:6, 0:2], e),
                        np.einsum("nij,nj->ni", Jo[:, 4:6, 2:4], e)], axis=2)           # (n, 2, 2)
        # a roller touching at one slice only pivots there (J_yy of rank 1): the pseudo-inverse leaves its neutral
        # direction out; an unloaded roller (J_yy = 0) adds nothing
        corr = np.einsum("nij,njk,nkl->il", JGy, np.linalg.pinv(Jyy, rcond=1e-12), Jyu)
        return G, JGu - corr, (r, tau, ri, ro)

    # ------------------------------------------------------------------ the bearing
    def solve(self, load, misalignment: float = 0.0, direction: str = "radial", cage_angle: float = 0.0,
              u0=None) -> SlicedBearingState:
        """The equilibrium under the force ``load`` (2,) on the planet [N] with the pin's slope ``misalignment``
        γ [rad] against the bore, ``direction`` "radial" or "tangential" to the load (or an angle [rad] of the
        slope in the bearing's frame), the cage at ``cage_angle`` [rad] (roller 0's angle)."""
        b = self.b
        F = np.asarray(load, float)
        Fn = float(np.hypot(*F))
        if not Fn > 0.0:
            raise ValueError(f"load: expected a nonzero force vector [N], got {load!r}")
        chi = math.atan2(F[1], F[0])
        if isinstance(direction, str):
            if direction not in MISALIGNMENT_DIRECTIONS:
                raise ValueError(f"direction: expected one of {list(MISALIGNMENT_DIRECTIONS)} or an angle [rad], "
                                 f"got {direction!r}")
            beta = chi + (0.0 if direction == "radial" else 0.5 * math.pi)
        else:
            beta = float(direction)
        s_pin = misalignment * np.array([math.cos(beta), math.sin(beta)])
        psi = self._directions(cage_angle)[0]
        state = {}

        def bore(uv):
            G, J, state["rollers"] = self.bore_balance(uv, F, s_pin, cage_angle)
            return G, J

        if u0 is None:
            q_max = 5.0 * Fn / (self.Z * b.rows)
            approach = 2.0 * (q_max / self.K) ** (1.0 / b.contact_exponent)
            u0 = (0.5 * b.clearance + approach) * F / Fn
        sol = root(bore, np.asarray(u0, float), jac=True, method="hybr", options={"xtol": 1e-13})
        G, _ = bore(sol.x)
        if not (np.hypot(*G) <= 1e-8 * Fn):
            raise RuntimeError(f"sliced bearing: no equilibrium under {Fn:g} N (residual {np.hypot(*G):.3g} N; "
                               f"{sol.message})")
        return self._state(sol.x, psi, *state["rollers"])

    def states(self, load, misalignment=0.0, direction="radial", positions: int = 8) -> list[SlicedBearingState]:
        """The bearing at ``positions`` cage angles evenly over one roller pitch (each started from the last)."""
        out, u0 = [], None
        for m in range(positions):
            s = self.solve(load, misalignment, direction, cage_angle=2.0 * math.pi * m / (positions * self.Z), u0=u0)
            out.append(s)
            u0 = s.u
        return out


def sliced_bearing_life(states: list[SlicedBearingState], b) -> float | None:
    """ISO/TS 16281 life with slices [10^6 revolutions] from the bearing's states over a roller pitch
    (:meth:`SlicedBearing.states`): per row and slice the pin's equivalent load over rollers and positions with the
    stationary exponent 4.5, the bore's with the rotating exponent 4 (:mod:`components.life`), then
    :func:`components.life.sliced_life`."""
    q_pin = np.stack([s.q_pin for s in states])                  # (positions, rows, Z, n_s)
    q_bore = np.stack([s.q_bore for s in states])
    pe = life.equivalent_load(np.mean(q_pin ** life.STATIONARY_EXPONENT, axis=(0, 2)), life.STATIONARY_EXPONENT)
    be = life.equivalent_load(np.mean(q_bore ** life.ROTATING_EXPONENT, axis=(0, 2)), life.ROTATING_EXPONENT)
    return life.sliced_life(pe, be, b)


def misalignment_sweep(b, load, gammas, direction: str, positions: int = 8) -> list[dict]:
    """The bearing ``b`` under ``load`` (2,) [N] at each pin slope γ of ``gammas`` [rad] (``direction`` "radial" or
    "tangential" to the load): per γ the sliced life ``life_Mrev`` [10^6 revolutions], ``life_relative`` to the first
    γ of the list (give 0 first: relative to the aligned bearing), and over the ``positions`` cage positions the
    largest ``edge_ratio`` of the most loaded roller, the largest slice pressure ``p_max_Pa`` and the smallest
    ``loaded_length``."""
    sb = SlicedBearing(b)
    rows = []
    for g in gammas:
        st = sb.states(load, g, direction, positions=positions)
        rows.append({"gamma_rad": float(g), "direction": direction, "life_Mrev": sliced_bearing_life(st, b),
                     "edge_ratio": max(s.edge_ratio() for s in st), "p_max_Pa": max(s.max_pressure for s in st),
                     "loaded_length": min(s.loaded_length() for s in st)})
    ref = rows[0]["life_Mrev"]
    for r in rows:
        r["life_relative"] = r["life_Mrev"] / ref if ref and r["life_Mrev"] else None
    return rows
