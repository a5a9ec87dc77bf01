"""The oil film of a roller in its cage pocket and the cage's drag in the oil–air mixture (docs/model.md §8.5,
§8.7). Both are opt-in families beside :class:`mbd.elements.contact.PocketContact` (the solid pocket contact and
its dry wall friction, which act as before when the roller closes its film) and
:class:`mbd.elements.contact.LubricantDrag`.

The pocket film (:class:`PocketFilm`). Each pocket has two flat walls (the cage bars), a pocket clearance C_p per
side from the roller's centred position. The roller, a rigid cylinder of radius R = D/2 and length l, at the
circumferential offset s of §8.5 stands at the gaps h₊ = C_p − s and h₋ = C_p + s from them; each gap is a
rigid cylinder near a plane in isoviscous oil of viscosity η, lubricated as Reynolds' equation with the gap
h(x) = h + x²/(2R) (h ≪ R) gives:

* the wedge (entraining) load of a rolling cylinder on a plane (Martin 1916, "Lubrication of gear teeth",
  Engineering 102, 119–121; the rigid-isoviscous line contact of Hamrock, Schmid & Jacobson, *Fundamentals of
  Fluid Film Lubrication*, 2nd ed., 2004, whose h_min/R = 4.9 U/W' it is), with the Reynolds outlet condition
  p = dp/dx = 0 at x_e = √(2Rh)·tan γ_e:  w = 6 cos²γ_e · η ũ R l / h = 4.895 η ũ R l / h, γ_e = 0.44355 the root
  of ∫_{-π/2}^{γ_e} (cos²γ − sec²γ_e cos⁴γ) dγ = 0 (x_e/√(2Rh) = 0.4751), ũ the surfaces' mean speed relative to
  the moving contact point along the wall;
* the squeeze film of a cylinder approaching a plane at speed V = −dh/dt (the same gap, p = 0 far away, a full
  film on approach; the film cannot pull, so none on separation — it cavitates):  w = 3√2 π η V l (R/h)^(3/2);
* the film's shear along the wall: Couette, −η Δu l ∫dx/h over the film from the inlet to the Reynolds outlet,
  ∫dx/h = √(2R/h)(π/2 + γ_e), Δu the roller surface's speed relative to the wall (opposite on the wall), and
  Poiseuille, −(h/2)dp/dx on *both* surfaces, −c_P η ũ l √(2R/h) with
  c_P = 6[(π/2 + γ_e) − sec²γ_e (π/4 + γ_e/2 + sin 2γ_e /4)] = 3.2535 (against the entraining direction).
  The pressure on the roller passes through its centre, and the film's force balance gives it the tangential
  resultant +2c_P η ũ l √(2R/h) (as §9.5's rolling resistance on a flat raceway): the roller's net tangential
  force is the wall's shear reversed, its moment about its centre that of its own shear.

The wedge and squeeze loads are added, each with its own cavitation boundary: an approximation (the Reynolds
outlet is a free boundary, so the two do not superpose: the sum overstates the combined gap's load by up to 22 % on
approach, the wedge alone overstates it on separation; docs/model.md §8.9), and the two walls add: a centred roller feels both walls' shear and no net load. Below the thinnest film h_min the
film is taken at h_min (its rates kept: the force stays continuous) and the solid contact of §8.4 carries the
roller when the gap closes. Range: rigid surfaces (the film's pressure ≪ the Hertz pressure that would flatten
them: a few MPa here), isoviscous oil, Newtonian, laminar, fully flooded pocket (an upper bound), h ≪ R, flat
pocket walls (a conformal — cylindrical — pocket face would carry more: this is the lower bound of the wedge load).

The cage drag (:class:`CageDrag`): each side face of the cage, an annulus r_i … r_o, turns relative to the
carrier in the mixture as a free rotating disk in laminar flow (von Kármán's flow, Cochran's solution;
Schlichting & Gersten, *Boundary-Layer Theory*, 8th ed., §5.2.4: moment of a disk wetted on both sides
2M = 0.616 π ρ R⁴ √(ν ω³), C_M = 3.87 Re^(−1/2), laminar to Re = R²ω/ν ≈ 3·10⁵):
M = −0.616 π √(ρ_e η_e) (r_o⁴ − r_i⁴) sign(Δω)|Δω|^(3/2) for the two faces together, Δω the cage's speed relative
to the carrier. A lower bound: the faces run a few millimetres from the carrier's and the planet's walls, not in
unbounded fluid.
"""
from __future__ import annotations

import numpy as np
from scipy.optimize import brentq

from .. import ad
from ..element import Element, body_dofs, marker_velocity, point_force
from ..errors import ModelError
from .contact import _ETA2, _multiplicity, _scaled

__all__ = ["PocketFilm", "CageDrag", "OUTLET_ANGLE", "WEDGE_LOAD", "SQUEEZE_LOAD", "COUETTE_EXTENT",
           "POISEUILLE_SHEAR", "DISK_MOMENT", "gap_film"]


def _outlet_angle() -> float:
    """γ_e of the Reynolds outlet of a rigid cylinder rolling on a plane: p(−∞) = p(x_e) = 0 with dp/dx(x_e) = 0,
    i.e. ∫_{-π/2}^{γ_e} (cos²γ − sec²γ_e cos⁴γ) dγ = 0 in x = √(2Rh) tan γ (closed-form antiderivatives)."""
    def c2(g):
        return g / 2.0 + np.sin(2.0 * g) / 4.0 + np.pi / 4.0

    def c4(g):
        return 3.0 * g / 8.0 + np.sin(2.0 * g) / 4.0 + np.sin(4.0 * g) / 32.0 + 3.0 * np.pi / 16.0
    return float(brentq(lambda g: c2(g) - c4(g) / np.cos(g) ** 2, 0.1, 1.0, xtol=1e-15, rtol=1e-15))


OUTLET_ANGLE = _outlet_angle()                               # γ_e = 0.443554
WEDGE_LOAD = 6.0 * np.cos(OUTLET_ANGLE) ** 2                 # w = 4.895 η ũ R l / h (Martin)
SQUEEZE_LOAD = 3.0 * np.sqrt(2.0) * np.pi                    # w = 13.33 η V l (R/h)^(3/2)
COUETTE_EXTENT = 0.5 * np.pi + OUTLET_ANGLE                  # ∫dx/h = √(2R/h)·2.0144
POISEUILLE_SHEAR = 6.0 * (COUETTE_EXTENT - (0.25 * np.pi + 0.5 * OUTLET_ANGLE + 0.25 * np.sin(2.0 * OUTLET_ANGLE))
                          / np.cos(OUTLET_ANGLE) ** 2)      # 3.2535: −(h/2)dp/dx integrated, per η ũ l √(2R/h)
DISK_MOMENT = 0.616 * np.pi                                  # Cochran: 2M = 0.616 π ρ R⁴ √(ν ω³)


def gap_film(el, R, inv_h, ue, du, Vp):
    """The gap's law (module docstring) of a rigid cylinder of radius R near a plane at the gap h (inv_h = 1/h), for
    η·l = el, the entraining speed ũ = ue relative to the contact point, the sliding Δu = du of the cylinder's surface
    on the plane's and the approach speed's positive part Vp = max(V, 0): (W, T_C, F_P) — the normal load
    W = WEDGE_LOAD η|ũ|Rl/h + SQUEEZE_LOAD η l (R/h)^(3/2) Vp pushing them apart, the Couette shear on the cylinder
    T_C = −COUETTE_EXTENT η Δu l √(2R/h) (the plane's the opposite) and the Poiseuille shear's size
    F_P = POISEUILLE_SHEAR η ũ l √(2R/h), which acts as −F_P on both surfaces along ũ while the pressure's tangential
    resultant is +2F_P (the film's force balance). The element owns the geometry (which surface, which point)."""
    rr = R * inv_h
    root = ad.sqrt(2.0 * rr)
    W = (WEDGE_LOAD * el) * ad.abs_(ue) * rr + (SQUEEZE_LOAD * el) * rr * ad.sqrt(rr) * Vp
    poi = (POISEUILLE_SHEAR * el) * ue * root
    return W, -1.0 * (COUETTE_EXTENT * el) * du * root, poi


class PocketFilm(Element):
    """The oil film between a roller and the two walls of its cage pocket (module docstring; docs/model.md §8.5).

    Instances couple a roller (first 3 coordinates) with its cage (last 3), as :class:`PocketContact`: the
    offset s = r_m·wrap(β − θ_g − ψ), its rate ṡ = r_m((p − c_g) × (ṗ − ċ_g)/ρ² − ω_g). For each wall w = ±1 (at
    +C_p and −C_p from the pocket centre): the gap h = C_p − w s (taken at h_min below it), the approach speed
    V = w ṡ, the roller surface's sliding on the wall Δu = v_c − w R (ω_R − ω_g) and the entraining speed
    ũ = Δu/2 − v_c (v_c = (ṗ − ċ_g)·e_r the roller centre's radial speed in the cage, which the contact point
    follows; the wall is at rest in the cage). The normal load W = WEDGE_LOAD η|ũ|Rl/h + SQUEEZE_LOAD η l
    (R/h)^(3/2) max(V, 0) pushes the roller away from the wall, applied in the pocket's potential form
    (−Σ w W ∂s/∂q; the cage gets the opposite force and the moment Σ w W r_m). Along e_r at the wall point
    P_w = p + w R t: the roller gets T = −η l Δu √(2R/h)·COUETTE_EXTENT + POISEUILLE_SHEAR η ũ l √(2R/h) (the
    wall's shear reversed), the cage −T at the same point, and the couple w D POISEUILLE_SHEAR η ũ l √(2R/h) on the
    roller (its own Poiseuille shear and the pressure through its centre), the opposite on the cage.

    Parameters per instance: pocket_angle ψ [rad], pitch_radius r_m [m], clearance C_p [m] (> min_film), D [m],
    length l [m], eta η [Pa·s], min_film h_min [m], multiplicity (identical parallel pockets).

    Outputs per physical pocket: "force" Σ w W [N] (+ when the film pushes the cage forward, as the pocket's),
    "shear" T [N] along e_r on the roller, "gap" the smaller gap min(h₊, h₋) [m] (unclipped; < 0: solid contact).
    """
    batched = True
    n_local = 6
    compiled_twin = "contact.pocket_film"

    def __init__(self, name, roller, cage, *, pocket_angle, pitch_radius, clearance, D, length, eta, min_film,
                 multiplicity=1):
        self.name = name
        self.dofs = body_dofs(roller, cage)
        self.pocket_angle = self._per_instance("pocket_angle", pocket_angle)
        self.pitch_radius = self._per_instance("pitch_radius", pitch_radius, positive=True)
        self.clearance = self._per_instance("clearance", clearance, positive=True)
        self.D = self._per_instance("D", D, positive=True)
        self.length = self._per_instance("length", length, positive=True)
        self.eta = self._per_instance("eta", eta, positive=True)
        self.min_film = self._per_instance("min_film", min_film, positive=True)
        if np.any(self.clearance <= self.min_film):
            raise ModelError(f"{name}: parameter 'clearance' must exceed min_film (the pocket film needs a gap "
                             f"above its thinnest film), got clearance {clearance!r} m, min_film {min_film!r} m")
        self.multiplicity = _multiplicity(self, multiplicity)
        self._multi = bool(np.any(self.multiplicity != 1.0))

    def kernel(self, t, fs, q, v, z):
        qr, qg, vr, vg = q[:3], q[3:], v[:3], v[3:]
        rm, R = self.pitch_radius, 0.5 * self.D
        dx, dy = qr[0] - qg[0], qr[1] - qg[1]
        rho2 = dx * dx + dy * dy + _ETA2
        inv_r2 = 1.0 / rho2                     # divisions as products with reciprocals: the dual-number path
        inv_r = 1.0 / ad.sqrt(rho2)             # (which divides so) then rounds as the plain one
        ex, ey = dx * inv_r, dy * inv_r
        s = rm * ad.wrap_angle(ad.arctan2(dy, dx) - qg[2] - self.pocket_angle)
        wx, wy = vr[0] - vg[0], vr[1] - vg[1]
        s_dot = rm * ((dx * wy - dy * wx) * inv_r2 - vg[2])
        v_c = wx * ex + wy * ey
        dw = vr[2] - vg[2]
        el = self.eta * self.length
        N = 0.0
        forces = [0.0] * 6
        shear = 0.0
        for w in (1.0, -1.0):
            h = self.clearance - w * s
            inv_h = 1.0 / ad.where(ad.value(h) > self.min_film, h, self.min_film)
            ue = -0.5 * v_c - (0.5 * w) * R * dw
            du = v_c - w * R * dw
            V = w * s_dot
            # max(V, 0) with the slope 1/2 at V = 0 (the mean of its one-sided slopes: a centred roller's two walls
            # then sum to the smooth law they form there)
            Vp = ad.where(ad.value(V) > 0.0, V, ad.where(ad.value(V) == 0.0, 0.5 * V, 0.0))
            W, cou, poi = gap_film(el, R, inv_h, ue, du, Vp)
            N = N + w * W
            T = cou + poi
            shear = shear + T
            rwx, rwy = -1.0 * w * R * ey, w * R * ex              # P_w − p = w R t
            fr = point_force((rwx, rwy), (T * ex, T * ey))
            fg = point_force((dx + rwx, dy + rwy), (-1.0 * T * ex, -1.0 * T * ey))
            cpl = (w * 2.0) * R * poi
            forces = [forces[0] + fr[0], forces[1] + fr[1], forces[2] + fr[2] + cpl,
                      forces[3] + fg[0], forces[4] + fg[1], forces[5] + fg[2] - cpl]
        # the normal loads in the pocket's potential form: −N ∂s/∂q, ∂s/∂p = r_m (−dy, dx)/ρ², ∂s/∂θ_g = −r_m
        fnx, fny = N * rm * dy * inv_r2, -1.0 * N * rm * dx * inv_r2
        forces = [forces[0] + fnx, forces[1] + fny, forces[2],
                  forces[3] - fnx, forces[4] - fny, forces[5] + N * rm]
        forces = _scaled(forces, self.multiplicity, self._multi)
        gap = self.clearance - np.abs(ad.value(s))
        return forces, {"force": N, "shear": shear, "gap": gap}


class CageDrag(Element):
    """The oil–air mixture's drag on the cage's side faces (module docstring; docs/model.md §8.7): the moment
    M = −coef·sign(Δω)|Δω|^(3/2), Δω = ω_cage − ω_carrier, on the cage and −M on the carrier (first body the
    cage, second the carrier). ``coef`` = 0.616 π √(ρ_e η_e)(r_o⁴ − r_i⁴) [N·m·s^(3/2)] per instance.
    Output: "moment" M on the cage [N·m]."""
    batched = True
    n_local = 6
    compiled_twin = "contact.cage_drag"

    def __init__(self, name, cage, carrier, *, coef):
        self.name = name
        self.dofs = body_dofs(cage, carrier)
        self.coef = self._per_instance("coef", coef, nonneg=True)

    @staticmethod
    def coefficient(rho, eta, r_inner, r_outer):
        """coef of the two faces of an annulus r_inner … r_outer [m] in a fluid of density rho [kg/m³] and
        viscosity eta [Pa·s] (Cochran's free disk)."""
        return DISK_MOMENT * np.sqrt(rho * eta) * (r_outer ** 4 - r_inner ** 4)

    def kernel(self, t, fs, q, v, z):
        dw = v[2] - v[5]
        M = -1.0 * self.coef * ad.sign(dw) * ad.power(ad.abs_(dw), 1.5)
        zero = 0.0 * q[0]
        return [zero, zero, M, zero, zero, -1.0 * M], {"moment": M}
