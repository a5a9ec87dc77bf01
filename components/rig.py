"""A planet bearing alone on a test rig (docs/model.md §10.5, check §15.4), and its quasi-static post-processing.

Scene: a pin fixed to ground (the inner raceway), an outer ring (the "planet": the outer raceway),
Z rollers and a cage between them (:func:`components.bearing.add_planet_bearing`). A radial load F_r,
fixed in the inertial frame, pulls the outer ring (ramped in smoothly); a speed drive holds the ring's
spin at ``outer_speed`` (0: a held ring). Everything is in the inertial frame.

Where the load goes: the ring is pulled along u = (cos a, sin a) (a = ``load_angle``), so it closes
the radial gap on the *opposite* side of the pin: the loaded rollers sit around the direction −u seen
from the pin centre (the *load-zone centre*), and they press the pin along u. Roller angles below are
measured from that load-zone centre. ``discrete_load_distribution`` gives the classical (Stribeck /
Sjövall) answer for the same discrete roller set: Q_max·Z/F_r ≈ 4.08 at zero clearance for a line
contact (4.083 for Z = 12 with a roller on the load line), larger with clearance.

``run_sampled`` integrates a model and returns the states at given times (used here and by tests).
"""
from __future__ import annotations

import dataclasses
import time
from dataclasses import dataclass

import numpy as np
from scipy import optimize

import mbd
from mbd.ad import wrap_angle
from mbd.compile_time import compile_seconds
from mbd.elements import ForceSource, GroundSupport, Ramp, SpeedDrive
from mbd.elements.tilt import CoordinateSpring
from mbd.static import SteadyMotion, carry, solve_static

from .bearing import BearingHandles, add_planet_bearing
from .families import FAMILY
from .outputs import pin_reactions
from .params import BearingParams, BearingRigParams, BearingRigSI, BearingSI, LubricantParams, LubricantSI
from .presets import reference_bearing_rig
from .scene import BuiltScene, Scene, SceneOptions
from .units import ParameterError

__all__ = ["build_bearing_rig", "check_rig_pin", "BearingRigScene", "rig_options", "run_sampled", "rig_loads", "rig_quasi_static",
           "RigSolution",
           "rig_static_solution", "discrete_load_distribution", "DiscreteDistribution"]


# ----------------------------------------------------------------------------------------------
# classical reference
# ----------------------------------------------------------------------------------------------
@dataclass(frozen=True)
class DiscreteDistribution:
    """Quasi-static load distribution of a rigid-ring bearing with discrete rollers (no centrifugal
    force, no traction): ring displacement ``deflection`` along the load [m] (and ``sideways``,
    perpendicular to it, non-zero only for a roller set that is not symmetric about the load line),
    roller loads ``loads`` [N] at ``angles`` [rad, from the load-zone centre]."""
    deflection: float
    sideways: float
    angles: np.ndarray
    loads: np.ndarray
    radial_load: float
    clearance: float
    rows: int = 1

    @property
    def q_max(self) -> float:
        return float(self.loads.max())

    @property
    def stribeck(self) -> float:
        """Q_max·Z/F_r of one row (its share F_r/rows; ≈ 4.08 at zero clearance, as :class:`RigSolution`'s)."""
        return self.q_max * self.loads.size * self.rows / self.radial_load

    @property
    def zone_angle(self) -> float:
        """Full angle of the continuous load zone for this deflection and clearance [rad]."""
        return _zone_angle(self.deflection, self.clearance)


def _zone_angle(deflection: float, clearance: float) -> float:
    """Full angle 2ψ_l of the continuous load zone: roller compression δ_r cos ψ − P_d/2 > 0."""
    if deflection <= 0.5 * clearance:
        return 0.0
    return 2.0 * float(np.arccos(0.5 * clearance / deflection))


def discrete_load_distribution(b: BearingSI, radial_load: float, angles=None) -> DiscreteDistribution:
    """Classical reference: rigid rings, the rollers at ``angles`` [rad] from the load-zone centre
    (default: one roller on the load line, Z equally spaced), contacts Q = K δ^p (Palmgren: p = 10/9, the
    bearing's contact_exponent) at both raceways in series (equal loads: Q = K (δ/2)^p for a total
    compression δ), diametral clearance P_d. ``b``: ``BearingParams.si()``. Solves the ring's equilibrium
    F_r = rows·Σ Q_j cos ψ_j (and Σ Q_j sin ψ_j = 0 with a sideways shift): ``loads`` are per physical
    roller, each of the ``b.rows`` identical rows carrying F_r/rows."""
    F = float(radial_load)
    if not (np.isfinite(F) and F > 0):
        raise ParameterError.at("radial_load", f"must be > 0 N for a load distribution, got {radial_load!r}")
    F_total, F = F, F / b.rows
    Z, p = b.rollers, b.contact_exponent
    psi = 2 * np.pi * np.arange(Z) / Z if angles is None else np.asarray(angles, float)
    c, s = np.cos(psi), np.sin(psi)
    K2 = b.contact_stiffness * 2.0 ** (-p)
    half = 0.5 * b.clearance

    def loads(d):   # d = (along the load, sideways): compression δ_r cos ψ + d_s sin ψ − P_d/2
        comp = d[0] * c + d[1] * s - half
        return K2 * np.where(comp > 0, np.abs(comp), 0.0) ** p

    # 1-D solve (symmetric set) as the start, then the 2-D equilibrium
    f1 = lambda x: np.sum(loads((x, 0.0)) * c) - F
    hi = half + 1e-6
    while f1(hi) < 0:
        hi *= 2.0
    d0 = optimize.brentq(f1, half, hi, xtol=1e-16, rtol=1e-14)
    # scaled unknowns (d / d0) and residuals (/ F): hybr's default tolerances then mean what they say
    sol = optimize.root(lambda x: [np.sum(loads(x * d0) * c) / F - 1.0, np.sum(loads(x * d0) * s) / F],
                        [1.0, 0.0], method="hybr", options={"xtol": 1e-13})
    # hybr may stop "not making good progress" when it sits on the root to round-off: accept that
    if not sol.success and np.max(np.abs(sol.fun)) > 1e-12:
        raise RuntimeError(f"discrete_load_distribution: no equilibrium found ({sol.message})")
    d = sol.x * d0
    return DiscreteDistribution(float(d[0]), float(d[1]), psi, loads(d), F_total, float(b.clearance), b.rows)


# ----------------------------------------------------------------------------------------------
# the scene
# ----------------------------------------------------------------------------------------------
@dataclass(frozen=True, eq=False, kw_only=True)
class BearingRigScene(BuiltScene):
    """The built bearing rig (:func:`build_bearing_rig`)."""
    bearing_handles: BearingHandles       # what :func:`~components.bearing.add_planet_bearing` added
    ring: str                             # the outer ring's body name
    pin: str                              # the fixed pin's body name
    bearing: BearingSI
    options: SceneOptions                 # the resolved switches the rig was built with
    radial_load: float                    # F_r [N]
    load_angle: float                     # direction of the load on the ring [rad, fixed frame]
    zone_angle: float                     # direction of the load-zone centre [rad]
    outer_speed: float                    # the ring's spin [rad/s]
    ramp: float                           # duration of the load ramp [s]
    period: float                         # period of the ring's radial mode on the loaded bearing [s]
    t_settle: float                       # a suggested start of the averaging window [s]
    radial_stiffness: float               # dF/dδ_r of the classical solution [N/m] (0 unloaded)
    reference: DiscreteDistribution | None    # the classical load distribution (None unloaded)
    pin_slope: np.ndarray = dataclasses.field(default_factory=lambda: np.zeros(2))   # the pin's slope [rad], fixed
                                                                                     # frame (the sliced model)

    @property
    def fold(self) -> int:
        """Physical rollers one roller body stands for: ``bearing.rows`` in the planar model (its rows folded into
        one), 1 in the sliced model (every row built)."""
        return self.bearing.rows // self.bearing_handles.rows


def build_bearing_rig(bearing, *, radial_load: float, load_angle: float = -0.5 * np.pi, outer_speed: float = 0.0,
                      options: SceneOptions | None = None, lubricant=None,
                      rig: BearingRigParams | None = None, misalignment: float = 0.0,
                      misalignment_direction="radial") -> BearingRigScene:
    """A bearing between a fixed pin and a loaded outer ring (SI arguments).

    ``bearing``: :class:`~components.params.BearingParams` or its SI object (``.si()``); ``lubricant`` a
    LubricantParams (or its SI object), or None for no lubricant drag. ``radial_load`` F_r ≥ 0 [N] on
    the outer ring along ``load_angle`` [rad, fixed frame; default downwards]. ``outer_speed`` [rad/s]
    the ring's spin, held by a speed drive. ``rig``: the ring, its drive, the load ramp and the settling
    dashpot (:class:`~components.params.BearingRigParams`; default
    :func:`components.presets.reference_bearing_rig`). ``options``: the scene switches, see
    :func:`rig_options` (cage "free": guided by the outer ring, "held": a fixed body, the rollers cannot
    orbit, "none").

    Rig aids [assumed], neither changes the static solution: the load is ramped over
    ``rig.load_ramp_periods`` periods of the ring's radial mode on the loaded bearing, and a dashpot
    from the ring to ground with ``rig.settle_damping_ratio`` of that mode's critical damping lets it
    settle (the Hertz contacts alone damp the ring very little).

    With ``bearing.model = "sliced"`` (docs/model.md §8.8, §10.5) the ring gets a slope pair (diametral inertia
    ``rig.ring_tilt_inertia``, gyroscopic terms with its spin) held at zero by the housing's support
    (``rig.tilt_support_stiffness``, its dashpot ``rig.settle_damping_ratio`` of the tilt mode's critical damping),
    and the pin's axis is sloped by ``misalignment`` γ [rad] against it, in ``misalignment_direction``: "radial"
    (along the load on the ring, the load plane), "tangential" (90° ahead of it) or an angle [rad] in the fixed
    frame — the tilted bearing under a radial load that ISO/TS 16281 covers. The planar model refuses a
    misalignment.

    Returns a :class:`BearingRigScene`.
    """
    b, lub, rs = _rig_inputs(bearing, lubricant, rig)
    _check_bearing(b)
    check_rig_pin(b)
    F = _finite("radial_load", radial_load, nonneg=True)
    a = _finite("load_angle", load_angle)
    w = _finite("outer_speed", outer_speed)
    gamma = _finite("misalignment", misalignment)
    if gamma != 0.0 and b.model != "sliced":
        raise ParameterError.at("misalignment", "a tilted rig bearing needs bearing.model = 'sliced' (the planar "
                                                "model has no slopes)")
    if isinstance(misalignment_direction, str):
        if misalignment_direction not in ("radial", "tangential"):
            raise ParameterError.at("misalignment_direction", f"expected 'radial', 'tangential' or an angle [rad], "
                                                              f"got {misalignment_direction!r}")
        beta = a + (0.0 if misalignment_direction == "radial" else 0.5 * np.pi)
    else:
        beta = _finite("misalignment_direction", misalignment_direction)
    pin_slope = gamma * np.array([np.cos(beta), np.sin(beta)])
    opt = rig_options(options, has_lubricant=lub is not None)
    scene = Scene(frame_omega=0.0, gravity=rs.gravity if opt.gravity else 0.0, options=opt)
    scene.body("pin", 1.0, 1.0, fixed=True)
    scene.body("ring", rs.ring_mass, rs.ring_inertia, vel=(0.0, 0.0, w))
    h = add_planet_bearing(scene, "pb", pin_body="pin", pin_local=(0.0, 0.0), outer_body="ring", bearing=b,
                           lubricant=lub, pin_xy=(0.0, 0.0), pin_vel=(0.0, 0.0), omega_pin=0.0, omega_outer=w,
                           damage={}, bore_tilt_inertia=rs.ring_tilt_inertia, bore_spin_inertia=rs.ring_inertia,
                           pin_slope=pin_slope)   # the rig's bearing is perfect
    if b.model == "sliced":         # the housing holds the ring's slope at zero: the pin's slope is the tilt
        k_t = rs.tilt_support_stiffness
        c_t = 2.0 * rs.settle_damping_ratio * np.sqrt(k_t * rs.ring_tilt_inertia)
        scene.add_late_element(lambda sc: CoordinateSpring("ring_tilt_support", list(sc.slope_index["ring"]),
                                                           k=k_t, c=c_t))
    # radial mode of the ring on the loaded bearing (stiffness dF/dδ_r of the classical solution)
    if F > 0:
        ref = discrete_load_distribution(b, F, _roller_angles_from_zone(b.rollers, a))
        k_r = _radial_stiffness(b, F, a)
        period = 2 * np.pi * np.sqrt(rs.ring_mass / k_r)
    else:
        ref, k_r, period = None, 0.0, 1e-3       # unloaded: no mode, a nominal time scale for the meta
    ramp = rs.load_ramp_periods * period
    u = np.array([np.cos(a), np.sin(a)])
    scene.add_element(ForceSource("radial_load", [scene.index["ring"]], F * u, ramp=Ramp(0.0, ramp)))
    wd = 2 * np.pi * rs.drive_bandwidth
    scene.add_element(SpeedDrive("ring_drive", scene.index["ring"], w, k=rs.ring_inertia * wd**2,
                                 c=2 * rs.drive_damping_ratio * rs.ring_inertia * wd))
    c_settle = 2.0 * rs.settle_damping_ratio * np.sqrt(k_r * rs.ring_mass)
    if c_settle > 0:
        scene.add_element(GroundSupport("ring_damper", [scene.index["ring"]], kx=0.0, cx=c_settle))
    return scene.build(BearingRigScene, bearing_handles=h, ring="ring", pin="pin", bearing=b, options=opt,
                       radial_load=F, load_angle=a, zone_angle=a + np.pi, outer_speed=w, ramp=ramp, period=period,
                       t_settle=ramp + 10.0 * period, radial_stiffness=k_r, reference=ref,
                       pin_slope=pin_slope)


def rig_options(options: SceneOptions | None, has_lubricant: bool) -> SceneOptions:
    """The rig's scene switches: the given ones, else the rig's own (frame "fixed", bearings "rollers",
    cage "free", gravity off, drag when there is a lubricant). A given switch the rig cannot honour is
    refused, never replaced: frame must be "fixed", bearings "rollers", drag needs a lubricant."""
    opt = options or SceneOptions()
    given = opt.given()
    needs = {"frame": "fixed", "bearings": "rollers"}
    for key, value in needs.items():
        if given.get(key, value) != value:
            raise ParameterError.at(f"options.{key}", f"the bearing rig needs {value!r}, got {given[key]!r}")
    if given.get("drag") and not has_lubricant:
        raise ParameterError.at("options.drag", "lubricant drag needs a lubricant: pass lubricant=LubricantParams")
    return opt.resolved(**needs, cage="free", gravity=False, drag=has_lubricant)


def _rig_inputs(bearing, lubricant, rig) -> tuple[BearingSI, LubricantSI | None, BearingRigSI]:
    """SI objects of the bearing, the lubricant (None: no drag) and the rig parameters."""
    if isinstance(bearing, BearingParams):
        bearing = bearing.si()
    if not isinstance(bearing, BearingSI):
        raise ParameterError.at("bearing", f"expected BearingParams or BearingSI, got {type(bearing).__name__}")
    if isinstance(lubricant, LubricantParams):
        lubricant = lubricant.si()
    if lubricant is not None and not isinstance(lubricant, LubricantSI):
        raise ParameterError.at("lubricant", f"expected LubricantParams or None, got {type(lubricant).__name__}")
    if rig is None:
        rig = reference_bearing_rig()
    if not isinstance(rig, BearingRigParams):
        raise ParameterError.at("rig", f"expected BearingRigParams, got {type(rig).__name__}")
    return bearing, lubricant, rig.si()


def check_rig_pin(b) -> None:
    """Refuse an elastic pin (``bearing.pin.model = "elastic"``, ``b`` the bearing's parameters or SI object): the
    rig's pin is a fixed body, so a bending pin would be silently rigid here."""
    if b.pin.model != "rigid":
        raise ParameterError.at("bearing.pin.model", f"the bearing rig's pin is fixed (rigid): expected 'rigid', got "
                                                     f"{b.pin.model!r}")


def _check_bearing(b: BearingSI) -> None:
    """The fit checks of :func:`components.geometry.design_findings` that concern the bearing alone."""
    Z, D, d_m = b.rollers, b.roller_diameter, b.pitch_diameter
    if Z < 3:     # an SI object may have been replaced by hand: no check ran on it
        raise ParameterError.at("bearing.rollers", f"must be >= 3, got {Z}")
    if not D < d_m:
        raise ParameterError.at("bearing.roller_diameter", f"{D * 1e3:g} mm leaves no pin inside the pitch "
                                                           f"diameter {d_m * 1e3:g} mm")
    chord = d_m * np.sin(np.pi / Z)
    if chord <= D:
        raise ParameterError.at("bearing.rollers", f"{Z} rollers of {D * 1e3:g} mm do not fit on the "
                                                   f"{d_m * 1e3:g} mm pitch circle (centre spacing {chord * 1e3:.3f} mm)")
    if b.clearance < 0:
        raise ParameterError.at("bearing.clearance", f"must be >= 0, got {b.clearance!r} m")


def _finite(name, value, positive=False, nonneg=False) -> float:
    try:
        x = float(value)
    except (TypeError, ValueError):
        raise ParameterError.at(name, f"expected a finite number (SI units), got {value!r}") from None
    if not np.isfinite(x) or (positive and x <= 0) or (nonneg and x < 0):
        cond = "> 0" if positive else ">= 0" if nonneg else "finite"
        raise ParameterError.at(name, f"must be {cond}, got {value!r}")
    return x


def _roller_angles_from_zone(Z: int, load_angle: float) -> np.ndarray:
    """Initial roller angles (roller j at 2πj/Z from +x) measured from the load-zone centre."""
    return wrap_angle(2 * np.pi * np.arange(Z) / Z - (load_angle + np.pi))


def _radial_stiffness(b: BearingSI, F: float, a: float) -> float:
    """dF_r/dδ_r of the classical solution (central difference)."""
    ang = _roller_angles_from_zone(b.rollers, a)
    d1 = discrete_load_distribution(b, 0.99 * F, ang).deflection
    d2 = discrete_load_distribution(b, 1.01 * F, ang).deflection
    return 0.02 * F / (d2 - d1)


# ----------------------------------------------------------------------------------------------
# running and post-processing
# ----------------------------------------------------------------------------------------------
def run_sampled(model: mbd.Model, q0, v0, times, *, controller, stepper: mbd.HHT | None = None,
                system: mbd.System | None = None, t0: float = 0.0, state: mbd.State | None = None,
                results: list | None = None) -> list[mbd.State]:
    """Integrate from (t0, q0, v0) (or ``state``) and return copies of the states at ``times`` (ascending);
    each piece's :class:`mbd.SimResult` is appended to ``results`` when given (run time, error estimate).

    The run is split at the sample times (steps end exactly on them, no interpolation); an
    :class:`mbd.Adaptive` controller continues each piece from the largest step of the previous one."""
    system = system or mbd.System(model)
    stepper = stepper or mbd.PRODUCTION.stepper()
    if state is None:
        state = stepper.initial_state(system, t0, q0, v0)
    out = []
    for t in np.asarray(times, float):
        if t > state.t:
            res = mbd.simulate(model, t_end=float(t), state=state, stepper=stepper, controller=controller,
                               system=system, progress=False)
            state = res.state
            if results is not None:
                results.append(res)
            if isinstance(controller, mbd.Adaptive) and res.steps:
                controller = dataclasses.replace(controller, h0=float(np.clip(res.h_max_used, controller.h_min,
                                                                                 controller.h_max)))
        out.append(state.copy())
    return out


def rig_loads(built: BearingRigScene, system: mbd.System, s: mbd.State) -> dict:
    """Instantaneous roller loads of the rig at state ``s``: inner- and outer-raceway loads (Z,) [N],
    roller angles from the load-zone centre (Z,) [rad], the ring centre (2,) [m], and the vector sums
    (2,) [N, fixed frame] of the inner normal loads pressing the pin, Σ Q_j·(−e_j), and of the whole
    contact forces (normal + traction) the rollers exert on the pin and on the ring. Loads are per physical
    roller; the sums count every row. The sliced model (docs/model.md §8.8) adds, its rollers row by row,
    ``slices_inner`` and ``slices_outer`` (rows, Z, n_s) the slice loads [N], ``tilt`` (rows, Z) the rollers' tilts
    [rad] and ``ring_slope`` (2,) the ring's slope [rad, fixed frame]."""
    m = built.model
    out = system.outputs(s.t, s.q, s.v, s.z)
    h = built.bearing_handles
    si, so = h.race_inner, h.race_outer
    inner, outer = out[FAMILY["race_inner"]], out[FAMILY["race_outer"]]
    ang = inner["angle"][si]                            # about the pin (fixed, θ = 0): fixed-frame angle
    e = np.column_stack([np.cos(ang), np.sin(ang)])
    qf, _ = m.full(s.t, s.q, s.v)
    ring = qf[3 * m.body(built.ring).index: 3 * m.body(built.ring).index + 2]
    Qi, Qo = inner["load"][si], outer["load"][so]
    rows = built.fold
    rec = {
        "t": s.t, "angle": wrap_angle(ang - built.zone_angle), "load_inner": Qi, "load_outer": Qo,
        "ring": ring.copy(),
        "load_sum": -rows * (Qi[:, None] * e).sum(axis=0),
        "pin_force": pin_reactions(inner, si, np.zeros(si.stop - si.start, int), 1, rows)[0],
        "ring_force": rows * np.array([outer["fx"][so].sum(), outer["fy"][so].sum()]),   # −(force on ring)
    }
    if "max_slice_load" in inner:
        shape = (h.rows, built.bearing.rollers, -1)
        for key, o, sl in (("slices_inner", inner, si), ("slices_outer", outer, so)):
            n_s = sum(1 for k in o if k.startswith("slice_load_"))
            rec[key] = np.stack([np.asarray(o[f"slice_load_{k}"])[sl] for k in range(n_s)], axis=-1).reshape(shape)
        rec["tilt"] = np.asarray(inner["tilt"])[si].reshape(shape[:2])
        rec["ring_slope"] = qf[_slope_indices(built)]
    return rec


def rig_quasi_static(built: BearingRigScene, times=None, engine: str = "auto", system: mbd.System | None = None,
                     hold_tilt: bool = True, length_tol: float | None = None):
    """The rig's quasi-static states (:func:`mbd.static.solve_static`, docs/model.md §10.5, §16) at ``times`` [s]
    (default: the end of the load ramp, the load at its full value), each started from the last: every roller keeps
    its pocket's centre (it moves along its radius only, as ISO/TS 16281's rollers do), its radius, tilt and spin
    rate solved; a free cage's rate with its rollers' orbits; the ring's translation. Held: the ring's angle (its speed
    drive supplies the torque) and, in the sliced model, the ring's slope at its given zero (the tilting moment is the
    housing's reaction; ``hold_tilt=False`` solves it against the housing's support instead, as a dynamic run sees
    it). ``length_tol`` [m]: the static solver's (:func:`mbd.static.solve_static`; None: its default). Returns the
    :class:`mbd.static.StaticSolution` list; :func:`rig_loads` reads each. A turning ring's unloaded
    rollers have no traction and so no static spin rate: the ring at rest (the standard's case) always has a state."""
    m, h = built.model, built.bearing_handles
    system = system if system is not None else mbd.System(m)
    times = [built.ramp] if times is None else [float(t) for t in times]
    orbit = np.zeros(m.n_bodies)
    host = np.full(m.n_bodies, -1)
    circles = {}
    idx = [m.body(r).index for r in h.rollers]
    cage = m.body(h.cage).index if h.cage is not None else -1
    cage_free = cage >= 0 and not m.fixed[cage]
    for i in idx:
        if h.omega_cage != 0.0:
            orbit[i] = h.omega_cage
            if cage_free:
                host[i] = cage
        else:
            circles[i] = (0.0, 0.0)            # the pin's centre: the rollers rest on their radial lines
    motion = SteadyMotion.from_state(m, built.q0, built.v0, orbit, host, circles=circles)
    full = [3 * m.body(built.ring).index + 2]
    if built.bearing.model == "sliced" and hold_tilt:
        full += [int(i) for i in _slope_indices(built)]
    hold = m.full_to_free[full]
    rates = ([(cage, idx if h.omega_cage != 0.0 else [])] if cage_free else []) + [(i, []) for i in idx]
    # the first start: the ring displaced by the classical deflection (the contacts near the zone's centre closed;
    # from the kinematic pose a profiled roller touches nowhere and nothing resists the load)
    q_first = np.asarray(built.q0, float).copy()
    if built.reference is not None:
        k = 3 * m.body(built.ring).index
        q_first[m.full_to_free[[k, k + 1]]] += built.reference.deflection * np.array([np.cos(built.load_angle),
                                                                                      np.sin(built.load_angle)])
    out = []
    for t in times:
        start = carry(m, motion, out[-1], t, rates) if out else (q_first, None)
        tol = {} if length_tol is None else {"length_tol": float(length_tol)}
        out.append(solve_static(m, motion, t, hold=hold[hold >= 0], rates=rates, q_start=start[0],
                                rates_start=start[1], system=system, engine=engine, **tol))
    return out


def _slope_indices(built: BearingRigScene) -> np.ndarray:
    """Full indices of the ring's slope pair (its support's coordinates)."""
    sup = [e for e in built.model.elements if e.name == "ring_tilt_support"][0]
    return np.asarray(sup.dofs).ravel()


@dataclass(frozen=True)
class RigSolution:
    """Time means over the window [t0, t1] of a bearing rig run.

    ``angles`` (Z,) roller angles from the load-zone centre [rad] (mean angle of the rollers found in
    each of Z equal bins centred on the load-zone centre + 2πk/Z: orbiting rollers are binned by where
    they are, rollers at rest are their own bins), ``loads`` (Z,) mean inner-raceway load in each bin
    [N], ``loads_outer`` the same at the outer raceway; ``q_max`` the largest; ``stribeck`` = Q_max·Z/F_r;
    ``zone_angle`` full angular extent of the loaded bins (from the first to the last bin whose mean load
    exceeds ``zone_tol``·Q_max) [rad]; ``zone_angle_continuous`` = 2 arccos(P_d/(2 δ_r)), the load zone of
    the continuous theory for the measured deflection; ``deflection`` δ_r mean ring-centre displacement
    along the load [m], ``sideways`` perpendicular to it; ``load_sum`` (2,) mean Σ Q_j(−e_j) on the pin;
    ``pin_force``, ``ring_force`` (2,) mean total contact forces (normal + traction) of the rollers on the
    pin and (negated) on the ring; ``radial_load`` F_r [N] and ``load_vector`` (2,) the applied load."""
    t0: float
    t1: float
    samples: int
    angles: np.ndarray
    loads: np.ndarray
    loads_outer: np.ndarray
    q_max: float
    stribeck: float
    zone_angle: float
    zone_angle_continuous: float
    deflection: float
    sideways: float
    load_sum: np.ndarray
    pin_force: np.ndarray
    ring_force: np.ndarray
    radial_load: float
    load_vector: np.ndarray
    wall_s: float
    zone_tol: float = 1e-3
    steps: int = 0
    error_rms: float = float("nan")   # HHT local error estimate over the accepted steps, in units of atol
    error_max: float = float("nan")
    runs: tuple = ()                  # the mbd.SimResult of each piece (which engine ran, its counters)
    compile_s: float = 0.0            # compiling or loading the kernels [s], left out of wall_s
    loads_rows: np.ndarray | None = None   # (rows, Z) mean pin loads per row and bin [N] (the sliced model's rows)

    def summary(self) -> dict:
        return {"radial_load_N": self.radial_load, "q_max_N": self.q_max, "stribeck": self.stribeck,
                "zone_angle_deg": np.degrees(self.zone_angle),
                "zone_angle_continuous_deg": np.degrees(self.zone_angle_continuous),
                "deflection_um": self.deflection * 1e6, "load_sum_N": self.load_sum.tolist(), "wall_s": self.wall_s}


def rig_static_solution(built: BearingRigScene, *, t_settle: float | None = None, window: float | None = None,
                        samples: int = 40, controller=None, stepper: mbd.HHT | None = None,
                        zone_tol: float = 1e-3) -> RigSolution:
    """Run the rig built by :func:`build_bearing_rig` past the load ramp and average over a window.

    Defaults: t_settle = ``built.t_settle``, window = 10 periods of the ring's radial mode, ``samples``
    equally spaced samples in it; ``controller`` Adaptive (h0 = 1 µs, h_max = period/20)."""
    F, a, Z = built.radial_load, built.load_angle, built.bearing.rollers
    t_settle = built.t_settle if t_settle is None else float(t_settle)
    window = 10.0 * built.period if window is None else float(window)
    if controller is None:
        controller = mbd.Adaptive(h0=1e-6, h_max=built.period / 20.0)
    times = t_settle + window * np.arange(samples) / max(samples - 1, 1)
    system = mbd.System(built.model)
    w0, c0 = time.perf_counter(), compile_seconds()
    pieces = []
    states = run_sampled(built.model, built.q0, built.v0, times, controller=controller, stepper=stepper, system=system,
                         results=pieces)
    compile_s = compile_seconds() - c0          # the kernels' compile or load: timed where it happens, taken out
    wall = time.perf_counter() - w0 - compile_s
    steps = sum(r.steps for r in pieces)
    err_rms = float(np.sqrt(sum(r.error_rms ** 2 * r.steps for r in pieces) / max(steps, 1)))
    recs = [rig_loads(built, system, s) for s in states]
    # bin by angle from the load-zone centre (bin k centred on 2πk/Z)
    ang = np.array([r["angle"] for r in recs])                       # (samples, Z)
    k = np.mod(np.round(ang * Z / (2 * np.pi)).astype(int), Z)
    Qi = np.array([r["load_inner"] for r in recs])
    Qo = np.array([r["load_outer"] for r in recs])
    n, rows = len(recs), built.bearing_handles.rows        # explicit rows (sliced model): a bin's mean over them
    loads = np.bincount(k.ravel(), weights=Qi.ravel(), minlength=Z) / (n * rows)
    loads_o = np.bincount(k.ravel(), weights=Qo.ravel(), minlength=Z) / (n * rows)
    row = np.broadcast_to(np.repeat(np.arange(rows), Z), k.shape)
    loads_rows = np.bincount((row * Z + k).ravel(), weights=Qi.ravel(), minlength=rows * Z).reshape(rows, Z) / n
    # mean angle of each bin's occupants, relative to the bin centre (no wrap problems)
    centre = 2 * np.pi * np.arange(Z) / Z
    rel = wrap_angle(ang - centre[k])
    cnt = np.bincount(k.ravel(), minlength=Z)
    angles = wrap_angle(centre + np.bincount(k.ravel(), weights=rel.ravel(), minlength=Z) / np.maximum(cnt, 1))
    order = np.argsort(angles)
    angles, loads, loads_o, loads_rows = angles[order], loads[order], loads_o[order], loads_rows[:, order]
    q_max = float(loads.max())
    loaded = angles[loads > zone_tol * q_max] if q_max > 0 else np.array([])
    zone = float(loaded.max() - loaded.min()) if loaded.size else 0.0
    u = np.array([np.cos(a), np.sin(a)])
    ring = np.array([r["ring"] for r in recs]).mean(axis=0)
    defl = float(ring @ u)
    side = float(ring @ np.array([-u[1], u[0]]))
    mean = lambda key: np.array([r[key] for r in recs]).mean(axis=0)
    return RigSolution(t0=float(times[0]), t1=float(times[-1]), samples=n, angles=angles, loads=loads,
                       loads_rows=loads_rows,
                       loads_outer=loads_o, q_max=q_max,
                       stribeck=q_max * Z * built.bearing.rows / F if F > 0 else float("nan"),
                       zone_angle=zone, zone_angle_continuous=_zone_angle(defl, built.bearing.clearance),
                       deflection=defl, sideways=side, load_sum=mean("load_sum"), pin_force=mean("pin_force"),
                       ring_force=mean("ring_force"), radial_load=F, load_vector=F * u, wall_s=wall, compile_s=compile_s,
                       zone_tol=zone_tol, steps=steps, error_rms=err_rms,
                       error_max=max((r.error_max for r in pieces), default=0.0), runs=tuple(pieces))
