"""Scene composition: components add bodies and element *instances*; one family per element kind.

Components never create one element object per roller: they append instances to a
:class:`FamilyCollector` (body indices + per-instance parameters), and :meth:`Scene.build` turns each
collector into a single vectorised element family. Initial poses and velocities are given in the
fixed frame I (the kinematic steady state) and converted once into the reference frame R.
A scene contains only what its components added: nothing unused is built or evaluated.
"""
from __future__ import annotations

from dataclasses import dataclass, fields
from typing import ClassVar, TypeVar

import numpy as np

import mbd
from mbd.model import to_reference

from .names import did_you_mean

__all__ = ["Scene", "BuiltScene", "FamilyCollector", "SceneOptions"]


@dataclass(frozen=True)
class SceneOptions:
    """Physics switches of a scene (PyBaMM-style validated options). Unknown keys fail loudly.

    A switch left None takes the scene's own default: :attr:`DEFAULTS` for the DPGT, the rig's values
    for the bearing rig (:func:`components.rig.build_bearing_rig`). A scene never overrides a switch
    that was given: it refuses one it cannot honour. ``cage`` also accepts true/false (old TOML and
    CLI input) as "free"/"none"."""
    bearings: str | None = None        # "rollers": full roller/cage model; "linear": radial spring
    cage: str | None = None            # "free": cage body + pocket and guide contacts; "held": a cage that
                                       # cannot turn (bearing rig only); "none": no cage (rollers only)
    drag: bool | None = None           # lubricant drag on rollers
    gravity: bool | None = None
    mesh_stiffness: str | None = None  # "time_varying" | "constant"
    frame: str | None = None           # "rotating" (R turns with the nominal carrier speed) | "fixed"

    DEFAULTS: ClassVar[dict] = {"bearings": "rollers", "cage": "free", "drag": True, "gravity": True,
                                "mesh_stiffness": "time_varying", "frame": "rotating"}
    _CHOICES: ClassVar[dict] = {"bearings": ("rollers", "linear"), "cage": ("free", "held", "none"),
                                "mesh_stiffness": ("time_varying", "constant"), "frame": ("rotating", "fixed")}

    def __post_init__(self):
        if isinstance(self.cage, (bool, np.bool_)):
            object.__setattr__(self, "cage", "free" if self.cage else "none")
        for key, allowed in self._CHOICES.items():
            if getattr(self, key) not in (None, *allowed):
                raise mbd.ModelError(f"scene option {key!r} must be one of {allowed}, got {getattr(self, key)!r}"
                                     f"{did_you_mean(getattr(self, key), allowed)}")
        for key in ("drag", "gravity"):
            if getattr(self, key) is not None and not isinstance(getattr(self, key), bool):
                raise mbd.ModelError(f"scene option {key!r} must be true or false, got {getattr(self, key)!r}")

    def given(self) -> dict:
        """The switches that were set (not None)."""
        return {f.name: getattr(self, f.name) for f in fields(self) if getattr(self, f.name) is not None}

    def resolved(self, **defaults) -> "SceneOptions":
        """Every switch set: the given ones, else ``defaults`` (a scene's own), else :attr:`DEFAULTS`."""
        return SceneOptions(**{**self.DEFAULTS, **defaults, **self.given()})

    @classmethod
    def from_dict(cls, d: dict | None) -> "SceneOptions":
        d = dict(d or {})
        valid = [f.name for f in fields(cls)]
        unknown = set(d) - set(valid)
        if unknown:
            first = sorted(unknown)[0]
            raise mbd.ModelError(f"unknown scene option(s) {sorted(unknown)}{did_you_mean(first, valid)}; "
                                 f"valid options: {valid}")
        return cls(**d)


class FamilyCollector:
    """Instances of one element family, accumulated by components, created once at build."""

    def __init__(self, cls, name: str, body_args: tuple[str, ...], resolve=None, **common):
        self.cls, self.name, self.body_args, self.common = cls, name, body_args, common
        self.resolve = resolve        # resolve(columns, scene) -> the family's arguments (families on tilt coordinates)
        self.rows: list[dict[str, np.ndarray]] = []

    def add(self, n: int, **kw) -> slice:
        """Append n instances. Each value is a scalar (same for all n) or an array whose first
        dimension is n (e.g. (n, 2) marker offsets). Returns the instances' slice in the family."""
        row = {}
        for k, v in kw.items():
            a = np.asarray(v)
            if a.ndim == 0:
                a = np.full(n, v, dtype=a.dtype if a.dtype != object else object)
            elif a.shape[0] != n:
                raise mbd.ModelError(f"family {self.name!r}: argument {k!r} needs {n} rows, got shape {a.shape}")
            row[k] = a
        start = self.n
        row["__n"] = n
        self.rows.append(row)
        return slice(start, start + n)

    @property
    def n(self) -> int:
        return sum(r["__n"] for r in self.rows)

    def make(self, body_index, scene=None):
        keys = [k for k in self.rows[0] if k != "__n"]
        cat = {k: np.concatenate([r[k] for r in self.rows]) for k in keys}
        if self.resolve is not None:
            return self.cls(self.name, **self.resolve(cat, scene), **self.common)
        for b in self.body_args:
            cat[b] = np.array([body_index[x] if isinstance(x, str) else int(x) for x in cat[b]], dtype=np.int64)
        return self.cls(self.name, **{b: cat.pop(b) for b in self.body_args}, **cat, **self.common)


@dataclass(frozen=True, eq=False, kw_only=True)
class BuiltScene:
    """A built model with its initial state (free DOFs, in R) at t = 0: in R the ground turns at −Ω, so at
    a later time a body held to the ground (the ring on its torsional support) is wanted elsewhere and ``q0`` is no
    state of the machine there (docs/model.md §10.4). A scene builder returns a subclass whose
    typed fields carry what its outputs need (:class:`components.dpgt.DPGTScene`,
    :class:`components.rig.BearingRigScene`, :class:`components.planetary.PlanetaryScene`)."""
    model: mbd.Model
    q0: np.ndarray
    v0: np.ndarray

    def body_index(self, name: str) -> int:
        return self.model.body(name).index


S = TypeVar("S", bound=BuiltScene)


class Scene:
    def __init__(self, frame_omega: float = 0.0, gravity: float = 0.0, options: SceneOptions | None = None):
        self.options = (options or SceneOptions()).resolved()     # components read every switch
        frame = mbd.Frame.rotating(frame_omega) if frame_omega != 0.0 else mbd.Frame.inertial()
        self.mb = mbd.ModelBuilder(frame=frame, gravity=(0.0, -gravity))
        self.frame_omega = frame_omega
        self._vel: list[np.ndarray] = []           # initial velocities in I (the builder keeps the poses)
        self.index: dict[str, int] = {}
        self.families: dict[str, FamilyCollector] = {}
        self._direct: list = []
        self._slopes: dict[str, float] = {}        # tilt coordinates asked for: body name -> diametral inertia
        self._tilts: dict[str, float] = {}
        self.slope_index: dict[str, tuple[int, int]] = {}    # filled by build(): full indices
        self.tilt_index: dict[str, int] = {}
        self._extras: list = []                    # elements built after the tilt coordinates: fn(scene) -> element

    def body(self, name, mass, inertia, pose=(0.0, 0.0, 0.0), vel=(0.0, 0.0, 0.0), fixed=False) -> int:
        """Add a body with its initial pose and velocity in the fixed frame; returns its index."""
        ref = self.mb.add_body(name, mass, inertia, pose=pose, fixed=fixed)
        self.index[name] = ref.index
        self._vel.append(np.zeros(3) if fixed else np.asarray(vel, float))
        return ref.index

    def pose(self, name: str) -> np.ndarray:
        return self.mb.pose(self.index[name])

    def set_pose(self, name: str, pose) -> None:
        """Change a body's initial pose in the fixed frame before the scene is built (e.g. a ring
        turned to mate with its planets). Its nominal pose in the model follows."""
        self.mb.set_pose(self.index[name], pose)

    def kinematic_inertia(self, speed: float) -> float:
        """2T/speed² [kg·m²] for initial velocities that all scale with ``speed`` (e.g. the carrier's in
        a ring-fixed train): the inertia a drive of that member sees. Velocities are divided by the speed
        before squaring, so tiny speeds do not underflow."""
        m, J = self.mb.masses(), self.mb.inertias()
        u = np.array(self._vel) / speed
        return float(np.sum(m * (u[:, 0] ** 2 + u[:, 1] ** 2) + J * u[:, 2] ** 2))

    def scale_velocities(self, factor: float) -> None:
        """Every initial velocity times ``factor``: a kinematic state whose speeds all scale with one member's
        (a ring-fixed train started at a fraction of its speed)."""
        self._vel = [v * factor for v in self._vel]

    def family(self, key: str, cls, body_args: tuple[str, ...], resolve=None, **common) -> FamilyCollector:
        """The collector for family ``key`` (created on first use). ``resolve(columns, scene)``: the family's arguments
        from its collected columns, for families that index tilt coordinates (known only at build)."""
        if key not in self.families:
            self.families[key] = FamilyCollector(cls, key, body_args, resolve=resolve, **common)
        return self.families[key]

    def slopes(self, name: str, inertia: float) -> None:
        """Give body ``name`` a slope pair (mbd.ModelBuilder.add_slopes) of diametral inertia ``inertia`` [kg·m²];
        declared at build, after every body."""
        self._slopes[name] = float(inertia)

    def tilt(self, name: str, inertia: float) -> None:
        """Give body ``name`` a scalar tilt (mbd.ModelBuilder.add_tilts) of inertia ``inertia`` [kg·m²]."""
        self._tilts[name] = float(inertia)

    def add_late_element(self, make) -> None:
        """An element family made at build, after the tilt coordinates: ``make(scene)`` returns it."""
        self._extras.append(make)

    def add_element(self, element) -> None:
        """A ready-made element family (e.g. one drive)."""
        self._direct.append(element)

    def build(self, kind: type[S], **fields) -> S:
        """Freeze the model; returns ``kind`` (a :class:`BuiltScene` type) with the initial state and
        ``fields``, the scene type's own (what its outputs read)."""
        for name, J in self._slopes.items():          # tilt coordinates after every body (their indices follow)
            self.slope_index[name] = self.mb.add_slopes(self.index[name], J)
        if self._tilts:
            idx = self.mb.add_tilts([self.index[nm] for nm in self._tilts], list(self._tilts.values()))
            self.tilt_index.update(zip(self._tilts, (int(i) for i in idx)))
        for fam in self.families.values():
            if fam.n:
                self.mb.add(fam.make(self.index, self))
        for e in self._direct:
            self.mb.add(e)
        for make in self._extras:
            self.mb.add(make(self))
        model = self.mb.build()
        fs = model.frame.at(0.0)
        q, v = to_reference(self.mb.poses(), np.array(self._vel), fs)
        qf, vf = q.ravel(), v.ravel()
        if model.has_tilt:      # every slope and tilt starts at zero, at rest in R
            qf, vf = model.full_of_poses(q), model.full_of_poses(v)
        return kind(model=model, q0=qf[model.free].copy(), v0=vf[model.free].copy(), **fields)
