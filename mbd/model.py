"""Static model (built once, frozen) and mutable state — the mjModel/mjData split.

Coordinates: every body b has q_b = (x_b, y_b, θ_b), its centre of mass in the reference frame R and
its angle relative to R. R rotates about the fixed z axis at a prescribed Ω(t) (Ω = 0: R is inertial).
The *full* coordinate vector holds 3 entries per body (body b at 3b, 3b + 1, 3b + 2), then the *tilt
coordinates* some bodies declare, appended after every body's three: a pair of out-of-plane slopes
s = (s_x, s_y) of the body's axis in R (:meth:`ModelBuilder.add_slopes`, inertia J_d each) or a scalar tilt
in a plane the body's own elements define (:meth:`ModelBuilder.add_tilts`). Tilt coordinates are always
free. Bodies fixed to ground have prescribed motion (constant pose in the inertial frame) and are not
degrees of freedom. Elements index the full vector; the integrator sees only the free DOFs. A model
without tilt coordinates is the planar model, entry for entry.
"""
from __future__ import annotations

import functools
from dataclasses import dataclass, field
from typing import Callable, Sequence

import numpy as np

from .errors import ModelError

__all__ = ["Frame", "FrameState", "BodyRef", "ModelBuilder", "Model", "State", "SLOPE_X", "SLOPE_Y", "TILT"]

# kinds of tilt coordinate (Model.extra_kind)
SLOPE_X, SLOPE_Y, TILT = 0, 1, 2


@dataclass(frozen=True)
class FrameState:
    """Angle φ = ∫Ω dt of R relative to I, its rate Ω and acceleration Ω̇ at one instant."""
    phi: float
    omega: float
    domega: float

    def rot(self) -> np.ndarray:
        c, s = np.cos(self.phi), np.sin(self.phi)
        return np.array([[c, -s], [s, c]])


@dataclass(frozen=True)
class Frame:
    """Reference frame R rotating about z.

    ``omega`` is a constant rate [rad/s], or ``profile`` a callable t -> (φ, Ω, Ω̇) for a
    prescribed time-varying rate (φ must be the exact integral of Ω so that fixed-frame outputs match).
    """
    omega: float = 0.0
    profile: Callable[[float], tuple[float, float, float]] | None = None

    @staticmethod
    def inertial() -> "Frame":
        return Frame(0.0)

    @staticmethod
    def rotating(omega: float) -> "Frame":
        return Frame(float(omega))

    @property
    def is_inertial(self) -> bool:
        return self.profile is None and self.omega == 0.0

    def at(self, t: float) -> FrameState:
        if self.profile is not None:
            return FrameState(*map(float, self.profile(t)))
        return FrameState(self.omega * t, self.omega, 0.0)


@dataclass(frozen=True)
class BodyRef:
    """Handle to a body: its index and the indices of its 3 entries in the full coordinate vector."""
    index: int
    name: str

    @property
    def dofs(self) -> tuple[int, int, int]:
        i = 3 * self.index
        return (i, i + 1, i + 2)


class ModelBuilder:
    """Collects bodies and element families, then :meth:`build` freezes them into a :class:`Model`."""

    def __init__(self, frame: Frame | None = None, gravity: Sequence[float] = (0.0, 0.0)):
        self.frame = frame if frame is not None else Frame.inertial()
        self.gravity = np.asarray(gravity, dtype=float)
        if self.gravity.shape != (2,) or not np.all(np.isfinite(self.gravity)):
            raise ModelError(f"gravity must be a finite 2-vector in the fixed frame [m/s^2], got {gravity!r}")
        self._names: list[str] = []
        self._mass: list[float] = []
        self._inertia: list[float] = []
        self._fixed: list[bool] = []
        self._pose: list[np.ndarray] = []
        self._elements: list = []
        self._extra_owner: list[int] = []      # tilt coordinates: owning body, kind, inertia [kg·m²]
        self._extra_kind: list[int] = []
        self._extra_inertia: list[float] = []

    def add_body(self, name: str, mass: float, inertia: float, pose=(0.0, 0.0, 0.0),
                 fixed: bool = False) -> BodyRef:
        """Add a rigid body. ``pose`` (x, y, θ) is its nominal pose in the *fixed* frame at t = 0;
        for a fixed body it is the pose it keeps for ever."""
        if name in self._names:
            raise ModelError(f"body name {name!r} is used twice")
        if self._extra_owner:     # tilt coordinates sit after every body's three: their indices would move
            raise ModelError(f"body {name!r}: add every body before the first add_slopes/add_tilts")
        if not (np.isfinite(mass) and mass > 0):
            raise ModelError(f"body {name!r}: mass must be > 0 kg, got {mass!r}")
        if not (np.isfinite(inertia) and inertia > 0):
            raise ModelError(f"body {name!r}: polar inertia must be > 0 kg*m^2, got {inertia!r}")
        pose = _checked_pose(name, pose)
        self._names.append(name)
        self._mass.append(float(mass))
        self._inertia.append(float(inertia))
        self._fixed.append(bool(fixed))
        self._pose.append(pose)
        return BodyRef(len(self._names) - 1, name)

    def add_slopes(self, body: BodyRef, inertia: float) -> tuple[int, int]:
        """Give ``body`` two slope coordinates (s_x, s_y): its axis through its centre c passes through
        c + ζ·s at axial station ζ, s in R. ``inertia``: its diametral moment of inertia J_d [kg·m²] about
        its centre, which is each slope's mass. In a rotating R the engine adds the slope pair's frame terms,
        those of a point of mass J_d at position s (docs/model.md §2.3, §2.4); a spinning body's gyroscopic terms are
        an element family (:class:`mbd.elements.SlopeGyroscopic`). Returns the pair's full indices."""
        b = self._body_index(body, "add_slopes")
        if b in [o for o, k in zip(self._extra_owner, self._extra_kind) if k == SLOPE_X]:
            raise ModelError(f"body {self._names[b]!r} has slope coordinates already")
        if not (np.isfinite(inertia) and inertia > 0):
            raise ModelError(f"body {self._names[b]!r}: diametral inertia must be > 0 kg*m^2, got {inertia!r}")
        first = 3 * len(self._names) + len(self._extra_owner)
        self._extra_owner += [b, b]
        self._extra_kind += [SLOPE_X, SLOPE_Y]
        self._extra_inertia += [float(inertia)] * 2
        return first, first + 1

    def add_tilts(self, bodies, inertia) -> np.ndarray:
        """Give each body of ``bodies`` one scalar tilt coordinate (a slope in a plane its elements define, e.g. a
        roller's radial–axial plane), of inertia ``inertia`` [kg·m²] (scalar or one per body). No frame terms:
        a tilt is measured in a plane that turns with the body's own elements. Returns the full indices."""
        idx = [self._body_index(b, "add_tilts") for b in np.atleast_1d(np.asarray(bodies, dtype=object))]
        J = np.broadcast_to(np.asarray(inertia, float), (len(idx),))
        if not np.all(np.isfinite(J) & (J > 0)):
            raise ModelError(f"add_tilts: tilt inertia must be > 0 kg*m^2, got {inertia!r}")
        if set(idx) & {o for o, k in zip(self._extra_owner, self._extra_kind) if k == TILT} or len(set(idx)) < len(idx):
            raise ModelError("add_tilts: a body has a tilt coordinate already")
        first = 3 * len(self._names) + len(self._extra_owner)
        self._extra_owner += idx
        self._extra_kind += [TILT] * len(idx)
        self._extra_inertia += [float(j) for j in J]
        return first + np.arange(len(idx), dtype=np.int64)

    def _body_index(self, body, what: str) -> int:
        b = getattr(body, "index", body)
        if not (isinstance(b, (int, np.integer)) and 0 <= b < len(self._names)):
            raise ModelError(f"{what}: body must be a BodyRef or an index in [0, {len(self._names)}), got {body!r}")
        return int(b)

    def set_pose(self, index: int, pose) -> None:
        """Change body ``index``'s nominal pose (x, y, θ) in the fixed frame at t = 0 before :meth:`build`
        (e.g. a ring turned to mate with its planets)."""
        if not (isinstance(index, (int, np.integer)) and 0 <= index < len(self._names)):
            raise ModelError(f"body index must be an integer in [0, {len(self._names)}), got {index!r}")
        self._pose[index] = _checked_pose(self._names[index], pose).copy()

    def pose(self, index: int) -> np.ndarray:
        """Body ``index``'s nominal pose (x, y, θ) in the fixed frame at t = 0 (a copy)."""
        return self._pose[index].copy()

    def poses(self) -> np.ndarray:
        """(nb, 3) nominal poses in the fixed frame at t = 0, in body order."""
        return np.array(self._pose).reshape(-1, 3)

    def masses(self) -> np.ndarray:
        """(nb,) body masses [kg], in body order."""
        return np.array(self._mass)

    def inertias(self) -> np.ndarray:
        """(nb,) polar moments of inertia [kg·m²], in body order."""
        return np.array(self._inertia)

    def add(self, element):
        if any(e.name == element.name for e in self._elements):
            raise ModelError(f"element family name {element.name!r} is used twice")
        self._elements.append(element)
        return element

    @property
    def n_bodies(self) -> int:
        return len(self._names)

    def build(self) -> "Model":
        nb = len(self._names)
        if nb == 0:
            raise ModelError("a model needs at least one body")
        nfull = 3 * nb + len(self._extra_owner)
        for e in self._elements:
            d = np.asarray(e.dofs)
            if d.ndim != 2 or d.shape[1] != e.n_local or d.dtype.kind not in "iu":
                raise ModelError(f"element {e.name!r}: dofs must be an integer (n, {e.n_local}) array, got shape {d.shape}")
            if d.size and (d.min() < 0 or d.max() >= nfull):
                raise ModelError(f"element {e.name!r}: dof index out of range [0, {nfull}) — "
                                 "does it refer to a body of another model?")
            e.check()
        fixed = np.array(self._fixed)
        dof_fixed = np.concatenate([np.repeat(fixed, 3), np.zeros(len(self._extra_owner), bool)])
        free = np.flatnonzero(~dof_fixed)
        full_to_free = -np.ones(nfull, dtype=np.int64)
        full_to_free[free] = np.arange(free.size)
        mass = np.array(self._mass)
        inertia = np.array(self._inertia)
        mdiag_full = np.concatenate([np.column_stack([mass, mass, inertia]).ravel(), self._extra_inertia])
        return Model(
            body_names=tuple(self._names), mass=mass, inertia=inertia, fixed=fixed,
            pose0=np.array(self._pose), frame=self.frame, gravity=self.gravity,
            elements=tuple(self._elements), free=free, full_to_free=full_to_free,
            mdiag=mdiag_full[free], extra_owner=np.array(self._extra_owner, np.int64),
            extra_kind=np.array(self._extra_kind, np.int64), extra_inertia=np.array(self._extra_inertia, float),
        )


@dataclass(frozen=True, eq=False)
class Model:
    body_names: tuple[str, ...]
    mass: np.ndarray
    inertia: np.ndarray
    fixed: np.ndarray
    pose0: np.ndarray        # (nb, 3) nominal poses in the fixed frame at t = 0
    frame: Frame
    gravity: np.ndarray      # (2,) in the fixed frame
    elements: tuple
    free: np.ndarray         # full indices of the free DOFs
    full_to_free: np.ndarray  # (n_full,) free index or -1
    mdiag: np.ndarray        # (ndof,) diagonal mass matrix on the free DOFs
    # tilt coordinates, full index 3 nb + j: owning body, kind (SLOPE_X, SLOPE_Y, TILT), inertia [kg·m²]
    extra_owner: np.ndarray = field(default_factory=lambda: np.zeros(0, np.int64))
    extra_kind: np.ndarray = field(default_factory=lambda: np.zeros(0, np.int64))
    extra_inertia: np.ndarray = field(default_factory=lambda: np.zeros(0))

    @property
    def n_bodies(self) -> int:
        return len(self.body_names)

    @property
    def ndof(self) -> int:
        return self.free.size

    @property
    def n_body_coords(self) -> int:
        """3 per body: the full indices below it are bodies' (x, y, θ), those from it tilt coordinates."""
        return 3 * len(self.body_names)

    @property
    def n_full(self) -> int:
        return 3 * len(self.body_names) + self.extra_owner.size

    @property
    def has_tilt(self) -> bool:
        return self.extra_owner.size > 0

    @functools.cached_property
    def slope_pairs(self) -> np.ndarray:
        """(n_pairs, 2) full indices (s_x, s_y) of every slope pair, in declaration order."""
        j = np.flatnonzero(self.extra_kind == SLOPE_X)
        return np.column_stack([j, j + 1]).astype(np.int64) + self.n_body_coords

    @functools.cached_property
    def angle_dofs(self) -> np.ndarray:
        """(ndof,) True where a free DOF is an angle θ or a tilt coordinate (else a length x or y)."""
        return np.where(self.free < self.n_body_coords, (self.free % 3) == 2, True)

    def coordinate_name(self, full: int) -> str:
        """A readable name of full coordinate ``full``: 'body.x', 'body.θ', 'body.s_x', 'body.tilt'."""
        nb3 = self.n_body_coords
        if full < nb3:
            return f"{self.body_names[full // 3]}.{'xyθ'[full % 3]}"
        j = full - nb3
        return f"{self.body_names[self.extra_owner[j]]}.{('s_x', 's_y', 'tilt')[self.extra_kind[j]]}"

    def body_poses(self, q_full: np.ndarray) -> np.ndarray:
        """(..., nb, 3) the bodies' (x, y, θ) from full vectors (..., n_full) (tilt coordinates left out)."""
        q_full = np.asarray(q_full)
        return q_full[..., : self.n_body_coords].reshape(q_full.shape[:-1] + (-1, 3))

    def full_of_poses(self, X: np.ndarray, extra: np.ndarray | None = None) -> np.ndarray:
        """The full vector of body poses X (nb, 3) and tilt coordinates ``extra`` (default 0)."""
        out = np.zeros(self.n_full)
        out[: self.n_body_coords] = np.asarray(X).ravel()
        if extra is not None:
            out[self.n_body_coords:] = extra
        return out

    def body(self, name: str) -> BodyRef:
        try:
            return BodyRef(self.body_names.index(name), name)
        except ValueError:
            raise ModelError(f"no body named {name!r}") from None

    def element(self, name: str):
        for e in self.elements:
            if e.name == name:
                return e
        raise ModelError(f"no element family named {name!r}; have {[e.name for e in self.elements]}")

    # frames -----------------------------------------------------------------------------------
    def fixed_body_motion(self, t: float) -> tuple[np.ndarray, np.ndarray]:
        """Full-vector (q, v) of the fixed bodies in R at time t (zeros elsewhere)."""
        fs = self.frame.at(t)
        q = np.zeros(self.n_full)
        v = np.zeros(self.n_full)
        if self.fixed.any():
            idx = np.flatnonzero(self.fixed)
            p = self.pose0[idx]
            qr, vr = to_reference(p, np.zeros_like(p), fs)
            for j in range(3):
                q[3 * idx + j] = qr[:, j]
                v[3 * idx + j] = vr[:, j]
        return q, v

    def full(self, t: float, q: np.ndarray, v: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        if self.fixed.any():
            qf, vf = self.fixed_body_motion(t)
        else:  # two distinct arrays: (np.zeros(n),) * 2 would alias q and v
            qf, vf = np.zeros(self.n_full), np.zeros(self.n_full)
        qf[self.free] = q
        vf[self.free] = v
        return qf, vf

    def full_batch(self, t, q, v) -> tuple[np.ndarray, np.ndarray]:
        """:meth:`full` at K states: ``t`` (K,), ``q``, ``v`` (K, n_free) → (K, n_full) each."""
        t = np.asarray(t, float)
        qf, vf = np.zeros((t.size, self.n_full)), np.zeros((t.size, self.n_full))
        if self.fixed.any():          # at rest in I: seen from R (as fixed_body_motion, K times at once)
            idx = np.flatnonzero(self.fixed)
            p = self.pose0[idx]
            fs = self.frame_batch(t)
            c, s = np.cos(fs.phi), np.sin(fs.phi)
            xr, yr = c * p[:, 0] + s * p[:, 1], -s * p[:, 0] + c * p[:, 1]
            qf[:, 3 * idx], qf[:, 3 * idx + 1], qf[:, 3 * idx + 2] = xr, yr, p[:, 2] - fs.phi
            vf[:, 3 * idx], vf[:, 3 * idx + 1], vf[:, 3 * idx + 2] = fs.omega * yr, -fs.omega * xr, -fs.omega
        qf[:, self.free] = q
        vf[:, self.free] = v
        return qf, vf

    def frame_batch(self, t) -> FrameState:
        """The frame's state at K times as one FrameState of (K, 1) columns (they broadcast over instances)."""
        t = np.asarray(t, float)[:, None]
        if self.frame.profile is None:
            return FrameState(self.frame.omega * t, np.full_like(t, self.frame.omega), np.zeros_like(t))
        fs = [self.frame.at(float(tk)) for tk in t[:, 0]]
        col = lambda key: np.array([getattr(f, key) for f in fs], float)[:, None]
        return FrameState(col("phi"), col("omega"), col("domega"))

    def poses(self, q_full: np.ndarray) -> np.ndarray:
        """(nb, 3) the bodies' (x, y, θ) of a full vector (tilt coordinates left out)."""
        return q_full[: self.n_body_coords].reshape(-1, 3)


def _checked_pose(name: str, pose) -> np.ndarray:
    pose = np.asarray(pose, dtype=float)
    if pose.shape != (3,) or not np.all(np.isfinite(pose)):
        raise ModelError(f"body {name!r}: pose must be finite (x [m], y [m], theta [rad]), got {pose!r}")
    return pose


def to_reference(pose_I: np.ndarray, vel_I: np.ndarray, fs: FrameState):
    """Poses/velocities (nb, 3) from the fixed frame I into the rotating frame R."""
    c, s = np.cos(fs.phi), np.sin(fs.phi)
    x, y = pose_I[:, 0], pose_I[:, 1]
    xr, yr = c * x + s * y, -s * x + c * y
    vx, vy = vel_I[:, 0], vel_I[:, 1]
    # v_R = Rot(-φ) v_I − Ω k × x_R
    vxr = c * vx + s * vy + fs.omega * yr
    vyr = -s * vx + c * vy - fs.omega * xr
    q = np.column_stack([xr, yr, pose_I[:, 2] - fs.phi])
    v = np.column_stack([vxr, vyr, vel_I[:, 2] - fs.omega])
    return q, v


def to_fixed(pose_R: np.ndarray, vel_R: np.ndarray, fs: FrameState, acc_R: np.ndarray | None = None):
    """Poses, velocities (and accelerations) (..., 3) from R into the fixed frame I."""
    c, s = np.cos(fs.phi), np.sin(fs.phi)
    x, y = pose_R[..., 0], pose_R[..., 1]
    vx, vy = vel_R[..., 0], vel_R[..., 1]
    W, dW = fs.omega, fs.domega
    q = np.stack([c * x - s * y, s * x + c * y, pose_R[..., 2] + fs.phi], axis=-1)
    # v_I = Rot(φ) (v_R + Ω k × x_R)
    ux, uy = vx - W * y, vy + W * x
    v = np.stack([c * ux - s * uy, s * ux + c * uy, vel_R[..., 2] + W], axis=-1)
    if acc_R is None:
        return q, v
    ax, ay = acc_R[..., 0], acc_R[..., 1]
    # a_I = Rot(φ) (a_R + 2Ω k × v_R + Ω̇ k × x_R − Ω² x_R)
    bx = ax - 2 * W * vy - dW * y - W * W * x
    by = ay + 2 * W * vx + dW * x - W * W * y
    a = np.stack([c * bx - s * by, s * bx + c * by, acc_R[..., 2] + dW], axis=-1)
    return q, v, a


@dataclass
class State:
    """Mutable integration state on the free DOFs.

    ``f`` is the total generalized force F(q, v, t) at this state (HHT needs F_n of the last step),
    ``z`` holds element internal states (e.g. a PI integrator), keyed by element family name.
    """
    t: float
    q: np.ndarray
    v: np.ndarray
    a: np.ndarray
    f: np.ndarray
    z: dict = field(default_factory=dict)

    def copy(self) -> "State":
        return State(self.t, self.q.copy(), self.v.copy(), self.a.copy(), self.f.copy(),
                     {k: np.array(v, copy=True) for k, v in self.z.items()})
