"""Recorder: chosen outputs at a fixed sampling rate, streamed to disk, written atomically.

Samples fall at t_start + k·dt. Between two accepted steps the state is interpolated (cubic Hermite
in q with v, in v with a; linear in a) and element outputs are evaluated there, so the sampling rate
is independent of the step size. Samples are buffered in memory up to ``chunk`` samples, then written
to a chunk file (atomic rename), so memory stays bounded on long runs. :meth:`finalize` streams the
chunks into one netCDF4/HDF5 file (readable with xarray or h5py) through a temporary file and an
atomic rename: a results file is either complete or absent.

Layout of the file (every variable and coordinate carries CF-style ``units`` and ``long_name``):

* ``time`` (time) [s];
* per :class:`BodyMotion` probe ``<name>``: coordinates ``<name>.body`` (body names) and ``axis``
  (x, y); ``<name>.position`` (time, <name>.body, axis) [m], ``<name>.angle`` (time, <name>.body) [rad],
  ``<name>.velocity`` [m/s], ``<name>.angular_velocity`` [rad/s], ``<name>.acceleration`` [m/s^2],
  ``<name>.angular_acceleration`` [rad/s^2] (lengths and angles are never in one variable);
* per :class:`ElementOutput` of family ``<f>``: ``<f>.<key>`` (time, <f>.instance) with the units and
  long name given in ``ElementOutput.meta``; the dimension ``<f>.instance`` has a coordinate of the same
  name (instance names from ``ElementOutput.instances``, else the index 0..n-1) and any further
  per-instance coordinates ``<f>.<coord>`` given there (listed in each variable's ``coordinates``);
* per :class:`DerivedOutput` ``<name>``: ``<name>`` (time, <name>.instance), a quantity a caller derives
  from each sample (e.g. a virtual sensor), with its units and long name.
"""
from __future__ import annotations

import contextlib
import io
import json
import os
import shutil
from dataclasses import dataclass
from pathlib import Path
from collections.abc import Mapping
from typing import Callable, Sequence

import numpy as np

from .errors import ModelError
from .model import to_fixed

__all__ = ["BodyMotion", "ElementOutput", "DerivedOutput", "Recorder", "atomic_write_bytes", "atomic_write_text", "hermite",
           "temporaries"]


def _tmp_for(path: Path) -> Path:
    return path.with_name(f".{path.name}.tmp{os.getpid()}")


def temporaries(folder, pid: int) -> list[Path]:
    """The temporary files of the atomic writes process ``pid`` began below ``folder`` and never finished (a
    process killed in a write leaves its file: no handler runs)."""
    return sorted(Path(folder).rglob(f".*.tmp{int(pid)}"))


@contextlib.contextmanager
def _discard_on_failure(tmp: Path):
    """A failed write (disk full, unwritable folder, interrupt) leaves no temporary file behind; the file it
    would have replaced stays as it was."""
    try:
        yield
    except BaseException:
        tmp.unlink(missing_ok=True)
        raise


def atomic_write_bytes(path, data: bytes) -> None:
    """Write ``data`` to ``path`` through a temporary file and os.replace: ``path`` is either the old or the
    new content, never a part (a failed write raises and leaves no temporary file)."""
    path = Path(path)
    tmp = _tmp_for(path)
    with _discard_on_failure(tmp):
        with open(tmp, "wb") as fh:
            fh.write(data)
            fh.flush()
            os.fsync(fh.fileno())
        os.replace(tmp, path)


def atomic_write_text(path, text: str) -> None:
    atomic_write_bytes(path, text.encode())


@dataclass(frozen=True)
class BodyMotion:
    """Pose, velocity and acceleration of bodies (all when ``bodies`` is None) in the reference frame
    R (``frame='reference'``) or the fixed frame I (``frame='fixed'``)."""
    name: str = "motion"
    bodies: Sequence[str] | None = None
    frame: str = "reference"
    quantities: Sequence[str] = ("q", "v", "a")

    def __post_init__(self):
        if self.frame not in ("reference", "fixed"):
            raise ModelError(f"BodyMotion.frame must be 'reference' or 'fixed', got {self.frame!r}")
        bad = set(self.quantities) - {"q", "v", "a"}
        if bad:
            raise ModelError(f"BodyMotion.quantities: unknown {sorted(bad)}; use q, v, a")


# BodyMotion quantity -> (name, units, words) of its translational (x, y) and its rotational part
BODY_QUANTITIES = {
    "q": (("position", "m", "position"), ("angle", "rad", "angle")),
    "v": (("velocity", "m/s", "velocity"), ("angular_velocity", "rad/s", "angular velocity")),
    "a": (("acceleration", "m/s^2", "acceleration"), ("angular_acceleration", "rad/s^2", "angular acceleration")),
}
_FRAME_WORDS = {"reference": "in the reference frame R", "fixed": "in the fixed frame I"}


@dataclass(frozen=True)
class ElementOutput:
    """Outputs of an element family (all its output keys when ``keys`` is None).

    ``meta`` maps an output key to (units, long_name) for the file's attributes (CF units: "N", "m",
    "rad", "1" for dimensionless). ``instances`` maps a coordinate name to (long_name, one value per
    instance): the entry "instance" names the instances (the dimension's own coordinate, e.g. roller
    names), others (e.g. "planet", "pair") become extra coordinates ``<family>.<name>`` along it.
    ``derived`` (optional): a function of the family's outputs (the dict of one evaluation) returning
    further per-instance arrays a caller derives from them (e.g. the film of a contact), recorded under
    their keys like the family's own. ``batched``: ``derived`` is elementwise over the samples, so a block's
    samples are handed to it at once (each output (S, n), each result (S, n)); else it is called sample by
    sample."""
    element: str
    keys: Sequence[str] | None = None
    meta: Mapping[str, tuple[str, str]] | None = None
    instances: Mapping[str, tuple[str, Sequence]] | None = None
    derived: Callable[[Mapping[str, np.ndarray]], Mapping[str, np.ndarray]] | None = None
    batched: bool = False

    def evaluate(self, outputs: Mapping[str, np.ndarray]) -> Mapping[str, np.ndarray]:
        """The family's outputs with the derived ones added."""
        return outputs if self.derived is None else {**outputs, **self.derived(outputs)}


@dataclass(frozen=True)
class DerivedOutput:
    """A quantity derived from each sample: ``fn(t, X, V, A, outputs)`` → one float per instance, where
    X, V, A are (n_bodies, 3) arrays of every body in the reference frame R (bodies at rest in I with
    their frame acceleration) and ``outputs`` the element outputs at the sample (evaluated once per sample
    and shared with the :class:`ElementOutput` probes). Recorded as ``<name>`` along ``<name>.instance``.
    ``batched``: ``fn`` is elementwise over the samples and takes a block's S samples at once — ``t`` (S,),
    X, V, A (S, n_bodies, 3), the outputs (S, n) — returning (S, n_instances); else it is called sample by
    sample."""
    name: str
    fn: Callable
    units: str
    long_name: str
    instances: Sequence[str] = ("0",)
    batched: bool = False


WRITE_BYTES = 64 * 2**20     # the chunks joined in memory up to this size when the results file is written


class Recorder:
    def __init__(self, path, dt: float, probes: Sequence, t_start: float = 0.0, chunk: int = 2000,
                 attrs: dict | None = None):
        if not (np.isfinite(dt) and dt > 0):
            raise ModelError(f"Recorder.dt must be > 0 s, got {dt!r}")
        self.path = Path(path)
        self.dt = float(dt)
        self.t_start = float(t_start)
        self.probes = list(probes)
        self.chunk = int(chunk)
        self.attrs = dict(attrs or {})
        self.parts = self.path.with_name(self.path.name + ".parts")
        self.next_index = 0
        self.n_chunks = 0
        self._buf: dict[str, list] = {}
        self._times: list[float] = []

    # binding to a model ------------------------------------------------------------------------
    def bind(self, model, system, state) -> None:
        self.model, self.system = model, system
        self.vars: dict[str, tuple[tuple[str, ...], dict]] = {}     # name -> (dims, attrs)
        self.coords: dict[str, tuple[str, list, dict]] = {}         # name -> (dim, values, attrs)
        self.dims: dict[str, int] = {}
        self._plan = []
        for p in self.probes:
            if isinstance(p, BodyMotion):
                names = list(p.bodies) if p.bodies is not None else list(model.body_names)
                idx = np.array([model.body(nm).index for nm in names], dtype=int)
                bdim = f"{p.name}.body"
                self._coord(bdim, bdim, names, "1", "body name")
                self._coord("axis", "axis", ["x", "y"], "1", "Cartesian axis of the frame")
                where = _FRAME_WORDS[p.frame]
                for qty in p.quantities:
                    (lin, lu, lw), (ang, au, aw) = BODY_QUANTITIES[qty]
                    self.vars[f"{p.name}.{lin}"] = (("time", bdim, "axis"),
                                                   {"units": lu, "long_name": f"body {lw} {where}"})
                    self.vars[f"{p.name}.{ang}"] = (("time", bdim), {"units": au, "long_name": f"body {aw} {where}"})
                self._plan.append(("body", p, idx))
            elif isinstance(p, ElementOutput):
                e = model.element(p.element)
                probe_out = p.evaluate(system.outputs(state.t, state.q, state.v, state.z)[e.name])
                keys = list(p.keys) if p.keys is not None else list(probe_out)
                missing = set(keys) - set(probe_out)
                if missing:
                    raise ModelError(f"element {e.name!r} has no outputs {sorted(missing)}; it has {sorted(probe_out)}")
                dim = f"{e.name}.instance"
                n = int(np.size(probe_out[keys[0]])) if keys else 0
                self.dims[dim] = n
                inst = dict(p.instances or {})
                long_name, values = inst.pop("instance", (f"instance index of element family {e.name}", range(n)))
                self._coord(dim, dim, values, "1", long_name)
                for c, (lname, vals) in inst.items():
                    self._coord(f"{e.name}.{c}", dim, vals, "1", lname)
                meta = dict(p.meta or {})
                for k in keys:
                    attrs = {"long_name": f"output {k!r} of element family {e.name}"}
                    if k in meta:
                        attrs = {"units": meta[k][0], "long_name": meta[k][1]}
                    if inst:
                        attrs["coordinates"] = " ".join(f"{e.name}.{c}" for c in inst)
                    self.vars[f"{e.name}.{k}"] = (("time", dim), attrs)
                self._plan.append(("elem", p, keys))
            elif isinstance(p, DerivedOutput):
                dim = f"{p.name}.instance"
                self._coord(dim, dim, p.instances, "1", f"instance of {p.name}")
                self.vars[p.name] = (("time", dim), {"units": p.units, "long_name": p.long_name})
                self._plan.append(("derived", p, None))
            else:
                raise ModelError(f"unknown probe {p!r}")
        self._buf = {k: [] for k in self.vars}

    def _coord(self, name: str, dim: str, values, units: str, long_name: str) -> None:
        values = list(values)
        if self.dims.setdefault(dim, len(values)) != len(values):
            raise ModelError(f"coordinate {name!r}: {len(values)} values for dimension {dim!r} of size "
                             f"{self.dims[dim]}")
        self.coords[name] = (dim, values, {"units": units, "long_name": long_name})

    # sampling ----------------------------------------------------------------------------------
    def due(self, t1: float) -> bool:
        """Whether a sample falls due at or before t1 (a step ending at t1 needs recording)."""
        return self.t_start + self.next_index * self.dt <= t1 + 1e-12 * max(1.0, abs(t1))

    def sample_times(self, t0: float, t1: float, include_start: bool) -> np.ndarray:
        """Sample times in (t0, t1] (and t0 itself if include_start)."""
        k0 = self.next_index
        ks = []
        k = k0
        while True:
            tk = self.t_start + k * self.dt
            if tk > t1 + 1e-12 * max(1.0, abs(t1)):
                break
            if tk > t0 + 1e-12 * max(1.0, abs(t0)) or (include_start and tk >= t0 - 1e-12 * max(1.0, abs(t0))):
                ks.append(k)
            k += 1
        return np.array(ks, dtype=int)

    def record(self, s0, s1, first: bool = False) -> None:
        """Record every sample time in (s0.t, s1.t] by interpolation (and s0.t itself if ``first``)."""
        if first:
            ks = self.sample_times(s0.t, s0.t, include_start=True)
            for k in ks:
                self._sample(self.t_start + k * self.dt, s0.q, s0.v, s0.a, s0.z)
                self.next_index = k + 1
            if s1 is None:
                return
        ks = self.sample_times(s0.t, s1.t, include_start=False)
        h = s1.t - s0.t
        for k in ks:
            t = self.t_start + k * self.dt
            th = min(1.0, max(0.0, (t - s0.t) / h))
            q, v, a = hermite(s0, s1, th, h)
            self._sample(t, q, v, a, s0.z)
            self.next_index = k + 1

    def record_block(self, block) -> None:
        """Every sample time in a compiled block's span (its start state's t, its last step's end], as
        :meth:`record` step by step, all its samples at once: the element outputs in one call
        (:meth:`mbd.System.outputs_batch`), the bodies' motion as (S, ...) arrays, appended to the chunk
        buffers as one block."""
        t = np.concatenate([[block.start.t], block.log[:, 0]])
        ks = self.sample_times(t[0], t[-1], include_start=False)
        if ks.size == 0:
            return
        ts = self.t_start + ks * self.dt
        tol = 1e-12 * np.maximum(1.0, np.abs(t))
        j = np.clip(np.searchsorted(t + tol, ts, side="left"), 1, t.size - 1) - 1    # sample in step (t_j, t_j+1]
        _, Q, V, A, Z = block.arrays()
        h = (t[j + 1] - t[j])[:, None]
        th = np.clip((ts[:, None] - t[j][:, None]) / h, 0.0, 1.0)
        q, v, a = hermite_rows(Q[j], V[j], A[j], Q[j + 1], V[j + 1], A[j + 1], th, h)
        z = {k: x[j] for k, x in Z.items()}                 # the step's start (as record: s0.z)
        outs = self.system.outputs_batch(ts, q, v, z) if self._needs_outputs else None
        self._samples(ts, q, v, a, outs)
        self.next_index = int(ks[-1]) + 1

    @property
    def _needs_outputs(self) -> bool:
        return any(kind != "body" for kind, _, _ in self._plan)

    def _samples(self, ts, q, v, a, outs) -> None:
        """S samples at times ``ts`` (S,) from their states ``q``, ``v``, ``a`` (S, n_free) and element outputs
        ``outs`` ({family: {key: (S, n)}}): the values :meth:`_sample` takes one by one, as (S, ...) arrays (the
        same operations, elementwise over the samples); a derived quantity whose function is not ``batched`` is
        evaluated sample by sample."""
        m = self.model
        S = ts.size
        qf, vf = m.full_batch(ts, q, v)
        af = np.zeros_like(qf)
        af[:, m.free] = a
        fs = m.frame_batch(ts)                               # (S, 1) columns
        if m.fixed.any() and not m.frame.is_inertial:
            _fixed_body_acceleration(m, fs, qf, vf, af)
        X, Vb, Ab = m.body_poses(qf), m.body_poses(vf), m.body_poses(af)      # (S, nb, 3)
        rows = None
        cols = {}
        for kind, p, sel in self._plan:
            if kind == "body":
                Qs, Vs, As = X[:, sel], Vb[:, sel], Ab[:, sel]
                if p.frame == "fixed":
                    Qs, Vs, As = to_fixed(Qs, Vs, fs, As)
                for qty, arr in zip("qva", (Qs, Vs, As)):
                    if qty in p.quantities:
                        (lin, _, _), (ang, _, _) = BODY_QUANTITIES[qty]
                        cols[f"{p.name}.{lin}"] = np.array(arr[..., :2])
                        cols[f"{p.name}.{ang}"] = np.array(arr[..., 2])
                continue
            if kind == "derived" and p.batched:
                cols[p.name] = np.asarray(p.fn(ts, X, Vb, Ab, outs), dtype=float).reshape(S, -1).copy()
                continue
            if kind == "elem" and (p.derived is None or p.batched):
                o = p.evaluate({key: np.ascontiguousarray(x, dtype=float) for key, x in outs[p.element].items()})
                shape = (S, self.dims[f"{p.element}.instance"])
                for k in sel:
                    cols[f"{p.element}.{k}"] = np.array(np.broadcast_to(np.asarray(o[k], dtype=float), shape))
                continue
            if rows is None:                                 # sample by sample: each sample's outputs, read lazily
                rows = [_SampleOutputs(outs, n) for n in range(S)]
            if kind == "derived":
                cols[p.name] = np.stack([np.asarray(p.fn(ts[n], X[n], Vb[n], Ab[n], rows[n]), dtype=float).reshape(-1)
                                         for n in range(S)])
            else:
                per = [p.evaluate(rows[n][p.element]) for n in range(S)]
                for k in sel:
                    cols[f"{p.element}.{k}"] = np.stack([np.asarray(o[k], dtype=float) for o in per])
        self._append(ts, cols)

    def _sample(self, t, q, v, a, z, outs=None):
        """One sample (the numpy engine's path, :meth:`record`): its outputs evaluated at the state unless given."""
        if outs is None and self._needs_outputs:
            outs = self.system.outputs(t, q, v, z)
        one = None if outs is None else {f: {key: np.asarray(x)[None] for key, x in o.items()} for f, o in outs.items()}
        self._samples(np.array([t], dtype=float), np.asarray(q)[None], np.asarray(v)[None], np.asarray(a)[None], one)

    def _append(self, ts, cols) -> None:
        """Buffer S samples (``cols``: each variable's (S, ...) array); whole chunks of ``chunk`` samples go to
        disk as soon as they are full (memory stays bounded)."""
        self._times.extend(float(x) for x in ts)
        for k, x in cols.items():
            self._buf[k].append(x)
        while len(self._times) >= self.chunk:
            self._write_chunk(self.chunk)

    # chunks, checkpoints, final file -----------------------------------------------------------
    def flush(self) -> None:
        """Write every buffered sample to a chunk file."""
        if self._times:
            self._write_chunk(len(self._times))

    def _write_chunk(self, n: int) -> None:
        """The first ``n`` buffered samples to the next chunk file (atomic); the rest stay buffered."""
        self.parts.mkdir(parents=True, exist_ok=True)
        arrays = {"time": np.array(self._times[:n])}
        rest = {}
        for k, lst in self._buf.items():
            x = lst[0] if len(lst) == 1 else np.concatenate(lst)
            arrays[k], rest[k] = x[:n], x[n:]
        bio = io.BytesIO()
        np.savez(bio, **{f"v{i}": a for i, a in enumerate(arrays.values())}, names=np.array(list(arrays)))
        atomic_write_bytes(self.parts / f"chunk_{self.n_chunks:06d}.npz", bio.getvalue())
        self.n_chunks += 1
        self._times = self._times[n:]
        self._buf = {k: ([rest[k]] if self._times else []) for k in self._buf}

    def checkpoint_state(self) -> dict:
        self.flush()
        return {"next_index": int(self.next_index), "n_chunks": int(self.n_chunks)}   # JSON-safe ints

    def restore(self, st: dict) -> None:
        self.next_index = int(st["next_index"])
        self.n_chunks = int(st["n_chunks"])
        self._times, self._buf = [], {k: [] for k in self._buf}
        if self.parts.exists():
            for f in self.parts.glob("chunk_*.npz"):
                if int(f.stem.split("_")[1]) >= self.n_chunks:
                    f.unlink()

    def reset(self) -> None:
        if self.parts.exists():
            shutil.rmtree(self.parts)
        self.next_index = 0
        self.n_chunks = 0

    def _chunks(self):
        for i in range(self.n_chunks):
            with np.load(self.parts / f"chunk_{i:06d}.npz") as d:
                names = list(d["names"])
                yield {nm: d[f"v{j}"] for j, nm in enumerate(names)}

    def _chunk_groups(self):
        """The chunks joined into groups of up to :data:`WRITE_BYTES` (each variable written once per group: a
        write into the file costs about as much for one sample as for thousands)."""
        group, size = [], 0
        for c in self._chunks():
            group.append(c)
            size += sum(x.nbytes for x in c.values())
            if size >= WRITE_BYTES:
                yield {k: np.concatenate([g[k] for g in group]) for k in group[0]}
                group, size = [], 0
        if group:
            yield group[0] if len(group) == 1 else {k: np.concatenate([g[k] for g in group]) for k in group[0]}

    def _samples_on_disk(self) -> int:
        total = 0
        for i in range(self.n_chunks):
            with np.load(self.parts / f"chunk_{i:06d}.npz") as d:
                total += d[f"v{list(d['names']).index('time')}"].shape[0]
        return total

    def finalize(self, attrs: dict | None = None) -> Path:
        """Stream all chunks into the results file (netCDF4 via h5netcdf) atomically; the chunks are removed
        only once the file is in place (a failed write keeps them and the checkpoint: the run can resume)."""
        self.flush()
        total = self._samples_on_disk()
        self.path.parent.mkdir(parents=True, exist_ok=True)
        tmp = _tmp_for(self.path)
        with _discard_on_failure(tmp):
            self._write(tmp, total, {**self.attrs, **(attrs or {})})
            os.replace(tmp, self.path)
        shutil.rmtree(self.parts, ignore_errors=True)
        return self.path

    def _write(self, tmp: Path, total: int, allattrs: dict) -> None:
        # deferred: HDF5 (≈ 0.1 s) only when results.nc is written, not in every `import mbd`
        import h5netcdf
        import h5py

        with h5netcdf.File(tmp, "w") as f:
            f.dimensions["time"] = total
            for key, val in allattrs.items():
                f.attrs[key] = val if isinstance(val, (int, float, str)) else json.dumps(val, default=float)
            tv = f.create_variable("time", ("time",), float)
            tv.attrs.update({"units": "s", "long_name": "time", "standard_name": "time"})
            for d, size in self.dims.items():
                f.dimensions[d] = size
            for name, (d, values, cattrs) in self.coords.items():
                if all(isinstance(x, str) for x in values):
                    # h5py has no conversion for numpy '<U' strings: variable-length UTF-8
                    cv = f.create_variable(name, (d,), h5py.string_dtype())
                    cv[:] = np.array(values, dtype=object)
                else:
                    arr = np.asarray(values)
                    cv = f.create_variable(name, (d,), arr.dtype)
                    cv[:] = arr
                cv.attrs.update(cattrs)
            created = {}
            for name, (dims, vattrs) in self.vars.items():
                created[name] = f.create_variable(name, dims, float, chunks=None)
                created[name].attrs.update(vattrs)
            i0 = 0
            for c in self._chunk_groups():
                n = c["time"].shape[0]
                tv[i0: i0 + n] = c["time"]
                for name in self.vars:
                    created[name][i0: i0 + n, ...] = c[name]
                i0 += n


class _SampleOutputs(Mapping):
    """Sample ``n`` of a block's element outputs ({family: {key: (S, n)}}) as one evaluation's {family: {key: (n,)}},
    each row read when asked for (a derived quantity evaluated sample by sample reads a few of them)."""

    def __init__(self, outs, n: int):
        self._outs, self._n = outs, n

    def __getitem__(self, family):
        return _SampleRow(self._outs[family], self._n)

    def __iter__(self):
        return iter(self._outs)

    def __len__(self):
        return len(self._outs)


class _SampleRow(Mapping):
    def __init__(self, out, n: int):
        self._out, self._n = out, n

    def __getitem__(self, key):
        return self._out[key][self._n]

    def __iter__(self):
        return iter(self._out)

    def __len__(self):
        return len(self._out)


def _fixed_body_acceleration(m, fs, qf, vf, af) -> None:
    """Acceleration in R of the bodies at rest in I (the frame terms with F = 0, docs/model.md §2.3):
    a fixed body seen from a rotating R accelerates, and to_fixed must map it back to zero. ``qf``, ``vf``,
    ``af`` (S, n_full) at S samples, the frame state ``fs`` of (S, 1) columns."""
    idx = np.flatnonzero(m.fixed)
    x, y, vx, vy = qf[:, 3 * idx], qf[:, 3 * idx + 1], vf[:, 3 * idx], vf[:, 3 * idx + 1]
    W, dW = fs.omega, fs.domega
    af[:, 3 * idx] = W * W * x + 2 * W * vy + dW * y
    af[:, 3 * idx + 1] = W * W * y - 2 * W * vx - dW * x
    af[:, 3 * idx + 2] = -dW


def hermite_rows(q0, v0, a0, q1, v1, a1, th, h):
    """The Hermite weights of :func:`hermite` applied to the step ends; for many steps at once pass rows of
    the ends and ``th``, ``h`` as (S, 1) columns."""
    th2 = th * th           # products, not powers: a scalar and an array then round alike
    th3 = th2 * th
    h00 = 2 * th3 - 3 * th2 + 1
    h10 = th3 - 2 * th2 + th
    h01 = -2 * th3 + 3 * th2
    h11 = th3 - th2
    q = h00 * q0 + h10 * h * v0 + h01 * q1 + h11 * h * v1
    v = h00 * v0 + h10 * h * a0 + h01 * v1 + h11 * h * a1
    a = (1 - th) * a0 + th * a1
    return q, v, a


def hermite(s0, s1, th, h):
    """Cubic Hermite interpolation of (q, v) and linear of a at fraction th of the step."""
    if th <= 0.0:
        return s0.q, s0.v, s0.a
    if th >= 1.0:
        return s1.q, s1.v, s1.a
    return hermite_rows(s0.q, s0.v, s0.a, s1.q, s1.v, s1.a, th, h)
