"""A single planetary gear set (sun, ring, carrier, N planets) for modal analysis — the lumped-parameter
model of the literature (Lin & Parker 1999) built from this project's elements.

Bodies: sun, ring, carrier (each with an isotropic translational support and a torsional spring to
ground) and N equally spaced planets p1..pN. Each planet sits on a linear bearing: a
:class:`mbd.elements.BodySpring` from the carrier's pin marker (at the planet centre radius) to the planet
centre. Meshes: sun–planet (external) and planet–ring (internal) :class:`mbd.elements.GearMesh` families
with constant stiffness and zero backlash. Nothing turns (inertial frame, no gravity).

Loaded flank. A zero-backlash two-flank mesh at its nominal state has both flanks just touching, with
zero force: its stiffness there is a kink, and the Jacobian (strict δ > 0 gating) is zero. The modal
model of the literature linearises each mesh on the flank the torque path loads — a spring along that
flank's line of action. :func:`modal_state` gives such a state: the sun and the ring are turned by
ε/r_b (ε = ``preload``, 1 nm by default) so that every mesh is compressed by ε on its loaded flank and
opened by ε on the other. The Jacobian there is exactly k·∇δ_f∇δ_fᵀ plus geometric terms of order
k·ε/a (≈ 10⁻⁸ of k), i.e. the loaded-flank linearisation, with no change to the model itself.
The loaded flanks for a sun torque of sign s (ring held): sun–planet flank s, planet–ring flank s
(the planet's spin balance needs the ring mesh to push back on the same flank sense).

The TOML format (all values pint strings; see :func:`planetary_spec`)::

    kind = "single_planetary"
    planets = 3
    module = "3 mm"
    pressure_angle = "20 deg"
    teeth = { sun = 30, planet = 30, ring = 90 }
    mesh_stiffness = { sun_planet = "5e8 N/m", ring_planet = "5e8 N/m" }
    [sun]                       # [ring] and [carrier]: the same keys
    mass = "1 kg"
    inertia = "1e-3 kg*m^2"
    support_stiffness = "1e8 N/m"
    torsional_stiffness = "0 N*m/rad"
    [planet]
    mass = "0.5 kg"
    inertia = "3e-4 kg*m^2"
    bearing_stiffness = "1e8 N/m"

Optional top-level keys: ``planet_angle`` (angle of planet 1, default "0 deg") and
``mesh_damping_ratio`` (ζ_m, default 0: mesh damping 2ζ_m·sqrt(k m_eq)).
"""
from __future__ import annotations

import math
import tomllib
import warnings
from dataclasses import dataclass
from pathlib import Path
from types import MappingProxyType
from typing import Mapping

import numpy as np

import mbd
from mbd.elements import BodySpring, GearMesh, GroundSupport
from mbd.elements.gear_mesh import mesh_u0

from .geometry import DesignWarning, mesh_damping
from .scene import BuiltScene, Scene, SceneOptions
from .units import ParameterError, quantity, to_si
from .names import did_you_mean

__all__ = ["EXAMPLE_PLANETARY", "MemberSpec", "PlanetarySpec", "planetary_spec", "load_planetary_toml",
           "build_single_planetary", "PlanetaryScene", "modal_state", "planetary_modes", "classify_modes", "PlanetaryModes",
           "CENTRAL"]

CENTRAL = ("sun", "ring", "carrier")

# the example of the format (values [assumed]: a generic, equally spaced set)
EXAMPLE_PLANETARY = MappingProxyType({k: MappingProxyType(v) if isinstance(v, dict) else v for k, v in {
    "kind": "single_planetary", "planets": 3, "module": "3 mm", "pressure_angle": "20 deg",
    "teeth": {"sun": 30, "planet": 30, "ring": 90},
    "mesh_stiffness": {"sun_planet": "5e8 N/m", "ring_planet": "5e8 N/m"},
    "sun": {"mass": "1 kg", "inertia": "1e-3 kg*m^2", "support_stiffness": "1e8 N/m", "torsional_stiffness": "0 N*m/rad"},
    "ring": {"mass": "4 kg", "inertia": "3e-2 kg*m^2", "support_stiffness": "1e8 N/m", "torsional_stiffness": "1e8 N*m/rad"},
    "carrier": {"mass": "3 kg", "inertia": "1.5e-2 kg*m^2", "support_stiffness": "1e8 N/m", "torsional_stiffness": "0 N*m/rad"},
    "planet": {"mass": "0.5 kg", "inertia": "3e-4 kg*m^2", "bearing_stiffness": "1e8 N/m"},
}.items()})

_MEMBER_KEYS = {"mass": "mass", "inertia": "inertia", "support_stiffness": "stiffness",
                "torsional_stiffness": "torsional_stiffness"}
_PLANET_KEYS = {"mass": "mass", "inertia": "inertia", "bearing_stiffness": "stiffness"}
_TOP_KEYS = {"kind", "planets", "module", "pressure_angle", "teeth", "mesh_stiffness", "sun", "ring", "carrier",
             "planet", "planet_angle", "mesh_damping_ratio"}


@dataclass(frozen=True)
class MemberSpec:
    """A central member in SI: mass [kg], inertia [kg m²], support [N/m], torsional [N m/rad]."""
    mass: float
    inertia: float
    support_stiffness: float
    torsional_stiffness: float


@dataclass(frozen=True)
class PlanetarySpec:
    """A validated single planetary set in SI floats (from :func:`planetary_spec`)."""
    planets: int
    module: float
    pressure_angle: float
    z_sun: int
    z_planet: int
    z_ring: int
    k_sun_planet: float
    k_ring_planet: float
    sun: MemberSpec
    ring: MemberSpec
    carrier: MemberSpec
    planet_mass: float
    planet_inertia: float
    bearing_stiffness: float
    planet_angle: float = 0.0
    mesh_damping_ratio: float = 0.0

    @property
    def radii(self) -> dict:
        m = self.module
        return {"sun": 0.5 * m * self.z_sun, "planet": 0.5 * m * self.z_planet, "ring": 0.5 * m * self.z_ring,
                "carrier": 0.5 * m * (self.z_sun + self.z_planet)}

    @property
    def psi(self) -> np.ndarray:
        return self.planet_angle + 2 * np.pi * np.arange(self.planets) / self.planets


def _merge(base: Mapping, overrides: Mapping | None) -> dict:
    """A deep copy of ``base`` with dotted-key ``overrides`` ({"planets": 4, "sun.mass": "2 kg"})."""
    out = {k: dict(v) if isinstance(v, Mapping) else v for k, v in base.items()}
    for key, val in (overrides or {}).items():
        head, _, rest = key.partition(".")
        if rest:
            if not isinstance(out.get(head, {}), Mapping):
                raise ParameterError.at(key, f"{head!r} is not a table")
            out.setdefault(head, {})[rest] = val
        else:
            out[head] = val
    return out


def _table(d: Mapping, name: str, keys) -> Mapping:
    t = d.get(name)
    if not isinstance(t, Mapping):
        raise ParameterError.at(name, f"expected a table with keys {sorted(keys)}, got {t!r}")
    unknown = sorted(set(t) - set(keys))
    missing = sorted(set(keys) - set(t))
    if unknown:
        raise ParameterError.at(f"{name}.{unknown[0]}", f"unknown key{did_you_mean(unknown[0], keys)}; valid keys of "
                                                        f"[{name}]: {sorted(keys)}")
    if missing:
        raise ParameterError.at(f"{name}.{missing[0]}", f"missing; [{name}] needs {sorted(keys)}")
    return t


def _q(name, value, kind, positive=False, nonneg=False) -> float:
    x = to_si(quantity(name, value, kind))
    if positive and not x > 0:
        raise ParameterError.at(name, f"must be > 0, got {value!r}")
    if nonneg and x < 0:
        raise ParameterError.at(name, f"must be >= 0, got {value!r}")
    return x


def _count(name, value, lo) -> int:
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)) and not (
            isinstance(value, float) and value.is_integer()):
        raise ParameterError.at(name, f"expected an integer, got {value!r}")
    if int(value) < lo:
        raise ParameterError.at(name, f"must be >= {lo}, got {value!r}")
    return int(value)


def planetary_spec(spec: Mapping | PlanetarySpec, overrides: Mapping | None = None) -> PlanetarySpec:
    """Validate the TOML-format mapping (plus dotted ``overrides``) into a :class:`PlanetarySpec`.
    Every error is a ParameterError naming the dotted key at fault."""
    if isinstance(spec, PlanetarySpec):
        if overrides:
            raise ParameterError.at("overrides", "apply overrides to the mapping, not to a PlanetarySpec")
        return spec
    if not isinstance(spec, Mapping):
        raise ParameterError.at("spec", f"expected a mapping in the single-planetary format, got {type(spec).__name__}")
    d = _merge(spec, overrides)
    unknown = sorted(set(d) - _TOP_KEYS)
    if unknown:
        raise ParameterError.at(unknown[0], f"unknown key{did_you_mean(unknown[0], _TOP_KEYS)}; valid keys: "
                                            f"{sorted(_TOP_KEYS)}")
    if d.get("kind", "single_planetary") != "single_planetary":
        raise ParameterError.at("kind", f"expected 'single_planetary', got {d.get('kind')!r}")
    for key in ("planets", "module", "pressure_angle"):
        if key not in d:
            raise ParameterError.at(key, "missing")
    N = _count("planets", d["planets"], 1)
    m = _q("module", d["module"], "length", positive=True)
    alpha = _q("pressure_angle", d["pressure_angle"], "angle")
    if not 0 < alpha < math.pi / 4:
        raise ParameterError.at("pressure_angle", f"must be between 0 and 45 deg, got {d['pressure_angle']!r}")
    teeth = _table(d, "teeth", ("sun", "planet", "ring"))
    zs, zp, zr = (_count(f"teeth.{k}", teeth[k], 3) for k in ("sun", "planet", "ring"))
    if zr != zs + 2 * zp:
        raise ParameterError.at("teeth.ring", f"{zr} teeth: coaxial standard gears need z_ring = z_sun + 2 z_planet "
                                              f"= {zs + 2 * zp}")
    ks = _table(d, "mesh_stiffness", ("sun_planet", "ring_planet"))
    k_sp = _q("mesh_stiffness.sun_planet", ks["sun_planet"], "stiffness", positive=True)
    k_rp = _q("mesh_stiffness.ring_planet", ks["ring_planet"], "stiffness", positive=True)
    members = {}
    for name in CENTRAL:
        t = _table(d, name, _MEMBER_KEYS)
        members[name] = MemberSpec(*(_q(f"{name}.{k}", t[k], kind, positive=k in ("mass", "inertia"), nonneg=True)
                                     for k, kind in _MEMBER_KEYS.items()))
    pt = _table(d, "planet", _PLANET_KEYS)
    pm, pj, kb = (_q(f"planet.{k}", pt[k], kind, positive=True) for k, kind in _PLANET_KEYS.items())
    psi0 = _q("planet_angle", d.get("planet_angle", "0 deg"), "angle")
    zeta = _q("mesh_damping_ratio", d.get("mesh_damping_ratio", 0.0), "dimensionless", nonneg=True)
    return PlanetarySpec(planets=N, module=m, pressure_angle=alpha, z_sun=zs, z_planet=zp, z_ring=zr,
                         k_sun_planet=k_sp, k_ring_planet=k_rp, sun=members["sun"], ring=members["ring"],
                         carrier=members["carrier"], planet_mass=pm, planet_inertia=pj, bearing_stiffness=kb,
                         planet_angle=psi0, mesh_damping_ratio=zeta)


def load_planetary_toml(path, overrides: Mapping | None = None) -> PlanetarySpec:
    """Read and validate a single-planetary TOML file."""
    try:
        data = tomllib.loads(Path(path).read_text(encoding="utf-8"))
    except tomllib.TOMLDecodeError as e:
        raise ParameterError(f"{path}: invalid TOML: {e}") from None
    return planetary_spec(data, overrides)


@dataclass(frozen=True, eq=False, kw_only=True)
class PlanetaryScene(BuiltScene):
    """The built single planetary set (:func:`build_single_planetary`)."""
    spec: PlanetarySpec
    planets: tuple[str, ...]              # planet body names
    psi: np.ndarray                       # (N,) planet angles on the carrier [rad]
    torque_sign: int                      # sign of the sun torque: the loaded flank (+1/−1) of both mesh types
    base_radius_sun: float                # [m]
    base_radius_planet: float             # [m]
    base_radius_ring: float               # [m]


def build_single_planetary(spec: Mapping | PlanetarySpec = EXAMPLE_PLANETARY, *, overrides: Mapping | None = None,
                           torque_sign: int = 1) -> PlanetaryScene:
    """Build the set at rest (inertial frame, no gravity, no drives). ``spec``: the TOML-format mapping
    (or a PlanetarySpec); ``overrides``: dotted keys, e.g. {"planets": 5, "ring.torsional_stiffness":
    "0 N*m/rad"}; ``torque_sign``: sign of the sun torque that decides the loaded flanks.

    Warns (DesignWarning) when (z_sun + z_ring)/N is not an integer (equally spaced planets would not
    assemble; with constant mesh stiffness the model is unaffected) or adjacent planets' tip circles
    overlap. Returns a :class:`PlanetaryScene`."""
    s = planetary_spec(spec, overrides)
    if torque_sign not in (1, -1):
        raise ParameterError.at("torque_sign", f"expected +1 or -1, got {torque_sign!r}")
    N, r = s.planets, s.radii
    if ((s.z_sun + s.z_ring) / N) % 1 != 0:
        warnings.warn(f"planets: (z_sun + z_ring)/N = {(s.z_sun + s.z_ring) / N:.4g} is not an integer: equally "
                      f"spaced planets do not assemble (constant mesh stiffness: no effect on this model)",
                      DesignWarning, stacklevel=2)
    tip = r["planet"] + s.module
    if N > 1 and 2 * r["carrier"] * math.sin(math.pi / N) < 2 * tip:
        warnings.warn(f"planets: {N} planets of tip radius {tip * 1e3:.1f} mm at {r['carrier'] * 1e3:.1f} mm overlap",
                      DesignWarning, stacklevel=2)
    scene = Scene(frame_omega=0.0, gravity=0.0, options=SceneOptions(bearings="linear", gravity=False, frame="fixed"))
    for name in CENTRAL:
        mem = getattr(s, name)
        scene.body(name, mem.mass, mem.inertia)
    psi = s.psi
    centres = r["carrier"] * np.column_stack([np.cos(psi), np.sin(psi)])
    names = [f"p{n + 1}" for n in range(N)]
    for n in range(N):
        scene.body(names[n], s.planet_mass, s.planet_inertia, pose=(*centres[n], 0.0))
    sup = scene.family("support", GroundSupport, ("bodies",))
    for name in CENTRAL:
        mem = getattr(s, name)
        sup.add(1, bodies=[name], kx=mem.support_stiffness, k_theta=mem.torsional_stiffness)
    bear = scene.family("bearing", BodySpring, ("body_a", "body_b"))
    bear.add(N, body_a=["carrier"] * N, body_b=names, k=s.bearing_stiffness, marker_a=centres,
             marker_b=np.zeros((N, 2)))
    ca = math.cos(s.pressure_angle)
    rbs, rbp, rbr = r["sun"] * ca, r["planet"] * ca, r["ring"] * ca
    zero = np.zeros((N, 3))
    planet_poses = np.column_stack([centres, np.zeros(N)])
    c_sp = mesh_damping(s.mesh_damping_ratio, s.k_sun_planet, s.sun.inertia, s.planet_inertia, rbs, rbp)
    c_rp = mesh_damping(s.mesh_damping_ratio, s.k_ring_planet, s.planet_inertia, s.ring.inertia, rbp, rbr)
    sp = scene.family("mesh_sp", GearMesh, ("gear1", "gear2"), internal=False)
    sp.add(N, gear1=["sun"] * N, gear2=names, rb1=rbs, rb2=rbp, alpha=s.pressure_angle, a0=r["carrier"],
           teeth1=s.z_sun, k_mean=s.k_sun_planet, c_mesh=c_sp, u0=mesh_u0(False, rbs, rbp, zero, planet_poses),
           backlash=0.0, phi_ref=psi)
    rp = scene.family("mesh_rp", GearMesh, ("gear1", "gear2"), internal=True)
    rp.add(N, gear1=names, gear2=["ring"] * N, rb1=rbp, rb2=rbr, alpha=s.pressure_angle, a0=r["ring"] - r["planet"],
           teeth1=s.z_planet, k_mean=s.k_ring_planet, c_mesh=c_rp, u0=mesh_u0(True, rbp, rbr, planet_poses, zero),
           backlash=0.0, phi_ref=psi)
    return scene.build(PlanetaryScene, spec=s, planets=tuple(names), psi=psi, torque_sign=torque_sign,
                       base_radius_sun=rbs, base_radius_planet=rbp, base_radius_ring=rbr)


def modal_state(built: PlanetaryScene, preload: float = 1e-9) -> tuple[np.ndarray, np.ndarray]:
    """(q, v) at which every mesh is compressed by ``preload`` [m] on its loaded flank (module docstring):
    the nominal state with the sun turned by f_sp·ε/r_b,sun and the ring by f_rp·ε/r_b,ring."""
    if not (np.isfinite(preload) and preload > 0):
        raise ParameterError.at("preload", f"must be > 0 m, got {preload!r}")
    m = built.model
    f = built.torque_sign
    qf, _ = m.full(0.0, built.q0, built.v0)
    qf[3 * m.body("sun").index + 2] += f * preload / built.base_radius_sun
    qf[3 * m.body("ring").index + 2] += f * preload / built.base_radius_ring
    return qf[m.free].copy(), np.zeros(m.ndof)


@dataclass(frozen=True)
class PlanetaryModes:
    """Modes of the set: ``frequencies_hz`` (ascending), mass-normalised ``shapes`` (ndof, n), ``kind``
    per mode ("rotational" | "translational" | "planet" | "mixed"), ``groups``: lists of mode indices
    with equal frequency (relative ``tol``), ``central_translation``, ``central_rotation`` the fractions
    of each mode's kinetic-energy norm x·M·x in the central members' translations / rotations."""
    frequencies_hz: np.ndarray
    shapes: np.ndarray
    kind: tuple
    groups: tuple
    central_translation: np.ndarray
    central_rotation: np.ndarray

    def multiplicities(self, kind: str) -> list[int]:
        """Sizes of the degenerate groups of one kind (a group of mixed kinds counts under 'mixed')."""
        out = []
        for g in self.groups:
            kinds = {self.kind[i] for i in g}
            k = kinds.pop() if len(kinds) == 1 else "mixed"
            if k == kind:
                out.append(len(g))
        return out


def classify_modes(model: mbd.Model, frequencies_hz, shapes, tol: float = 1e-6, freq_tol: float = 1e-6) -> PlanetaryModes:
    """Lin & Parker's classes: *rotational* — central members only rotate (no translation);
    *translational* — central members only translate (no rotation); *planet* — central members at rest.
    ``tol`` bounds the energy fractions taken as zero; frequencies within ``freq_tol`` (relative, or
    absolute 1e-9 Hz for zero modes) form one degenerate group."""
    f = np.asarray(frequencies_hz, float)
    X = np.asarray(shapes, float)
    full = model.free
    body, coord = full // 3, full % 3
    mdiag = model.mdiag
    energy = mdiag[:, None] * X * X
    total = energy.sum(axis=0)
    central = np.isin(body, [model.body(n).index for n in CENTRAL])
    trans = energy[central & (coord < 2)].sum(axis=0) / total
    rot = energy[central & (coord == 2)].sum(axis=0) / total
    kind = []
    for t, r in zip(trans, rot):
        if t < tol and r < tol:
            kind.append("planet")
        elif t < tol:
            kind.append("rotational")
        elif r < tol:
            kind.append("translational")
        else:
            kind.append("mixed")
    groups, cur = [], [0]
    for i in range(1, f.size):
        ref = f[cur[0]]
        if abs(f[i] - ref) <= max(freq_tol * max(abs(ref), abs(f[i])), 1e-9):
            cur.append(i)
        else:
            groups.append(tuple(cur))
            cur = [i]
    if f.size:
        groups.append(tuple(cur))
    return PlanetaryModes(f, X, tuple(kind), tuple(groups), trans, rot)


def planetary_modes(built: PlanetaryScene, preload: float = 1e-9, **classify_kw) -> PlanetaryModes:
    """Undamped modes about :func:`modal_state`, classified (:func:`classify_modes`)."""
    q, v = modal_state(built, preload)
    res = mbd.modal_analysis(built.model, 0.0, q, v)
    return classify_modes(built.model, res.frequencies_hz, res.shapes, **classify_kw)
