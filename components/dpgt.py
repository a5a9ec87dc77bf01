"""The double planetary gear train (DPGT) on the source's rig.

Bodies: sun, ring, carrier, N inner planets a_n, N outer planets b_n, and per planet a bearing (Z
rollers + cage, or a linear spring). Meshes: sun–a_n, a_n–b_n (external), b_n–ring (internal).
Rig (docs/model.md §10.3): sun driven by the torque P/|ω_s| along ω_s, carrier held at the reference speed
by a speed drive, ring fixed through stiff supports. Reverse rotation flips every speed.
The initial state is the kinematic steady state (docs/model.md §10.4); the sun torque is ramped in.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from mbd.elements import BeamSupport, GroundSupport, Ramp, Schedule, SlopeGyroscopic, SpeedDrive, TorqueSource

from . import faults, pins, teeth
from .bearing import BearingHandles, add_planet_bearing
from .gears import add_mesh_family
from .geometry import check_design, loaded_flanks
from .families import FAMILY, MESH_FAMILY
from .params import BearingSI, CarrierRippleParams, DPGTParams, LubricantSI
from .scene import BuiltScene, Scene, SceneOptions
from .units import ParameterError

__all__ = ["build_dpgt", "DPGTScene", "PlanetBearingScene", "Speeds", "PairHandles", "carrier_ripple", "schedules"]


@dataclass(frozen=True)
class PairHandles:
    """One planet pair of the DPGT: the planets' body names, their angles ψ on the carrier [rad] and
    what their bearings added (:attr:`PlanetBearingScene.pairs` holds one per pair)."""
    inner: str
    outer: str
    psi_a: float
    psi_b: float
    inner_bearing: BearingHandles
    outer_bearing: BearingHandles

    def planet(self, kind: str) -> str:
        """The inner or outer planet's body name."""
        return self.inner if kind == "inner" else self.outer

    def bearing(self, kind: str) -> BearingHandles:
        return self.inner_bearing if kind == "inner" else self.outer_bearing


@dataclass(frozen=True)
class Speeds:
    """The kinematic steady state's absolute spin speeds [rad/s] (fixed frame; reverse rotation: all negative)."""
    sun: float
    inner_planet: float
    outer_planet: float
    carrier: float

    def planet(self, kind: str) -> float:
        """The inner or outer planet's speed."""
        if kind not in ("inner", "outer"):
            raise ValueError(f"planet kind must be 'inner' or 'outer', got {kind!r}")
        return self.inner_planet if kind == "inner" else self.outer_planet

    def to_dict(self) -> dict[str, float]:
        return {"sun": self.sun, "inner_planet": self.inner_planet, "outer_planet": self.outer_planet,
                "carrier": self.carrier}


@dataclass(frozen=True, eq=False, kw_only=True)
class PlanetBearingScene(BuiltScene):
    """Planet bearings on a carrier, what the statistics and results read (:mod:`components.statistics`,
    :mod:`components.results.schema`, :mod:`components.static`): the DPGT, or a rig of planet bearings."""
    pairs: tuple[PairHandles, ...]
    speeds: Speeds
    bearing: BearingSI
    lubricant: LubricantSI | None         # None: no film statistics or outputs
    flanks: dict[str, int]                # loaded flank (+1/−1) per mesh type (:data:`MESH_FAMILY` keys); {} without meshes
    sun_torque: float                     # [N·m]; 0: the train transmits no torque (no nominal mesh load)


@dataclass(frozen=True, eq=False, kw_only=True)
class DPGTScene(PlanetBearingScene):
    """The built DPGT (:func:`build_dpgt`) with what its runner, statistics and studies read."""
    options: SceneOptions                 # the resolved switches the scene was built with
    direction: str                        # "forward" | "reverse"
    f_m: float                            # mesh frequency [Hz]
    f_c: float                            # carrier rotation frequency |f_c| [Hz]
    carrier_torque: float                 # [N·m]
    ramp: float                           # duration of the sun torque's ramp [s]
    ring_mismatch: tuple[float, ...]      # planets' ring-mesh phase mismatch [teeth]

    @property
    def planets(self) -> int:
        return len(self.pairs)

    @property
    def rollers(self) -> int:
        return int(self.bearing.rollers)

    def run_metadata(self) -> dict:
        """What results.nc keeps as its ``meta`` attribute (JSON; read back by :mod:`viz.results`)."""
        return {"speeds_rad_s": self.speeds.to_dict(), "f_c_hz": self.f_c, "f_m_hz": self.f_m,
                "sun_torque_Nm": self.sun_torque, "carrier_torque_Nm": self.carrier_torque, "ramp_s": self.ramp,
                "ring_mismatch_teeth": list(self.ring_mismatch), "planets": self.planets, "rollers": self.rollers,
                "direction": self.direction, "frame": self.options.frame, "bearings": self.options.bearings}


def _bearing_damage(si, planet: str, psi: float) -> dict:
    """Roller diameters and raceway spalls of one planet's bearing ({} for a perfect one)."""
    if not (si.errors.roller_diameter or si.errors.spall):
        return {}
    return dict(D=faults.roller_diameters(si, planet), inner=faults.spall_args(si, planet, "inner", psi),
                outer=faults.spall_args(si, planet, "outer", psi))


def carrier_ripple(ripple, wc: float) -> list[tuple[float, float, float]] | None:
    """The carrier drive's speed-ripple harmonics (k ω_c, A_k, φ_k) of the orders with A_k > 0 (None without
    any: the drive then runs its constant-speed reference unchanged). ``ripple``: a CarrierRippleSI."""
    orders = [k for k in CarrierRippleParams.ORDERS if getattr(ripple, f"amplitude_{k}") > 0.0]
    if orders and wc == 0.0:
        raise ParameterError.at(f"rig.carrier_ripple.amplitude_{orders[0]}",
                                "must be 0 rad/s with the carrier at rest (its orders of f_c = 0 Hz)")
    return [(k * wc, getattr(ripple, f"amplitude_{k}"), getattr(ripple, f"phase_{k}")) for k in orders] or None


def schedules(op) -> tuple[Schedule | None, Schedule | None]:
    """The operating point's schedule (``operating.schedule``, an OperatingSI's) as the carrier speed's and the sun
    torque's factors of time, (None, None) without one (docs/model.md §10.3)."""
    if not op.schedule:
        return None, None
    t = [k.time for k in op.schedule]
    return Schedule(t, [k.speed for k in op.schedule]), Schedule(t, [k.torque for k in op.schedule])


def planet_tilt_inertia(gear) -> float:
    """A planet's diametral moment of inertia [kg·m²] about its centre, from its polar one as a hollow cylinder of
    its face width b: J_d = J_p/2 + m b²/12 (J_p = m (r_o² + r_i²)/2)."""
    return 0.5 * gear.inertia + gear.mass * gear.face_width ** 2 / 12.0


def _beam_dofs(cat, scene):
    """The pin beams' arguments: carrier and pin bodies, and each pin's slope pair (known at build)."""
    idx = lambda names: np.array([scene.index[str(nm)] for nm in names], np.int64)     # noqa: E731
    pins_ = [str(x) for x in cat.pop("pin")]
    return dict(body_a=idx(cat.pop("carrier")), body_b=idx(pins_),
                slopes=np.array([scene.slope_index[nm] for nm in pins_], np.int64), **cat)


def _pin_gyro_dofs(cat, scene):
    names = [str(x) for x in cat.pop("body")]
    return dict(spin=np.array([3 * scene.index[nm] + 2 for nm in names], np.int64),
                slopes=np.array([scene.slope_index[nm] for nm in names], np.int64), **cat)


def add_elastic_pin(scene: Scene, planet: str, pin_xy, pin_vel, wc: float, b: BearingSI, span: float):
    """``planet``'s pin as an elastic beam (``bearing.pin.model = "elastic"``, docs/model.md §8.8): a body
    ``<planet>.pin`` at the pin's centre turning with the carrier, with a slope pair and its gyroscopic terms, held by
    the carrier at its pinhole on the beam's condensed stiffness (:func:`components.pins.pin_stiffness`,
    :class:`mbd.elements.tilt.BeamSupport`), damped at ``bearing.pin.damping_ratio`` of each coordinate's critical.
    Returns (the pin body, the raceway centre in its axes)."""
    name = f"{planet}.pin"
    inert = pins.pin_inertias(b, span)
    k = pins.pin_stiffness(b, span)
    z = b.pin.damping_ratio
    scene.body(name, inert["mass"], inert["polar"], pose=(*pin_xy, 0.0), vel=(*pin_vel, wc))
    scene.slopes(name, inert["diametral"])
    scene.family(FAMILY["pin_gyroscopic"], SlopeGyroscopic, (), resolve=_pin_gyro_dofs).add(
        1, body=[name], polar_inertia=inert["polar"])
    scene.family(FAMILY["pin_beam"], BeamSupport, (), resolve=_beam_dofs).add(
        1, carrier=["carrier"], pin=[name], marker_a=np.asarray(pin_xy, float)[None, :], **k,
        c_u=2 * z * np.sqrt(k["k_uu"] * inert["mass"]), c_s=2 * z * np.sqrt(k["k_ss"] * inert["diametral"]),
        c_theta=2 * z * np.sqrt(k["k_theta"] * inert["polar"]))
    return name, (0.0, 0.0)


def build_dpgt(params: DPGTParams, options: SceneOptions | None = None, strict: bool = True) -> DPGTScene:
    """Build the DPGT scene. Design errors raise ParameterError; design warnings are issued."""
    opt = (options or SceneOptions()).resolved()
    if opt.cage == "held":   # a cage fixed to the carrier would need a joint the engine does not have
        raise ParameterError.at("options.cage", "'held' is a bearing-rig option; the DPGT takes 'free' or 'none'")
    check_design(params, strict=strict)
    si = params.si()
    faults.check_errors(si)
    if si.bearing.model == "planar" and (faults.pin_slopes(si) or si.gears.carrier_windup):
        what = ("errors.pin_slope" if si.errors.pin_slope else "errors.pinhole_ends" if faults.pin_slopes(si)
                else "gears.carrier_windup")
        why = "a pinhole's two ends differ, so its pin slopes: " if what == "errors.pinhole_ends" else ""
        raise ParameterError.at(what, why + "a pin slope is seen only by the sliced bearing model: set "
                                            "bearing.model = 'sliced'")
    lay = si.layout
    G, op, sup, ms = si.gears, si.operating, si.support, si.mesh
    wc = op.carrier_speed
    speed = {"sun": op.sun_speed, "a": op.inner_planet_speed, "b": op.outer_planet_speed}
    b = si.bearing
    scene = Scene(frame_omega=wc if opt.frame == "rotating" else 0.0,
                  gravity=si.gravity if opt.gravity else 0.0, options=opt)
    N = lay.planets
    ph = lay.phasing
    scene.body("sun", G.sun.mass, G.sun.inertia, vel=(0, 0, speed["sun"]))
    scene.body("ring", G.ring.mass, G.ring.inertia, pose=(0, 0, ph.gamma_ring))
    elastic_pins = b.model == "sliced" and b.pin.model == "elastic"
    if si.bearing.pin.model == "elastic" and b.model == "planar":
        raise ParameterError.at("bearing.pin.model", "an elastic pin is seen only by the sliced bearing model: set "
                                                     "bearing.model = 'sliced'")
    m_c, J_c = G.carrier_mass, G.carrier_inertia
    if elastic_pins:        # the pins become bodies of their own: their mass and inertia leave the carrier's
        pin_in = pins.pin_inertias(b, G.carrier_plate_span)
        r2 = np.sum(np.asarray(lay.centres_a) ** 2) + np.sum(np.asarray(lay.centres_b) ** 2)
        m_c = m_c - 2 * lay.planets * pin_in["mass"]
        J_c = J_c - 2 * lay.planets * pin_in["polar"] - pin_in["mass"] * r2
        if not (m_c > 0.0 and J_c > 0.0):
            raise ParameterError.at("bearing.pin.density", f"the elastic pins' mass and inertia exceed the carrier's "
                                                           f"(gears.carrier_mass {G.carrier_mass:g} kg)")
    scene.body("carrier", m_c, J_c, vel=(0, 0, wc))
    sup_f = scene.family(FAMILY["support"], GroundSupport, ("bodies",))
    for name, k, m, J in (("sun", sup.sun_stiffness, G.sun.mass, G.sun.inertia),
                          ("ring", sup.ring_stiffness, G.ring.mass, G.ring.inertia),
                          ("carrier", sup.carrier_stiffness, G.carrier_mass, G.carrier_inertia)):
        kt = sup.ring_torsional_stiffness if name == "ring" else 0.0
        sup_f.add(1, bodies=[name], kx=k, cx=2 * sup.damping_ratio * np.sqrt(k * m), k_theta=kt,
                  c_theta=2 * sup.damping_ratio * np.sqrt(kt * J), theta0=ph.gamma_ring if name == "ring" else 0.0)

    pairs = []
    a_names = [f"a{n + 1}" for n in range(N)]
    b_names = [f"b{n + 1}" for n in range(N)]
    for n in range(N):
        # pins (and the planets on them) where the carrier's pinholes really are (errors.pinhole, pinhole_ends)
        pa, pb = faults.pin_position(si, a_names[n], lay.centres_a[n]), faults.pin_position(si, b_names[n], lay.centres_b[n])
        va, vb = wc * np.array([-pa[1], pa[0]]), wc * np.array([-pb[1], pb[0]])
        scene.body(a_names[n], G.inner_planet.mass, G.inner_planet.inertia, pose=(*pa, ph.gamma_inner[n]), vel=(*va, speed["a"]))
        scene.body(b_names[n], G.outer_planet.mass, G.outer_planet.inertia, pose=(*pb, ph.gamma_outer[n]), vel=(*vb, speed["b"]))
        tilt = {} if b.model == "planar" else {
            planet: dict(bore_tilt_inertia=planet_tilt_inertia(gear), bore_spin_inertia=gear.inertia,
                         pin_slope=faults.pin_slope(si, planet, c))
            for planet, gear, c in ((a_names[n], G.inner_planet, lay.centres_a[n]),
                                    (b_names[n], G.outer_planet, lay.centres_b[n]))}
        held = {planet: (add_elastic_pin(scene, planet, p, v, wc, b, G.carrier_plate_span) if elastic_pins
                         else ("carrier", p))
                for planet, p, v in ((a_names[n], pa, va), (b_names[n], pb, vb))}
        bearings = [add_planet_bearing(scene, f"{planet}.pb", pin_body=held[planet][0], pin_local=held[planet][1],
                                       outer_body=planet, bearing=b, lubricant=si.lubricant, pin_xy=p, pin_vel=v,
                                       omega_pin=wc, omega_outer=w, damage=_bearing_damage(si, planet, psi),
                                       **tilt.get(planet, {}))
                    for planet, p, v, w, psi in ((a_names[n], pa, va, speed["a"], lay.psi_a[n]),
                                                 (b_names[n], pb, vb, speed["b"], lay.psi_b[n]))]
        pairs.append(PairHandles(a_names[n], b_names[n], float(lay.psi_a[n]), float(lay.psi_b[n]), *bearings))

    # meshes, phased for the flank the torque path loads (reverse rotation loads the other flanks)
    T_s = op.sun_torque
    flanks = loaded_flanks(np.sign(T_s) if T_s != 0 else np.sign(speed["sun"]))
    tooth_pairs = teeth.has_teeth(si)       # real teeth: the tooth-pair law (perfect ones: its exact reduction)
    common = dict(time_varying=opt.mesh_stiffness == "time_varying", smoothing=ms.smoothing_width,
                  ratio=ms.stiffness_ratio, damping_ramp=ms.damping_ramp)
    M = lay.meshes
    for key, g1, g2, th1, th2 in (("sun_inner", ["sun"] * N, a_names, np.zeros(N), ph.gamma_inner),
                                  ("inner_outer", a_names, b_names, ph.gamma_inner, ph.gamma_outer),
                                  ("outer_ring", b_names, ["ring"] * N, ph.gamma_outer, np.full(N, ph.gamma_ring))):
        add_mesh_family(scene, MESH_FAMILY[key], M[key], gear1=g1, gear2=g2, theta1_0=th1, theta2_0=th2,
                        flank=flanks[key], errors=faults.mesh_error_args(si, g1, g2),
                        pairs=teeth.mesh_pairs(si, M[key], g1, g2) if tooth_pairs else None,
                        face_slices=ms.face_slices if b.model == "sliced" else None, **common)

    # drives: sun torque (driving motor), carrier speed drive (loading motor)
    f_m = op.mesh_frequency
    rig = si.rig
    ramp_t = min(rig.load_ramp_mesh_periods / f_m, rig.load_ramp_max) if f_m > 0 else 0.0
    speed_f, torque_f = schedules(op)
    if speed_f is not None and wc == 0.0 and len(set(speed_f.values)) > 1:
        raise ParameterError.at("operating.schedule", "a speed schedule needs operating.carrier_speed > 0 rpm "
                                                      "(its speeds are fractions of it)")
    if speed_f is not None and carrier_ripple(rig.carrier_ripple, wc):
        raise ParameterError.at("operating.schedule", "a schedule cannot be combined with rig.carrier_ripple "
                                                      "(its orders are of the constant carrier speed)")
    if T_s != 0:
        scene.add_element(TorqueSource("sun_torque", [scene.index["sun"]], T_s, ramp=Ramp(0.0, ramp_t),
                                       schedule=torque_f))
    # inertia the drive sees: every speed of the kinematic state scales with ω_c (ring fixed), so
    # J_eff = 2T/ω_c² over all bodies (carrier, sun reflected, planets orbiting and spinning, rollers, cages);
    # a carrier at rest has no kinematic scaling: then the carrier plus the planets' orbital inertia
    if wc != 0.0:
        J_eff = scene.kinematic_inertia(wc)
    else:
        J_eff = G.carrier_inertia + N * (G.inner_planet.mass * lay.r_ca**2 + G.outer_planet.mass * lay.r_cb**2)
    wd = 2 * np.pi * rig.carrier_drive_bandwidth
    scene.add_element(SpeedDrive("carrier_drive", scene.index["carrier"], wc, k=J_eff * wd**2,
                                 c=2 * rig.carrier_drive_damping_ratio * J_eff * wd, k_i=J_eff * wd**3 / 5,
                                 ripple=carrier_ripple(rig.carrier_ripple, wc), schedule=speed_f))
    if speed_f is not None:      # the run starts on the kinematic state at the schedule's first speed
        scene.scale_velocities(speed_f(0.0))
    return scene.build(DPGTScene, pairs=tuple(pairs), flanks=flanks, lubricant=si.lubricant, bearing=b, options=opt,
                       speeds=Speeds(sun=speed["sun"], inner_planet=speed["a"], outer_planet=speed["b"], carrier=wc),
                       f_c=abs(op.carrier_frequency), f_m=f_m, sun_torque=T_s, carrier_torque=op.carrier_torque,
                       ramp=ramp_t, ring_mismatch=tuple(float(x) for x in ph.ring_mismatch), direction=op.direction)
