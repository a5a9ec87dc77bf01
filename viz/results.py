"""Saved DPGT results (``results.nc`` of scenarios.core.runner) → the arrays the animations draw.

:func:`load_run` reads one results file (or a run directory holding ``results.nc``) into a :class:`Run`:
times, body names, body motion in the reference frame R, the fixed-frame motion of sun/carrier/ring,
element outputs, the bearing map and the run metadata.  The helpers turn a run into animation input:

* :func:`cage_orbits` — cage centre relative to its planet's bore centre, in carrier axes [m];
* :func:`roller_offsets` — roller centres relative to their ideal pocket positions, in cage axes [m];
* :func:`train_bodies` — the ``bodies`` list of :func:`viz.animate.train_animation`, seen from the
  carrier or from the housing;
* :func:`study_cage_animation` — the four-panel forward/reverse cage-orbit animation of the study.

Geometry (tooth counts, pitch radii, bearing d_m, D, guide clearance) is not part of the motion data.
It is read from the file's ``geometry`` attribute (or ``meta["geometry"]``), in the layout of
:func:`components.results.schema.drawing_geometry`, which the runner stores there. A caller may pass
``fallback_geometry`` for whatever a file lacks; ``run.geometry["source"]`` says which was used
("file", "file+given" or "given"), and given geometry is checked against the recorded motion (planet
centre distances, roller pitch radius): a :class:`GeometryWarning` is issued when they disagree.

viz reads results only, through :mod:`components.results` (which opens the files and imports nothing of the
engine): it imports neither mbd nor the rest of components — only numpy, xarray and matplotlib/pyvista.
"""
from __future__ import annotations

import json
import keyword
import re
import warnings
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from components.results import ResultsError, json_attr, open_dataset, read_results

from .plots import cage_orbit_picture

__all__ = ["ResultsError", "GeometryWarning", "Run", "load_run", "attribute_name", "attribute_names", "open_results", "cage_orbits", "roller_offsets", "train_bodies", "study_cage_animation",
           "study_cage_pictures",
           "cage_panels", "view_angle"]

_REQUIRED_VARS = ("time", "motion.position", "motion.angle")
_REQUIRED_ATTRS = ("bearings", "meta")


class GeometryWarning(UserWarning):
    """The drawing geometry does not match the recorded motion."""


# ----------------------------------------------------------------------------------------------
# geometry

def _merge(base: dict, over: Mapping) -> tuple[dict, bool]:
    """base updated recursively with over; also whether base supplied anything over lacked."""
    out, filled = dict(base), any(k not in over for k in base)
    for k, v in over.items():
        if isinstance(v, Mapping) and isinstance(base.get(k), Mapping):
            out[k], f = _merge(base[k], v)
            filled |= f
        else:
            out[k] = v
    return out, filled


# ----------------------------------------------------------------------------------------------
# the run

@dataclass(frozen=True, eq=False)
class Run:
    """One DPGT results file in memory.  Arrays are numpy, SI units; motion is (n_t, n_bodies, 3) with
    the last axis (x, y, θ) in the reference frame R."""
    path: Path
    t: np.ndarray
    bodies: tuple[str, ...]
    q: np.ndarray
    v: np.ndarray | None
    a: np.ndarray | None
    fixed_bodies: tuple[str, ...]
    fixed_q: np.ndarray | None
    outputs: Mapping[str, np.ndarray]
    bearings: tuple[dict, ...]
    meta: dict
    label: dict
    info: dict
    geometry: dict
    frame_angle: np.ndarray          # φ_R(t): angle of R relative to the fixed frame [rad]
    _index: dict = field(default_factory=dict, repr=False)

    @property
    def n_t(self) -> int:
        return self.t.size

    @property
    def direction(self) -> str:
        return str(self.meta.get("direction", "unknown"))

    @property
    def frame(self) -> str:
        return str(self.meta.get("frame", "rotating"))

    @property
    def carrier_speed(self) -> float:
        """Nominal carrier speed Ω_c [rad/s] (signed: negative in reverse)."""
        try:
            return float(self.meta["speeds_rad_s"]["carrier"])
        except (KeyError, TypeError) as exc:
            raise ResultsError(f"{self.path}: meta has no speeds_rad_s.carrier") from exc

    def index(self, name: str) -> int:
        try:
            return self._index[name]
        except KeyError:
            raise ResultsError(f"{self.path}: no body {name!r} in motion.body") from None

    def pose(self, name: str) -> np.ndarray:
        """(n_t, 3) pose of one body in R."""
        return self.q[:, self.index(name)]

    def output(self, key: str) -> np.ndarray:
        """(n_t, n) element output '<family>.<key>'."""
        if key not in self.outputs:
            raise ResultsError(f"{self.path}: no element output {key!r}; the file has "
                               f"{sorted(self.outputs)}")
        return self.outputs[key]

    def bearing(self, which: str | Mapping = "inner", pair: int = 0) -> dict:
        """A bearing record: by name ("a1.pb"), or by kind ("inner"/"outer") and pair index."""
        if isinstance(which, Mapping):
            return dict(which)
        for b in self.bearings:
            if b["name"] == which or (b["kind"] == which and b["pair"] == pair):
                return b
        raise ResultsError(f"{self.path}: no bearing {which!r}" + (f" in pair {pair + 1} (index {pair})" if which in
                           ("inner", "outer") else "") + "; bearings: "
                           + ", ".join(b["name"] for b in self.bearings))

    @property
    def pairs(self) -> list[int]:
        return sorted({int(b["pair"]) for b in self.bearings})


def _pose(res, probe: str, linear: str, angular: str) -> np.ndarray | None:
    """(n_t, n_bodies, 3) array (x, y, θ) from the file's ``<probe>.<linear>`` (time, body, axis) and
    ``<probe>.<angular>`` (time, body) variables; None when the file lacks them."""
    lin, ang = f"{probe}.{linear}", f"{probe}.{angular}"
    if lin not in res or ang not in res:
        return None
    return np.concatenate([np.asarray(res[lin], float), np.asarray(res[ang], float)[..., None]], axis=-1)


def load_run(path, fallback_geometry: Mapping | None = None) -> Run:
    """Read a DPGT results file (netCDF4 written by scenarios.core.runner) or a run directory holding one.

    ``fallback_geometry`` (the layout of :func:`components.results.schema.drawing_geometry`) supplies
    whatever drawing geometry the file lacks; it is checked against the recorded motion.

    The file is read whole with :func:`components.results.read_results` (h5py, no xarray). Raises
    :class:`ResultsError` with a clear message for a missing file, a file that is not netCDF4/HDF5, or a netCDF
    file without the DPGT layout (time, motion.position, motion.angle, bearings, meta)."""
    res = read_results(path)
    path = res.path
    missing = [v for v in _REQUIRED_VARS if v not in res]
    missing += [f"attribute {a!r}" for a in _REQUIRED_ATTRS if a not in res.attrs]
    if missing:
        raise ResultsError(f"{path} is not a DPGT results file: it lacks {', '.join(missing)}")
    t = np.asarray(res["time"], float)
    if t.ndim != 1 or t.size == 0:
        raise ResultsError(f"{path}: the results hold no samples (time is empty)")
    if res.dims["motion.position"] != ("time", "motion.body", "axis") or res["motion.position"].shape[2] != 2:
        raise ResultsError(f"{path} is not a DPGT results file: motion.position has dims "
                           f"{res.dims['motion.position']}")
    bodies = tuple(str(b) for b in res["motion.body"])
    q = _pose(res, "motion", "position", "angle")
    v = _pose(res, "motion", "velocity", "angular_velocity")
    a = _pose(res, "motion", "acceleration", "angular_acceleration")
    fixed_q = _pose(res, "fixed", "position", "angle") if "fixed.body" in res else None
    fixed_bodies = tuple(str(b) for b in res["fixed.body"]) if fixed_q is not None else ()
    outputs = {k: np.asarray(res[k], float) for k in res.data_vars
               if not (k.startswith("motion.") or k.startswith("fixed."))}
    attrs = dict(res.attrs)
    bearings = json_attr(attrs, "bearings", path)
    meta = json_attr(attrs, "meta", path)
    if not isinstance(bearings, list) or not isinstance(meta, dict):
        raise ResultsError(f"{path} is not a DPGT results file: 'bearings' must be a list and 'meta' "
                           "a mapping")
    label = json_attr(attrs, "label", path) if "label" in attrs else {}
    info = json_attr(attrs, "run", path) if "run" in attrs else {}
    index = {b: i for i, b in enumerate(bodies)}
    for b in bearings:
        for nm in [b.get("planet"), b.get("cage"), *b.get("rollers", [])]:
            if nm is not None and nm not in index:
                raise ResultsError(f"{path}: bearing {b.get('name')!r} names body {nm!r}, which is not "
                                   "in motion.body")

    geometry = _resolve_geometry(path, attrs, meta, fallback_geometry)

    # φ_R: exact from the carrier's pose in both frames when the file has it (θ_I = θ_R + φ),
    # otherwise from the metadata (R turns at the nominal carrier speed, or not at all).
    if fixed_q is not None and "carrier" in fixed_bodies and "carrier" in index:
        phi = fixed_q[:, fixed_bodies.index("carrier"), 2] - q[:, index["carrier"], 2]
    else:
        rotating = meta.get("frame", "rotating") == "rotating"
        try:
            om = float(meta["speeds_rad_s"]["carrier"]) if rotating else 0.0
        except (KeyError, TypeError):
            raise ResultsError(f"{path}: cannot tell how R turns (no fixed.position/angle of the carrier and no "
                               "meta speeds_rad_s.carrier)") from None
        phi = om * t
    run = Run(path=path, t=t, bodies=bodies, q=q, v=v, a=a, fixed_bodies=fixed_bodies, fixed_q=fixed_q,
              outputs=outputs, bearings=tuple(bearings), meta=meta, label=label or {}, info=info or {},
              geometry=geometry, frame_angle=np.asarray(phi, float), _index=index)
    if geometry["source"] != "file":
        _check_geometry(run)
    return run


# ----------------------------------------------------------------------------------------------
# names xarray's attribute access can use

def attribute_name(name: str) -> str:
    """The name :func:`attribute_names` gives a results.nc variable, coordinate or dimension: every character that
    cannot stand in a Python identifier becomes "_" ("race_inner.load" → "race_inner_load", "motion.body" →
    "motion_body", "bearing.load_radial.instance" → "bearing_load_radial_instance")."""
    out = re.sub(r"\W", "_", str(name))
    if not out or out[0].isdigit():
        out = "v_" + out
    return out + "_" if keyword.iskeyword(out) else out


def attribute_names(ds):
    """An xarray Dataset of results.nc (``xarray.open_dataset``) renamed so that attribute access reaches every
    variable, coordinate and dimension: ``ds.race_inner_load`` for ``ds["race_inner.load"]``,
    ``ds.race_inner_load.sel(race_inner_instance=...)``. The file keeps its dotted names (every reader uses them);
    each renamed variable keeps its name in the file as ``attrs["results_name"]``, and the dataset the whole
    mapping as ``attrs["results_names"]`` (JSON, new → file name). Raises :class:`ResultsError` if two names would
    meet or a name would hide behind a Dataset attribute (``ds.mean``)."""
    import xarray as xr  # deferred: ≈ 0.4 s; ds comes from xarray, `dpgt animate` need not pay for it

    names = list(dict.fromkeys([*ds.variables, *ds.dims]))
    mapping = {n: attribute_name(n) for n in names if attribute_name(n) != n}
    new_names = [mapping.get(n, n) for n in names]
    clash = sorted({x for x in new_names if new_names.count(x) > 1})
    if clash:
        raise ResultsError(f"attribute names would meet: {clash}")
    hidden = sorted(x for x in set(new_names) if hasattr(xr.Dataset, x))
    if hidden:
        raise ResultsError(f"attribute names would hide behind Dataset attributes: {hidden}")
    out = ds.rename(mapping)
    for old, new in mapping.items():
        if new in out.variables:
            out[new].attrs["results_name"] = old
    out.attrs["results_names"] = json.dumps({new: old for old, new in mapping.items()})
    return out


def open_results(path, attribute_access: bool = True):
    """``xarray.open_dataset`` of a results.nc (or a run directory holding one), with :func:`attribute_names`
    applied unless ``attribute_access`` is false."""
    ds = open_dataset(path)
    return attribute_names(ds) if attribute_access else ds


def _resolve_geometry(path: Path, attrs: Mapping, meta: Mapping, given: Mapping | None) -> dict:
    """The file's drawing geometry, completed from ``given``; ``source`` says which was used."""
    g_file = None
    if "geometry" in attrs:
        g_file = json_attr(attrs, "geometry", path)
    elif isinstance(meta.get("geometry"), Mapping):
        g_file = meta["geometry"]
    if given is None:
        if not g_file:
            raise ResultsError(f"{path} has no drawing geometry (attribute 'geometry'); pass load_run(..., "
                               "fallback_geometry=components.results.schema.drawing_geometry(params))")
        return {**json.loads(json.dumps(g_file)), "source": "file"}
    geometry, filled = _merge(json.loads(json.dumps(dict(given))), g_file or {})
    geometry["source"] = ("file+given" if filled else "file") if g_file else "given"
    return geometry


def _check_geometry(run: Run) -> None:
    """Warn when the (fallback) geometry does not fit the recorded motion: radii off by > 2 %."""
    g = run.geometry
    problems = []
    if "sun" in run._index:
        sun = run.pose("sun")[:, :2]
        for prefix, key in (("a", "r_ca"), ("b", "r_cb")):
            names = [b for b in run.bodies if b[:1] == prefix and b[1:].isdigit()]
            if names:
                r = np.mean([np.hypot(*(run.pose(n)[:, :2] - sun).T).mean() for n in names])
                if abs(r / g[key] - 1) > 0.02:
                    problems.append(f"{key} {g[key] * 1e3:.2f} mm vs {r * 1e3:.2f} mm recorded")
    b = next((b for b in run.bearings if b.get("rollers")), None)
    if b is not None:
        c = run.pose(b["planet"])[:, None, :2]
        p = np.stack([run.pose(nm)[:, :2] for nm in b["rollers"]], axis=1)
        rho = float(np.hypot(*(p - c).transpose(2, 0, 1)).mean())
        dm2 = 0.5 * g["bearing"]["d_m"]
        if abs(rho / dm2 - 1) > 0.02:
            problems.append(f"d_m/2 {dm2 * 1e3:.2f} mm vs roller pitch radius {rho * 1e3:.2f} mm recorded")
        if len(b["rollers"]) != int(g["bearing"]["Z"]):
            problems.append(f"Z {g['bearing']['Z']} vs {len(b['rollers'])} rollers recorded")
    if problems:
        warnings.warn(f"{run.path}: drawing geometry ({g['source']}) does not match the recorded "
                      f"motion: {'; '.join(problems)}", GeometryWarning, stacklevel=3)


# ----------------------------------------------------------------------------------------------
# derived quantities

def _rot(phi: np.ndarray, xy: np.ndarray) -> np.ndarray:
    """Rotate (n_t, ..., 2) vectors by the angle φ (n_t,)."""
    c, s = np.cos(phi), np.sin(phi)
    shape = (-1,) + (1,) * (xy.ndim - 2)
    c, s = c.reshape(shape), s.reshape(shape)
    return np.stack([c * xy[..., 0] - s * xy[..., 1], s * xy[..., 0] + c * xy[..., 1]], axis=-1)


def _require_cage(run: Run, b: Mapping) -> str:
    if not b.get("cage"):
        kind = b.get("type", "rollers")
        raise ResultsError(f"{run.path}: bearing {b['name']!r} has no cage body (bearings modelled as "
                           f"{kind!r}{', cage off' if kind == 'rollers' else ''})")
    return b["cage"]


def cage_orbits(run: Run, pair: int | None = 0, frame: str = "carrier") -> dict[str, np.ndarray]:
    """Cage-centre offset e = c_cage − c_bore (the bore centre is the planet centre) [m].

    pair=n → {"inner": (n_t, 2), "outer": (n_t, 2)} for the bearings of planet pair n (index 0, pair 1, is the
    reference pair of the study); pair=None → {bearing name: (n_t, 2)} for every bearing.
    frame: axes of the offset, see :func:`view_angle`; "carrier" (default) is the frame R itself for a
    run in the rotating frame and makes runs in either frame comparable.  |e| is the guide contact's
    eccentricity ε (docs/model.md §8.6)."""
    if pair is None:
        chosen = {b["name"]: b for b in run.bearings}
    else:
        chosen = {k: run.bearing(k, pair) for k in ("inner", "outer")}
    ang = view_angle(run, frame)
    return {k: _rot(ang, run.pose(_require_cage(run, b))[:, :2] - run.pose(b["planet"])[:, :2])
            for k, b in chosen.items()}


def roller_offsets(run: Run, bearing: str | Mapping = "inner", pair: int = 0) -> np.ndarray:
    """(n_t, Z, 2) offsets of the rollers from their ideal positions, in the axes of pocket j [m].

    Ideal position of roller j: centred in pocket j (angle θ_g + 2πj/Z, docs/model.md §8.5) on the circle
    d_m/2 about the pin.  The offset is expressed in cage axes, where pocket j lies at the fixed angle
    ψ_j = 2πj/Z, as radial·(cos ψ_j, sin ψ_j) + tangential·(−sin ψ_j, cos ψ_j) with
      tangential = s_j = (d_m/2)·wrap(β_j − θ_g − ψ_j), β_j the angle of the roller about the cage
                   centre: the roller's position in its pocket (the pocket contact's offset, ±C_p free);
      radial     = |p_j − c_pin| − d_m/2: the roller's radial play about the inner raceway (= −δ_i).
    This is the ``rollers`` input of :func:`viz.animate.cage_orbit_animation`.
    bearing: a bearing name ("b1.pb"), a kind ("inner"/"outer", with pair) or a bearing record."""
    b = run.bearing(bearing, pair)
    cage = run.pose(_require_cage(run, b))
    rollers = b.get("rollers") or []
    if not rollers:
        raise ResultsError(f"{run.path}: bearing {b['name']!r} has no rollers")
    Z = len(rollers)
    r = 0.5 * run.geometry["bearing"]["d_m"]
    p = np.stack([run.pose(nm)[:, :2] for nm in rollers], axis=1)            # (n_t, Z, 2)
    psi = 2 * np.pi * np.arange(Z) / Z
    d = p - cage[:, None, :2]
    beta = np.arctan2(d[..., 1], d[..., 0])
    s = r * np.angle(np.exp(1j * (beta - cage[:, 2:3] - psi[None])))        # wrapped to (−π, π]
    pin = _pin_xy(run)[b["planet"]]
    radial = np.hypot(*(p - pin[:, None, :]).transpose(2, 0, 1)) - r
    c, sn = np.cos(psi)[None], np.sin(psi)[None]
    return np.stack([radial * c - s * sn, radial * sn + s * c], axis=-1)


def view_angle(run: Run, frame: str) -> np.ndarray:
    """Angle (n_t,) that turns R vectors into the viewing frame: x_view = Rot(angle)·x_R.

    "fixed": the housing (angle φ_R).  "carrier": axes turning at the nominal carrier speed
    (angle φ_R − Ω_c t) — the frame R itself for a run in the rotating frame."""
    if frame == "fixed":
        return run.frame_angle
    if frame == "carrier":
        return run.frame_angle - run.carrier_speed * run.t
    raise ValueError(f"frame must be 'carrier' or 'fixed', got {frame!r}")


def _pin_locals(run: Run) -> dict[str, np.ndarray]:
    """Planet pin centres in carrier axes, by planet name.

    The geometry's pin positions when they fit the recorded planets (within 0.5 mm); otherwise an
    estimate: the nominal radius (r_ca, r_cb) at the planet's mean angle about the carrier."""
    g = run.geometry
    car = run.pose("carrier")
    out = {}
    for b in run.bearings:
        nm = b["planet"]
        rel = _rot(-car[:, 2], run.pose(nm)[:, :2] - car[:, :2]).mean(axis=0)
        pins = (g.get("pins") or {}).get(b["kind"]) or []
        n = int(b["pair"])
        if n < len(pins) and np.hypot(*(np.asarray(pins[n], float) - rel)) < 5e-4:
            out[nm] = np.asarray(pins[n], float)
        else:
            r = g["r_ca"] if b["kind"] == "inner" else g["r_cb"]
            out[nm] = r * rel / np.hypot(*rel)
    return out


def _pin_xy(run: Run) -> dict[str, np.ndarray]:
    """(n_t, 2) pin centres in R by planet name: carrier centre + Rot(θ_c)·pin."""
    car = run.pose("carrier")
    return {nm: car[:, :2] + _rot(car[:, 2], np.broadcast_to(p, (run.n_t, 2)))
            for nm, p in _pin_locals(run).items()}


def train_bodies(run: Run, frame: str = "carrier", magnify: float = 1.0,
                 rollers: bool = True) -> list[dict]:
    """The ``bodies`` list of :func:`viz.animate.train_animation` for the whole train.

    Sun, ring and planets (pitch circles with their teeth), the carrier plate (radius 1.2 r_cb, the
    inertia rule's disc) and its pins (the inner raceways, radius R_i), and per bearing the cage (its
    pitch circle d_m/2) and the rollers (diameter D) coloured by their inner-race load race_inner.load.

    frame: "carrier" (axes turning at the nominal carrier speed: the carrier stands still) or "fixed"
    (the housing: the carrier turns).  Positions are rotated from R with :func:`view_angle`, angles get
    the same angle added.
    magnify: displacements from the nominal positions are multiplied by this factor here, so pass
    magnify=1 to train_animation (a factor given there multiplies again).  Nominal centres ("ref" of each
    body): the origin for sun, ring and carrier; for a pin, planet and cage the pin position at the
    carrier's *actual* angle with the carrier centred; for a roller that point plus d_m/2 towards the
    roller.  So the supports' translations, the bearing deflections and the rollers' radial play
    (−inner-race deflection) are magnified, but neither the carrier's speed fluctuation nor a
    roller's travel round its bearing.
    """
    mag = float(magnify)
    if not (np.isfinite(mag) and mag > 0):
        raise ValueError(f"magnify must be a positive number, got {magnify!r}")
    g = run.geometry
    ang = view_angle(run, frame)
    n_t = run.n_t
    origin = np.zeros((n_t, 2))

    def xy_th(name):
        pq = run.pose(name)
        return _rot(ang, pq[:, :2]), pq[:, 2] + ang

    def body(name, kind, radius, ref, teeth=None, force=None, xy=None, theta=None):
        if xy is None:
            xy, theta = xy_th(name)
        ref = np.broadcast_to(np.asarray(ref, float), (n_t, 2))
        d = {"name": name, "kind": kind, "radius": float(radius), "xy": ref + mag * (xy - ref),
             "theta": theta, "ref": ref}
        if teeth:
            d["teeth"] = int(teeth)
        if force is not None:
            d["force"] = force
        return d

    R, T = g["pitch_radius"], g["teeth"]
    out = [body("ring", "ring", R["ring"], origin, T["ring"]),
           body("carrier", "carrier", g["carrier_radius"], origin),
           body("sun", "gear", R["sun"], origin, T["sun"])]
    car_xy, car_th = xy_th("carrier")
    pins = _pin_locals(run)
    load = run.outputs.get("race_inner.load")
    B = g["bearing"]
    for b in run.bearings:
        planet = b["planet"]
        pin_rel = _rot(car_th, np.broadcast_to(pins[planet], (n_t, 2)))
        pin_ref, pin_xy = pin_rel, car_xy + pin_rel
        out.append(body(f"{planet}.pin", "carrier", B["R_i"], pin_ref, xy=pin_xy, theta=car_th))
        key = "inner_planet" if b["kind"] == "inner" else "outer_planet"
        out.append(body(planet, "gear", R[key], pin_ref, T[key]))
        if b.get("cage"):
            out.append(body(b["cage"], "cage", 0.5 * B["d_m"], pin_ref))
        if rollers and b.get("rollers"):
            i0 = b.get("race_inner", [None])[0]
            for j, nm in enumerate(b["rollers"]):
                xy, th = xy_th(nm)
                rel = xy - pin_xy
                ref = pin_ref + 0.5 * B["d_m"] * rel / np.hypot(rel[:, :1], rel[:, 1:])
                f = load[:, i0 + j] if load is not None and i0 is not None else None
                out.append(body(nm, "roller", 0.5 * B["D"], ref, force=f, xy=xy, theta=th))
    return out


# ----------------------------------------------------------------------------------------------
# cage-orbit panels (CLI --kind cage, --compare, and the forward/reverse study)

def _as_run(r) -> Run:
    return r if isinstance(r, Run) else load_run(r)


def _run_tag(run: Run, others: Sequence[Run]) -> str:
    """A short name of the run for a panel title: its direction, or its directory when they clash."""
    tag = run.direction
    if sum(o.direction == run.direction for o in others) > 1 or tag == "unknown":
        tag = run.path.parent.name or run.path.stem
    return tag


def cage_panels(runs: Sequence, pair: int = 0, rollers: bool = True) -> dict:
    """Arguments of :func:`viz.animate.cage_orbit_animation` for one or more runs.

    Panels are ordered inner(run 1), inner(run 2), ..., outer(run 1), outer(run 2), ....  Runs sampled
    on different grids are compared on the first run's times from its window start: the others are
    interpolated onto t − t_0 and the window is cut to the shortest run.  The time label shows the
    first run's time.  Returns dict(t, orbits, clearance_m, rollers)."""
    runs = [_as_run(r) for r in runs]
    if not runs:
        raise ValueError("no runs given")
    t0 = runs[0].t
    rel = [r.t - r.t[0] for r in runs]
    span = min(x[-1] for x in rel)
    keep = rel[0] <= span * (1 + 1e-9) + 1e-15
    t_rel = rel[0][keep]
    if len(runs) > 1 and t_rel.size < 2:
        raise ResultsError("the runs to compare have no common time window")

    def on_grid(k, arr):
        if k == 0:
            return arr[keep]
        if arr.shape[0] == runs[0].t.size and np.allclose(rel[k], rel[0], rtol=0, atol=1e-12):
            return arr[keep]  # same sampling: no interpolation
        flat = arr.reshape(arr.shape[0], -1)
        out = np.column_stack([np.interp(t_rel, rel[k], flat[:, c]) for c in range(flat.shape[1])])
        return out.reshape((t_rel.size,) + arr.shape[1:])

    tags = [_run_tag(r, runs) for r in runs]
    orbits, clr, rol = {}, {}, {}
    for kind in ("inner", "outer"):
        for k, r in enumerate(runs):
            lab = f"{kind} PB, {tags[k]}" if len(runs) > 1 else f"{kind} PB"
            orbits[lab] = on_grid(k, cage_orbits(r, pair)[kind])
            clr[lab] = float(r.geometry["bearing"]["guide_clearance"])
            if rollers:
                rol[lab] = on_grid(k, roller_offsets(r, kind, pair))
    return {"t": t0[keep], "orbits": orbits, "clearance_m": clr, "rollers": rol or None}


def _rpm(run: Run) -> str:
    try:
        return f"{abs(run.carrier_speed) * 30 / np.pi:.0f} r/min"
    except ResultsError:
        return ""


def study_cage_animation(run_fwd_path, run_rev_path, out_path, *, pair: int = 0, fps: float = 20,
                         size: Sequence[int] = (1600, 460), max_frames: int | None = None,
                         magnify: float | None = None, rollers: bool = True,
                         title: str | None = None) -> Path:
    """Four panels — inner PB forward, inner PB reverse, outer PB forward, outer PB reverse — of the
    cage-centre orbit inside the guide clearance circle C_g, for planet pair ``pair`` (0: the
    reference pair), with the rollers' pocket offsets drawn schematically (magnified, see
    :func:`viz.animate.cage_orbit_animation`).  Paths may be results files, run directories or
    :class:`Run` objects.  Raises ResultsError when the runs are not a forward and a reverse run."""
    fwd, rev = _as_run(run_fwd_path), _as_run(run_rev_path)
    for r, want in ((fwd, "forward"), (rev, "reverse")):
        if r.direction != want:
            raise ResultsError(f"{r.path} is a {r.direction!r} run, expected {want!r}")
    args = cage_panels([fwd, rev], pair=pair, rollers=rollers)
    if title is None:
        title = f"Cage orbits in the guide clearance, planet pair {pair + 1}, carrier {_rpm(fwd)}"
    from .animate import cage_orbit_animation  # deferred: pyvista/VTK only when an animation is made
    return cage_orbit_animation(out_path, args["t"], args["orbits"], args["clearance_m"],
                                magnify=magnify, rollers=args["rollers"], fps=fps, size=size,
                                title=title, max_frames=max_frames)


def study_cage_pictures(runs: Mapping[str, object], out_dir, *, pair: int = 0, prefix: str = "",
                        title: str | None = None, frame: str = "carrier") -> list[Path]:
    """Static cage-orbit pictures of a study, one PNG per bearing type (``{prefix}cage_orbit_{inner,outer}.png``
    in ``out_dir``): a panel per run (label -> results file, run directory or :class:`Run`, e.g. forward and
    reverse) with the guide clearance circle and the cage centre's trail coloured by time
    (:func:`viz.plots.cage_orbit_picture`), the offsets in ``frame``'s axes (:func:`cage_orbits`), which the picture
    names. Runs without a cage are left out; no runs with one: no picture."""
    loaded = {label: _as_run(r) for label, r in runs.items()}
    paths = []
    for kind in ("inner", "outer"):
        panels = []
        for label, run in loaded.items():
            try:
                e = cage_orbits(run, pair, frame)[kind]
            except ResultsError:              # bearings without a cage: nothing to draw
                continue
            panels.append((label, run.t, e, float(run.geometry["bearing"]["guide_clearance"])))
        if not panels:
            continue
        rpm = _rpm(next(iter(loaded.values())))
        head = (title + "\n" if title else "") + f"{kind} planet bearing, planet pair {pair + 1}" + (f", carrier {rpm}" if rpm else "")
        paths.append(cage_orbit_picture(panels, Path(out_dir) / f"{prefix}cage_orbit_{kind}.png", title=head,
                                        frame=frame))
    return paths
