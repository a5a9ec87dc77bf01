"""The rig's accelerometer on the housing as transfer paths (docs/model.md §12).

The sensor sits on the housing at angle ψ_s of the fixed frame, at distance r_s from the gear axis, and
reads along its axis e (radial at ψ_s, or tangential 90° ahead). What it reads is the sum of three paths,
each with physical parameters (:class:`components.params.SensorParams`, ``rig.sensor.*``):

* **mesh** — the local ring-mesh path: a = Σ_n w(ψ_n − ψ_s)·(F̃_n·e)/m_eq, each outer planet's ring-mesh
  force on the ring weighted by a Hann window of its angular distance from the sensor (McFadden & Smith
  1985; Inalpolat & Kahraman 2009): the ring's local vibration under a passing planet. F̃_n is the force's
  vibration: the force less its mean over the run, the mean taken in the planet's own radial and tangential
  directions (it turns with the planet). a = F/m_eq is the ring's response above its local modes; the steady
  load deflects the ring where the planet is, and that deflection passing the sensor reads ω²·F/k_local —
  (N f_c / f_local)² of F/m_eq, 4·10⁻⁴ for planets passing at 100 Hz and a local mode at 5 kHz —, so it is
  left out rather than read as F/m_eq (which would put a 200 m/s² line at 3 f_c into the rig machine's spectrum). Only
  the steady part is: the force's slow fluctuations at carrier orders still read as F/m_eq, overstated below the
  ring's local modes — the path is for the lines near f_m.
* **torque** — the housing's rocking: the ring's torsional support puts the reaction torque M = −T_r on
  the housing (T_r: the support's torque on the ring). The sun's and carrier's supports are centred,
  isotropic translational springs (no torsional part): their forces pass through the axis (to within
  the bodies' µm deflections, neglected) and put no moment about it. The drives' reaction torques go to
  the motors on their own foundations, not into the gearbox housing. A gearbox on feet rocks about its
  mounting's elastic centre O, a depth h below the axis (the foot plane): a rigid-body mode J_O θ̈ +
  c θ̇ + k θ = M, and the sensor reads θ̈·(k × (r_s − r_O))·e. Hence a radial sensor does see rocking —
  except on the vertical through O (ψ_s = ±90°), where the rocking moves the housing horizontally only.
* **bearing** — what the sun's and carrier's bearings and the ring's seat transmit to the housing:
  F = −Σ (support forces on sun, carrier, ring), in the fixed frame. It drives the housing's translation
  m_h ẍ + c ẋ + k x = F (x and y alike), read as ẍ·e, and, since F acts at the axis and not at O, its
  rocking with the moment (r_axis − r_O) × F = −h F_x, read like the torque path. The ring's seat force
  belongs here with the bearings': together they are the whole force the train puts on the housing.

This replaces the previous sensor's second term, the carrier's own acceleration: the carrier is a body
*inside* the housing, on its bearing (1e8 N/m: a 570 Hz mode with its 7.75 kg). Above that mode the
carrier moves much more than anything it shakes — the housing feels only the force its bearing
transmits, which the bearing path carries through the housing's own mass and mounting.

One-way coupling: the housing is ground in the simulation (its µm motion does not act back on the
train), so the sensor changes nothing in the machine's dynamics; it is computed afterwards from the
recorded loads (:class:`HousingLoads`, recorded with ``RunConfig(sensor=True)``). Each mode is integrated
exactly for loads linear between samples (first-order hold, :func:`scipy.signal.lsim`), starting at rest
at the static deflection of the first sample's load: a constant load reads zero from the first sample,
and only the dynamic part at the first sample starts a free vibration, which decays as e^(−ζ ω_n t)
(time constants 5 ms for the rocking at 630 Hz, 3.2 ms for the translation at 1 kHz, ζ = 0.05) and sits
under the spectrum's Hann taper (w ≤ 0.03 over the first 5 ms of a 90 ms window): starting instead from the
load's mean over the mode's first period changes the rig machine's lines by < 1e-10 (measured).
"""
from __future__ import annotations

import math

import numpy as np

import mbd
from mbd.ad import wrap_angle

from .families import FAMILY
from .params import HousingSI, SensorSI

__all__ = ["PATHS", "hann_window", "sensor_axis", "rocking_lever", "mesh_path", "vibration", "mode_acceleration",
           "housing_paths", "paths", "HousingLoads", "sensor_from_dict"]

PATHS = ("mesh", "torque", "bearing")   # their sum is the housing sensor


def hann_window(dpsi, width: float) -> np.ndarray:
    """Weight of a planet at angular distance ``dpsi`` [rad] from the sensor: cos²(π Δ/width) for
    |Δ| < width/2 (Δ wrapped to (−π, π]), 0 beyond. 1 at the sensor; value and slope are continuous
    everywhere (a Hann window of full width ``width``, McFadden 1994), so a passing planet fades in and out."""
    d = wrap_angle(np.asarray(dpsi, float))
    return np.where(np.abs(d) < 0.5 * width, np.cos(np.pi * d / width) ** 2, 0.0)


def sensor_axis(sensor) -> np.ndarray:
    """The sensor's axis e in the fixed frame: radial at ψ_s, or tangential (90° ahead)."""
    a = sensor.angle + (0.0 if sensor.direction == "radial" else 0.5 * math.pi)
    return np.array([math.cos(a), math.sin(a)])


def rocking_lever(sensor) -> float:
    """(k × (r_s − r_O))·e [m]: the sensor's acceleration along its axis per unit rocking acceleration of the
    housing about O = (0, −h) (h = ``housing.rocking_centre_depth``), the sensor at r_s = r_s(cos ψ_s, sin ψ_s).
    0 for a radial sensor on the vertical through O (ψ_s = ±90°: cos ψ_s is round-off there, and so is the
    lever it gives)."""
    e = sensor_axis(sensor)
    dx = sensor.radius * math.cos(sensor.angle)
    dy = sensor.radius * math.sin(sensor.angle) + sensor.housing.rocking_centre_depth
    lever = -dy * e[0] + dx * e[1]
    return 0.0 if abs(lever) <= 1e-12 * math.hypot(dx, dy) else float(lever)


def mesh_path(psi_planets, ring_force, sensor) -> np.ndarray:
    """The local ring-mesh path Σ_n w(ψ_n − ψ_s)·(F_n·e)/m_eq [m/s²], broadcasting over leading (sample) axes.

    ``psi_planets`` (..., N): outer planets' angles in the fixed frame [rad]; ``ring_force`` (..., N, 2): each
    one's ring-mesh force on the ring in the fixed frame [N]; ``sensor``: :class:`components.params.SensorSI`."""
    w = hann_window(np.asarray(psi_planets, float) - sensor.angle, sensor.window_width)
    along = np.asarray(ring_force, float) @ sensor_axis(sensor)
    return (w * along).sum(axis=-1) / sensor.equivalent_mass


def vibration(psi_planets, ring_force) -> np.ndarray:
    """Each planet's ring-mesh force less its mean over the samples (axis 0), the mean taken in the planet's own
    radial and tangential directions at ψ_n (module docstring: the mesh path reads the vibration).

    ``psi_planets`` (n, N) [rad], ``ring_force`` (n, N, 2) [N], both in the fixed frame; returns (n, N, 2)."""
    psi, F = np.asarray(psi_planets, float), np.asarray(ring_force, float)
    c, s = np.cos(psi), np.sin(psi)
    radial, tangential = F[..., 0] * c + F[..., 1] * s, -F[..., 0] * s + F[..., 1] * c
    radial, tangential = radial - radial.mean(axis=0), tangential - tangential.mean(axis=0)
    return np.stack([radial * c - tangential * s, radial * s + tangential * c], axis=-1)


def mode_acceleration(t, load, inertia: float, frequency: float, damping_ratio: float) -> np.ndarray:
    """ẍ of m ẍ + c ẋ + k x = load(t), m = ``inertia`` (a mass or a moment of inertia), k = m ω_n²,
    c = 2ζ m ω_n (ω_n = 2π ``frequency``), the load sampled at the equally spaced times ``t``: exact for a
    load linear between samples (first-order hold), from rest at the static deflection load(t_0)/k."""
    load = np.asarray(load, float)
    wn = 2.0 * math.pi * frequency
    k, c = wn * wn, 2.0 * damping_ratio * wn                       # per unit inertia
    mode = (np.array([[0.0, 1.0], [-k, -c]]), np.array([[0.0], [1.0 / inertia]]), np.array([[-k, -c]]),
            np.array([[1.0 / inertia]]))
    from scipy import signal  # deferred: scipy.signal (≈ 0.5 s, with scipy.stats) only for a housing response

    return signal.lsim(mode, load, np.asarray(t, float), X0=[load[0] / (inertia * k), 0.0], interp=True)[1]


def housing_paths(t, force, torque, sensor) -> dict[str, np.ndarray]:
    """The torque and bearing paths [m/s²] from what the train puts on the housing, sampled at ``t``:
    ``force`` (n, 2) the net support force on the housing in the fixed frame [N], ``torque`` (n,) the net
    torque on it [N·m] (module docstring)."""
    h = sensor.housing
    force, torque = np.asarray(force, float), np.asarray(torque, float)
    lever, e = rocking_lever(sensor), sensor_axis(sensor)
    rock = lambda moment: lever * mode_acceleration(t, moment, h.rocking_inertia, h.rocking_frequency,
                                                    h.rocking_damping_ratio)
    shift = lambda f: mode_acceleration(t, f, h.mass, h.translation_frequency, h.translation_damping_ratio)
    # the forces act at the axis, a depth h above O: their moment about O is (0, h) × F = −h F_x
    bearing = shift(force[:, 0]) * e[0] + shift(force[:, 1]) * e[1] + rock(-h.rocking_centre_depth * force[:, 0])
    return {"torque": rock(torque), "bearing": bearing}


def paths(t, psi_planets, ring_force, force, torque, sensor) -> dict[str, np.ndarray]:
    """Every path of the housing sensor and their sum ("mesh", "torque", "bearing", "housing") [m/s²] from
    a run's samples (arguments as :func:`mesh_path` and :func:`housing_paths`); the mesh path of the ring-mesh
    forces' vibration (:func:`vibration`)."""
    out = {"mesh": mesh_path(psi_planets, vibration(psi_planets, ring_force), sensor),
           **housing_paths(t, force, torque, sensor)}
    out["housing"] = out["mesh"] + out["torque"] + out["bearing"]
    return out


def sensor_from_dict(d: dict):
    """A :class:`components.params.SensorSI` from its ``to_dict()`` (as a run stores it in results.nc)."""
    return SensorSI(**{**d, "housing": HousingSI(**d["housing"])})


class HousingLoads:
    """What the train puts on the housing at a recorded sample, in the fixed frame: minus each ground
    support's force and torque on its body (sun and carrier bearings, the ring's seat and torsional
    support). Recorded as ``housing.force_x``, ``housing.force_y`` [N] and ``housing.torque`` [N m] along
    ``<name>.instance`` (the supported bodies) by :meth:`probes`."""

    def __init__(self, scene):
        model = scene.model
        self.frame = model.frame
        sup = model.element(FAMILY["support"])
        self.bodies = tuple(model.body_names[int(i)] for i in sup.dofs[:, 0] // 3)

    def loads(self, t, outputs) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(F_X, F_Y, M) on the housing from each support [N, N, N m], fixed frame."""
        o = outputs[FAMILY["support"]]
        phi = self.frame.at(t).phi
        c, s = math.cos(phi), math.sin(phi)
        fx, fy = np.asarray(o["fx"], float), np.asarray(o["fy"], float)
        return -(c * fx - s * fy), -(s * fx + c * fy), -np.asarray(o["torque"], float)

    def probes(self) -> list[mbd.DerivedOutput]:
        words = "on the housing from the support of this body (minus the support's {} on it), fixed frame"
        return [mbd.DerivedOutput(f"housing.{key}", lambda t, X, V, A, outs, j=j: self.loads(t, outs)[j], unit,
                                  f"{name} {words.format(what)}", instances=self.bodies)
                for j, (key, unit, name, what) in enumerate((("force_x", "N", "force X", "force"),
                                                             ("force_y", "N", "force Y", "force"),
                                                             ("torque", "N m", "torque", "torque")))]
