"""The oil film between a roller and its raceway while their gap is open (docs/model.md §8.9). An opt-in family
beside :class:`mbd.elements.contact.RaceContact` (the Hertz contact, its damping and traction, which carry the roller
once the gap has closed), on the same geometry and the same kinematics (:func:`mbd.elements.contact.race_surfaces`).

The law. A roller of diameter D near a raceway of radius R_race is, across the gap, a cylinder of the contact's
reduced radius R = 1/(2/D + κ/R_race) (κ = +1: convex inner raceway; −1: concave outer raceway) near a plane, over
the roller's length l, at the gap h = −δ (δ the contact's deflection of §8.1: h > 0 while the surfaces are apart).
Reynolds' equation of that gap, rigid surfaces, isoviscous oil of viscosity η, gives the pocket film's laws
(:mod:`mbd.elements.pocket_film`, the one owner of the gap's law, :func:`~mbd.elements.pocket_film.gap_film`, and of
its constants), with the approach speed V = δ̇, the entraining speed ũ = u_e of the race contact (the surfaces' mean
speed along t relative to the moving contact point) and the sliding Δu = v_s (roller surface on raceway surface):

    squeeze load   3√2 π η V l (R/h)^(3/2) on approach (V > 0), none on separation (the film cavitates);
    wedge load     4.895 η |ũ| R l / h (Martin 1916, "Lubrication of gear teeth", Engineering 102, 119–121;
                   h/R = 4.9 U/W' of Hamrock, Schmid & Jacobson, Fundamentals of Fluid Film Lubrication, 2004);
    Couette shear  −COUETTE_EXTENT η Δu l √(2R/h) on the roller at the contact point P along t (raceway: opposite);
    Poiseuille     F_P = POISEUILLE_SHEAR η ũ l √(2R/h) along −t on both surfaces at P, and the pressure's tangential
                   resultant 2F_P along +t through the two centres of curvature, shared by curvature
                   (:func:`mbd.elements.contact.poiseuille_forces`, as the loaded contact's rolling resistance).

The loads are added (an approximation: the Reynolds outlet is a free boundary, so the squeeze and wedge pressures
do not superpose; the sum overstates the combined gap's load by up to 22 % on approach, the wedge alone overstates it
by up to a half on separation: docs/model.md §8.9) and push the roller off the raceway along the line of centres at P;
the race body gets every part reversed at P. ``law`` "squeeze": the squeeze load alone; "full": all four.

The film's hand-over to the loaded contact. The rigid-isoviscous law holds while the film's pressure neither
deflects the surfaces by a fair part of h nor raises the viscosity: the squeeze's peak, 6ηVR/h², is 5.5 MPa at
h = 2 µm and 22 MPa at 1 µm for a roller closing at 0.05 m/s on the reference pin (η = 0.024 Pa·s, R = 3.0 mm), where
the pressure-viscosity e^(αp) (α = 2.2e-8 1/Pa) thickens the oil by 13 % and 62 %, and grows as 1/h². In the last
stage of the approach the pressure flattens the surfaces, traps the oil in the contact and tends to Hertz's profile
(Lee & Cheng 1973, "The pressure and deformation profiles between two colliding lubricated cylinders", J. Lubr.
Technol. 95(3): 308–320, after Christensen's elastohydrodynamic normal approach): the contact is then the loaded EHL
contact, whose stiffness, damping and shear the model's Hertz law and traction carry (§8.1: its damping ratio stands
for the EHL film's damping of the loaded contact, measured and computed by Wijnant 1998 and Wensing 1998 for EHL line
and point contacts, Dietl, Wensing & van Nijen 2000 for whole bearings). So the film acts only while the gap is open,
and across the last film thickness h_f before touch it hands over to the contact by the quintic smoothstep S(h/h_f)
(:func:`mbd.elements.tooth_pairs.damping_share`, zero at h = 0, whole from h ≥ h_f, C² in between): every part is
taken at h_s = max(h, h_f) and times S(h/h_f) for h > 0, and is 0 for h ≤ 0 — continuous in h, V, ũ and Δu (kinks
at V = 0, ũ = 0 and h = h_f).

Range: rigid surfaces and isoviscous oil (gap ≫ the surfaces' elastic deflection under the film's pressure, the
pressure ≪ 1/α of the oil), Newtonian, laminar, a fully flooded gap (an upper bound: the unloaded zone of a
splash-lubricated bearing may run starved), the Reynolds outlet and no side leakage (a long cylinder), h ≪ R (always:
the gaps are micrometres, R millimetres), the roller parallel to its raceway (the planar model; the sliced contact of
§8.8 has no film).
"""
from __future__ import annotations

import numpy as np

from .. import ad
from ..element import Element, body_dofs, marker, marker_velocity, point_force
from ..errors import ModelError
from .contact import _multiplicity, _norm, _scaled, poiseuille_forces, race_surfaces
from .pocket_film import SQUEEZE_LOAD, gap_film
from .tooth_pairs import damping_share

__all__ = ["RaceFilm", "LAWS"]

LAWS = ("squeeze", "full")       # the squeeze film alone; the open gap's squeeze and wedge loads and its shear


class RaceFilm(Element):
    """The raceway film of a roller's open gap (module docstring; docs/model.md §8.9).

    Instances couple a roller (first 3 coordinates) with the body carrying the raceway (last 3), as
    :class:`mbd.elements.contact.RaceContact`: c the raceway centre (``race_marker`` on the race body), ρ = |p − c|,
    e = (p − c)/ρ, t = k × e, δ = D/2 − κ(ρ − R_race), δ̇ = −κ e·(ṗ − ċ), and the contact's v_s and u_e. Gap h = −δ,
    approach speed V = δ̇. "squeeze": W = coef · max(h, h_f)^(−3/2) · S(h/h_f) · max(V, 0) for h > 0 (else 0),
    coef = SQUEEZE_LOAD η l R_red^(3/2), on the roller as κ W e at the contact point P = c + R_race e (through its
    centre), the opposite on the race body at P. "full": S(h/h_f) times the gap's law
    (:func:`mbd.elements.pocket_film.gap_film` at h_s = max(h, h_f), R_red, ũ = u_e, Δu = v_s, max(V, 0)): the load
    W along κe and the Couette shear T along t at P on the roller, the Poiseuille shear F_P with the pressure's
    tangential resultant (:func:`mbd.elements.contact.poiseuille_forces`); the race body the opposite.

    Parameters per instance: kind "inner" | "outer" and law "squeeze" | "full" (family-wide), race_marker (x, y)
    [m], R_race [m], D [m], length l [m], eta η [Pa·s], floor h_f [m] (> 0), multiplicity (identical parallel
    contacts, as the race's).

    Outputs per physical contact: "force" W ≥ 0 [N] (pushing the surfaces apart), "gap" h = −δ [m] (negative: the
    surfaces touch), "approach_speed" V [m/s] (+ when the gap closes); with "full" also "couette" T [N] (on the
    roller along t), "poiseuille" F_P [N], "slip_velocity" v_s and "rolling_speed" u_e [m/s].
    """
    batched = True
    n_local = 6
    compiled_twin = "contact.race_film"

    def __init__(self, name, roller, race_body, *, kind, race_marker, R_race, D, length, eta, floor, law,
                 multiplicity=1):
        self.name = name
        self.dofs = body_dofs(roller, race_body)
        if kind not in ("inner", "outer"):
            raise ModelError(f"{name}: kind must be 'inner' or 'outer', got {kind!r}")
        self.kind = kind
        if law not in LAWS:
            raise ModelError(f"{name}: parameter 'law' must be one of {', '.join(LAWS)}, got {law!r}")
        self.law = law
        self.race_marker = self._per_instance_xy("race_marker", race_marker)
        self.R_race = self._per_instance("R_race", R_race, positive=True)
        self.D = self._per_instance("D", D, positive=True)
        self.length = self._per_instance("length", length, positive=True)
        self.eta = self._per_instance("eta", eta, positive=True)
        self.floor = self._per_instance("floor", floor, positive=True)
        self.kappa = np.full(self.n, 1.0 if kind == "inner" else -1.0)
        if np.any(2.0 / self.D + self.kappa / self.R_race <= 0.0):
            raise ModelError(f"{name}: parameter 'R_race' of an outer raceway must exceed D/2 [m], got {R_race!r}")
        self.R_red = 1.0 / (2.0 / self.D + self.kappa / self.R_race)   # reduced radius: convex inner, concave outer
        self.coef = SQUEEZE_LOAD * self.eta * self.length * self.R_red * np.sqrt(self.R_red)
        self.el = self.eta * self.length
        self.multiplicity = _multiplicity(self, multiplicity)
        self._multi = bool(np.any(self.multiplicity != 1.0))

    _FUSED = ("dofs", "race_marker", "R_race", "D", "length", "eta", "floor", "kappa", "R_red", "coef", "el",
              "multiplicity")

    def fuse_key(self):
        return ("RaceFilm", self.law)

    @classmethod
    def fuse(cls, parts):
        """One family holding the instances of several of one law (inner and outer raceways alike)."""
        f = super().fuse(parts)
        f.kind = None
        f.law = parts[0].law
        f._multi = bool(np.any(f.multiplicity != 1.0))
        return f

    def kernel(self, t, fs, q, v, z):
        qr, qb, vr, vb = q[:3], q[3:], v[:3], v[3:]
        R, kap = self.R_race, self.kappa
        (cx, cy), rc = marker(qb, self.race_marker)
        dx, dy = qr[0] - cx, qr[1] - cy
        rho = _norm(dx, dy)
        ex, ey = dx / rho, dy / rho
        delta = 0.5 * self.D - kap * (rho - R)
        Vc = marker_velocity(vb, rc)
        wx, wy = vr[0] - Vc[0], vr[1] - Vc[1]
        V = -kap * (ex * wx + ey * wy)                    # δ̇: + when the gap closes
        h = -1.0 * delta
        hv = ad.value(h)
        hs = ad.where(hv > self.floor, h, self.floor)     # the film's thickness, floored at h_f (rates kept)
        S = damping_share(ad.where(hv > 0.0, h, 0.0), self.floor)
        if self.law == "full":
            return self._full(vr, vb, rc, Vc, rho, ex, ey, wx, wy, h, hs, S, V)
        c = self.coef * ad.power(hs, -1.5) * S
        W = ad.where((hv > 0.0) & (ad.value(V) > 0.0), c * V, 0.0)
        Fx, Fy = kap * W * ex, kap * W * ey
        # at P = c + R e: through the roller's centre (no moment on it); on the race body the moment of −F at rc + R e,
        # −rc × F (e × F = 0)
        forces = [Fx, Fy, 0.0 * W, -1.0 * Fx, -1.0 * Fy, -1.0 * (rc[0] * Fy - rc[1] * Fx)]
        forces = _scaled(forces, self.multiplicity, self._multi)
        return forces, {"force": W, "gap": h, "approach_speed": V}

    def _full(self, vr, vb, rc, Vc, rho, ex, ey, wx, wy, h, hs, S, V):
        """The open gap's squeeze and wedge loads and its Couette and Poiseuille shear (module docstring), faded by
        S(h/h_f) and none once the surfaces touch (S = 0 for h ≤ 0)."""
        R, kap = self.R_race, self.kappa
        tx, ty = -1.0 * ey, ex
        r_roll, r_race, v_s, u_e = race_surfaces(vr, vb, Vc, rc, ex, ey, tx, ty, rho, R, wx, wy)
        Vp = ad.where(ad.value(V) > 0.0, V, 0.0)
        Wg, Tg, Pg = gap_film(self.el, self.R_red, 1.0 / hs, u_e, v_s, Vp)
        W, T, FP = S * Wg, S * Tg, S * Pg
        # the load along κe and the Couette shear along t at P on the roller, the opposite on the race body; the
        # Poiseuille shear at P with the pressure's tangential resultant through the centres (as §9.5's)
        Fx, Fy = kap * W * ex + T * tx, kap * W * ey + T * ty
        forces = point_force(r_roll, (Fx, Fy)) + point_force(r_race, (-1.0 * Fx, -1.0 * Fy))
        forces = [a + b for a, b in zip(forces, poiseuille_forces(FP, rho, tx, ty, rc, R))]
        forces = _scaled(forces, self.multiplicity, self._multi)
        return forces, {"force": W, "gap": h, "approach_speed": V, "couette": T, "poiseuille": FP,
                        "slip_velocity": v_s, "rolling_speed": u_e}
