"""The squeeze film of the oil between a roller and its raceway while their gap is open (docs/model.md §8.9). An
opt-in family beside :class:`mbd.elements.contact.RaceContact` (the Hertz contact and its damping, which carry the
roller once the gap has closed), on the same geometry.

The law. A roller of diameter D near a raceway of radius R_race is, across the gap, a cylinder of the contact's
reduced radius R = 1/(2/D + κ/R_race) (κ = +1: convex inner raceway; −1: concave outer raceway) near a plane, over
the roller's length l. With the gap h = −δ (δ the contact's deflection of §8.1: h > 0 while the surfaces are apart)
and the approach speed V = −dh/dt = δ̇, Reynolds' equation of a rigid cylinder approaching a plane in isoviscous
oil of viscosity η, p = 0 far from the gap, gives the squeeze load (the pocket film's law, whose one owner is
:data:`mbd.elements.pocket_film.SQUEEZE_LOAD`):

    w = 3√2 π η V l (R/h)^(3/2)                 on approach (V > 0); none on separation (V ≤ 0: the film cavitates
                                                 and cannot pull).

The film's hand-over to the loaded contact. The rigid-isoviscous law holds while the film's pressure neither
deflects the surfaces by a fair part of h nor raises the viscosity: its peak, 6ηVR/h², is 5.5 MPa at h = 2 µm and
22 MPa at 1 µm for a roller closing at 0.05 m/s on the reference pin (η = 0.024 Pa·s, R = 3.0 mm), where the
pressure-viscosity e^(αp) (α = 2.2e-8 1/Pa) thickens the oil by 13 % and 62 %, and grows as 1/h². In the last stage of the approach the
pressure flattens the surfaces, traps the oil in the contact and tends to Hertz's profile (Lee & Cheng 1973, "The
pressure and deformation profiles between two colliding lubricated cylinders", J. Lubr. Technol. 95(3): 308–320,
after Christensen's elastohydrodynamic normal approach): the contact is then the loaded EHL contact, whose
stiffness and damping the model's Hertz law carries (§8.1: its damping ratio stands for the EHL film's damping of the
loaded contact, measured and computed by Wijnant 1998 and Wensing 1998 for EHL line and point contacts, Dietl,
Wensing & van Nijen 2000 for whole bearings). So the squeeze acts only while the gap is open, and across the last
film thickness h_f before touch its coefficient hands over to the contact by the quintic smoothstep S(h/h_f)
(:func:`mbd.elements.tooth_pairs.damping_share`, zero at h = 0, whole from h ≥ h_f, C² in between): with
c(h) = 3√2 π η l R^(3/2) · max(h, h_f)^(−3/2),

    W = c(h) · S(h/h_f) · max(V, 0)   for h > 0,   0 for h ≤ 0 (the surfaces touch: the Hertz contact carries),

continuous in h and V (a kink at V = 0 and at h = h_f, as the pocket film's floor). It pushes the roller off the
raceway along the line of centres at the contact point (as the Hertz load; the race body the opposite).

Range: rigid surfaces and isoviscous oil (gap ≫ the surfaces' elastic deflection under the film's pressure, the
pressure ≪ 1/α of the oil), Newtonian, laminar, a fully flooded gap (an upper bound: the unloaded zone of a
splash-lubricated bearing may run starved), h ≪ R (always: the gaps are micrometres, R millimetres), the
roller parallel to its raceway (the planar model; the sliced contact of §8.8 has no film). The squeeze film only: a
roller rolling a few micrometres off its raceway also carries the open gap's wedge load (Martin's 4.9 η u R l/h, the
pocket film's WEDGE_LOAD: ≈ 11 N at h = 1 µm on the pin at condition 1's entraining speed of 3.4 m/s, the order of the few newtons
that hold an unloaded roller on its bore) and is dragged by the gap's Couette and Poiseuille shear, as the pocket
film's roller is; neither is modelled here.
"""
from __future__ import annotations

import numpy as np

from .. import ad
from ..element import Element, body_dofs, marker, marker_velocity
from ..errors import ModelError
from .contact import _multiplicity, _norm, _scaled
from .pocket_film import SQUEEZE_LOAD
from .tooth_pairs import damping_share

__all__ = ["RaceFilm"]


class RaceFilm(Element):
    """The raceway squeeze film of a roller (module docstring; docs/model.md §8.9).

    Instances couple a roller (first 3 coordinates) with the body carrying the raceway (last 3), as
    :class:`mbd.elements.contact.RaceContact`: c the raceway centre (``race_marker`` on the race body), ρ = |p − c|,
    e = (p − c)/ρ, δ = D/2 − κ(ρ − R_race), δ̇ = −κ e·(ṗ − ċ). Gap h = −δ, approach speed V = δ̇; the load
    W = coef · max(h, h_f)^(−3/2) · S(h/h_f) · max(V, 0) for h > 0 (else 0), coef = SQUEEZE_LOAD η l R_red^(3/2),
    acts on the roller as κ W e at the contact point P = c + R_race e (through the roller's centre), the opposite on
    the race body at P.

    Parameters per instance: kind "inner" | "outer" (family-wide), race_marker (x, y) [m], R_race [m], D [m],
    length l [m], eta η [Pa·s], floor h_f [m] (> 0), multiplicity (identical parallel contacts, as the race's).

    Outputs per physical contact: "force" W ≥ 0 [N] (pushing the surfaces apart), "gap" h = −δ [m] (negative: the
    surfaces touch), "approach_speed" V [m/s] (+ when the gap closes).
    """
    batched = True
    n_local = 6
    compiled_twin = "contact.race_film"

    def __init__(self, name, roller, race_body, *, kind, race_marker, R_race, D, length, eta, floor, multiplicity=1):
        self.name = name
        self.dofs = body_dofs(roller, race_body)
        if kind not in ("inner", "outer"):
            raise ModelError(f"{name}: kind must be 'inner' or 'outer', got {kind!r}")
        self.kind = kind
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
        self.multiplicity = _multiplicity(self, multiplicity)
        self._multi = bool(np.any(self.multiplicity != 1.0))

    _FUSED = ("dofs", "race_marker", "R_race", "D", "length", "eta", "floor", "kappa", "R_red", "coef",
              "multiplicity")

    def fuse_key(self):
        return ("RaceFilm",)

    @classmethod
    def fuse(cls, parts):
        """One family holding the instances of several (inner and outer raceways alike)."""
        f = super().fuse(parts)
        f.kind = None
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
        c = self.coef * ad.power(hs, -1.5) * S
        W = ad.where((hv > 0.0) & (ad.value(V) > 0.0), c * V, 0.0)
        Fx, Fy = kap * W * ex, kap * W * ey
        # at P = c + R e: through the roller's centre (no moment on it); on the race body the moment of −F at rc + R e,
        # −rc × F (e × F = 0)
        forces = [Fx, Fy, 0.0 * W, -1.0 * Fx, -1.0 * Fy, -1.0 * (rc[0] * Fy - rc[1] * Fx)]
        forces = _scaled(forces, self.multiplicity, self._multi)
        return forces, {"force": W, "gap": h, "approach_speed": V}
