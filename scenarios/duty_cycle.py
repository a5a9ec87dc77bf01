"""Bearing life over a duty cycle: a load spectrum of speed–torque bins, each solved, the lives combined.

    python -m scenarios.duty_cycle --cycle examples/duty_cycles/forward.toml --out results/duty_cycle
    python -m scenarios.duty_cycle --cycle my_log.csv --speed-bin "250 rpm" --torque-bin "100 N*m" --params my.toml

The cycle (:func:`read_cycle`) is a table of bins — a speed (the carrier's or the sun's), a torque or a power, a time
(hours, or a share of the cycle's time), optionally a direction and an oil temperature, a name — in TOML
(``[[bin]]`` tables) or CSV (a header row, a unit in brackets after a column's name), or a torque–speed time series
(a CSV with a ``time`` column) that the command bins itself (:func:`bin_series`). Every bin is an operating point
(:mod:`scenarios.core.points`) solved quasi-statically (:mod:`components.static`: the mean loads and the lives in
seconds), the bins named in ``--dynamic`` also by time integration; on Dask, resumable like every sweep.
``--dynamic auto`` makes it a study of two phases: every bin statically, then dynamically the fewest bins that carry
``--dynamic-share`` of every planet bearing's damage by those static lives (:func:`dominant_bins`), named with the
shares they carry before their runs start.

The lives per bearing type and planet (:mod:`components.life`): each bin's ISO 281 and ISO/TS 16281-style L10, its
damage share and the combined life by Palmgren–Miner over the revolutions (:func:`components.life.miner_life`),
ISO 281's equivalent load of the spectrum; the meshes' drive-flank forces per bin with their mesh cycles.
A static bin's lives leave out the dynamic load (the mesh's dynamic factor, impacts): said in every output with the
share of each bearing's damage those bins do, and a ``--dynamic`` bin's lives are its dynamic run's, with the dynamic
increment of its equivalent load. No increment is carried from a dynamic bin to a static one: it depends on the bin's
own speed (the mesh frequency against the train's natural frequencies) and load (a lightly loaded bearing's
fluctuating load is a large part of its equivalent load), so a borrowed one would be a guess; the static bins' share
of the damage bounds what they leave out.
"""
from __future__ import annotations

import argparse
import csv
import io
import json
import math
import sys
import tomllib
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from components import life
from components.names import did_you_mean
from components.presets import CONDITIONS
from components.results.io import atomic_write_text
from components.static import DEFAULT_SNAPSHOTS, STATIC_LIVES_NOTE
from components.units import ParameterError, quantity, to_si

from .core import args
from .core.command import command
from .core.lock import holds_out_folder
from .core.points import Point, checked_point, machine_identity, points_from_toml
from .core.runner import RunConfig
from .core.study import Study, StudyRun
from .core.sweep import Case, build_params, user_overrides

NAME = "duty_cycle"
OUT = "results/duty_cycle"
EXAMPLES = ["{prog} --cycle examples/duty_cycles/forward.toml --out results/duty_cycle",
            "{prog} --cycle examples/duty_cycles/reverse_10pct.toml --dynamic rev_rated --workers 2",
            "{prog} --cycle examples/duty_cycles/forward.toml --dynamic auto --dynamic-share 0.9",
            '{prog} --cycle examples/duty_cycles/series.csv --speed-bin "500 rpm" --torque-bin "200 N*m"']
WRITES = ("per bin BIN/summary.json (BIN_dynamic/ for a --dynamic bin); duty_cycle.csv (per bin, bearing type and "
          "planet: time and revolution shares, both lives, damage shares), lives.csv (the combined lives per bearing "
          "type and planet, the equivalent load), mesh_spectrum.csv (drive-flank force per mesh and bin, mesh "
          "cycles), duty_cycle.md (the tables), duty_cycle.json (everything, with the machine and the binning), "
          "damage_share.png; for a time series binning.png")

STATIC_NOTE = (f"static bins: {STATIC_LIVES_NOTE}; a --dynamic bin's lives are its dynamic run's; no dynamic "
               f"increment is carried over from a dynamic bin to a static one (it depends on the bin's own speed and "
               f"load)")
# the carrier speed above which a bin is refused unless --rated-speed says otherwise: the source's fastest condition
RATED_DEFAULT = max(s for s, _ in CONDITIONS.values())
SHARE_TOL = 1e-9      # |Σ shares − 1| above which the shares are normalised with a warning


# ---------------------------------------------------------------------------------------------------------------
# the cycle
# ---------------------------------------------------------------------------------------------------------------
@dataclass(frozen=True)
class Bin:
    """One bin of a duty cycle: its operating point (direction fixed), its time and where it was read."""
    point: Point
    hours: float | None          # None: the cycle gives shares only
    share: float                 # of the cycle's time (normalised)
    row: str                     # "FILE row N" / "FILE [[bin]] #N" / "binned from FILE"


@dataclass
class Cycle:
    source: str
    bins: list[Bin]
    notes: list[str] = field(default_factory=list)          # warnings said once (shares normalised, standstill)
    binning: dict | None = None                              # a time series: how it was binned
    series: dict | None = None                               # a time series: t, speed, torque, bin index (figure)


def _where(path, i: int, kind: str) -> str:
    return f"{Path(path).name} {kind} {i}"


def _bin_point(fields: dict, row: str) -> Point:
    for k in ("carrier_speed", "sun_speed"):
        if k in fields and fields[k] not in (None, ""):
            speed, shaft = str(fields[k]), k.split("_")[0]
            break
    else:
        raise ParameterError.at(row, "needs a carrier_speed or a sun_speed")
    loads = [k for k in ("torque", "power") if fields.get(k) not in (None, "")]
    if len(loads) != 1:
        raise ParameterError.at(row, "needs one of torque and power")
    direction = fields.get("direction") or "forward"
    temp = fields.get("oil_temperature") or None
    try:
        return checked_point(Point(name=str(fields["name"]), speed=speed, shaft=shaft, load=str(fields[loads[0]]),
                              direction=direction, oil_temperature=temp), row)
    except ParameterError as exc:
        raise ParameterError.at(row, exc.problem or str(exc)) from None


def _time_of(fields: dict, row: str) -> tuple[float | None, float | None]:
    """(hours, share) of a bin row; negative or non-finite refused naming the row."""
    hours = share = None
    if fields.get("hours") not in (None, ""):
        v = fields["hours"]
        hours = to_si(quantity(f"{row} hours", v if isinstance(v, str) and not _bare(v) else f"{v} h", "time")) / 3600
    if fields.get("share") not in (None, ""):
        share = float(fields["share"])
    if (hours is None) == (share is None):
        raise ParameterError.at(row, "give one of hours and share")
    x = hours if hours is not None else share
    if not math.isfinite(x) or x < 0:
        raise ParameterError.at(row, f"time must be >= 0, got {fields.get('hours', fields.get('share'))!r}")
    return hours, share


def _bare(v) -> bool:
    try:
        float(v)
        return True
    except (TypeError, ValueError):
        return False


def _finish(path, rows: list[tuple[dict, str]]) -> Cycle:
    """Bins from rows of fields: their points and times; shares normalised (a warning naming the sum)."""
    if not rows:
        raise ParameterError.at(f"--cycle {path}", "the bin table is empty")
    points, times = [], []
    for i, (f, row) in enumerate(rows):
        f = {**f, "name": f.get("name") or f"bin{i + 1}"}
        points.append(_bin_point(f, row))
        times.append(_time_of(f, row))
    kinds = {h is None for h, _ in times}
    if len(kinds) > 1:
        raise ParameterError.at(f"--cycle {path}", "give every bin's time as hours, or every bin's as a share, not both")
    names = [p.name for p in points]
    dup = sorted({n for n in names if names.count(n) > 1})
    if dup:
        raise ParameterError.at(f"--cycle {path}", f"the bin {dup[0]!r} is named twice")
    notes = []
    if times[0][0] is not None:
        hours = [h for h, _ in times]
        total = math.fsum(hours)
        if not total > 0:
            raise ParameterError.at(f"--cycle {path}", "every bin's time is 0 h")
        shares = [h / total for h in hours]
    else:
        hours = [None] * len(times)
        raw = [s for _, s in times]
        total = math.fsum(raw)
        if not total > 0:
            raise ParameterError.at(f"--cycle {path}", "every bin's share is 0")
        if abs(total - 1.0) > SHARE_TOL:
            notes.append(f"warning: the time shares of {Path(path).name} sum to {total:.6g}, not 1: normalised "
                         f"(each divided by {total:.6g})")
        shares = [s / total for s in raw]
    return Cycle(str(path), [Bin(p, h, s, row) for p, h, s, (_, row) in zip(points, hours, shares, rows)], notes)


def _csv_rows(path) -> tuple[list[str], list[str], list[list[str]]]:
    """(names, units, rows) of a CSV file whose header names each column, a unit in brackets after it."""
    text = Path(path).read_text(encoding="utf-8")
    lines = [ln for ln in csv.reader(io.StringIO(text)) if ln and not ln[0].lstrip().startswith("#")]
    if not lines:
        raise ParameterError.at(f"--cycle {path}", "the bin table is empty")
    names, units = [], []
    for h in lines[0]:
        name, _, unit = h.strip().partition("[")
        names.append(name.strip().lower().replace(" ", "_"))
        units.append(unit.rstrip("]").strip())
    return names, units, lines[1:]


def read_cycle(path, speed_bin: str | None = None, torque_bin: str | None = None) -> Cycle:
    """The duty cycle in ``path`` (module docstring): a TOML file's ``[[bin]]`` tables, a CSV bin table, or a CSV
    time series (a ``time`` column) binned by :func:`bin_series`. One-line errors name the row."""
    p = Path(path)
    if p.suffix.lower() == ".toml":
        try:
            data = tomllib.loads(p.read_text(encoding="utf-8"))
        except (tomllib.TOMLDecodeError, UnicodeDecodeError) as exc:
            raise ParameterError.at(f"--cycle {path}", f"invalid TOML: {exc}") from None
        bins = data.get("bin", [])
        known = {"name", "carrier_speed", "sun_speed", "torque", "power", "hours", "share", "direction",
                 "oil_temperature"}
        rows = []
        for i, b in enumerate(bins):
            bad = sorted(set(b) - known)
            if bad:
                raise ParameterError.at(_where(path, i + 1, "[[bin]] #"), f"unknown key {bad[0]!r}; the keys are "
                                                                        f"{', '.join(sorted(known))}")
            rows.append((b, _where(path, i + 1, "[[bin]] #").replace("# ", "#")))
        return _finish(path, rows)
    names, units, body = _csv_rows(path)
    if "time" in names:
        return _read_series(path, names, units, body, speed_bin, torque_bin)
    rows = []
    for i, line in enumerate(body):
        row = _where(path, i + 2, "row")          # row 1 is the header
        if len(line) != len(names):
            raise ParameterError.at(row, f"{len(line)} values for {len(names)} columns")
        f = {}
        for n, u, v in zip(names, units, line):
            v = v.strip()
            f[n] = v if (not u or v == "" or n in ("name", "direction")) else (v if n == "share" else f"{v} {u}")
        rows.append((f, row))
    return _finish(path, rows)


def _column(names, units, body, key, dimension, path) -> np.ndarray | None:
    if key not in names:
        return None
    j = names.index(key)
    unit = units[j]
    out = np.empty(len(body))
    for i, line in enumerate(body):
        row = _where(path, i + 2, "row")
        try:
            out[i] = to_si(quantity(f"{row} {key}", f"{line[j].strip()} {unit}" if unit else line[j].strip(), dimension))
        except (IndexError, ParameterError) as exc:
            raise ParameterError.at(row, f"{key}: {getattr(exc, 'problem', None) or exc}") from None
    return out


def _read_series(path, names, units, body, speed_bin, torque_bin) -> Cycle:
    t = _column(names, units, body, "time", "time", path)
    n = _column(names, units, body, "carrier_speed", "angular_velocity", path)
    if n is None:
        raise ParameterError.at(f"--cycle {path}", "a time series needs a carrier_speed column (e.g. "
                                                   "'carrier_speed [rpm]'; negative: reverse)")
    T = _column(names, units, body, "torque", "torque", path)
    P = _column(names, units, body, "power", "power", path)
    if (T is None) == (P is None):
        raise ParameterError.at(f"--cycle {path}", "a time series needs one of a torque and a power column")
    if T is None:
        with np.errstate(divide="ignore", invalid="ignore"):
            T = np.where(n != 0, P / np.abs(n), 0.0)       # the carrier's torque: P = T |ω_c|
    oil = _column(names, units, body, "oil_temperature", "temperature", path)
    bad = np.flatnonzero(np.diff(t) <= 0)
    if bad.size:
        raise ParameterError.at(_where(path, int(bad[0]) + 3, "row"), "time must increase from row to row")
    return bin_series(t, n, T, oil, speed_bin, torque_bin, source=str(path))


def _width(text: str | None, data: np.ndarray, dimension: str, what: str) -> float:
    if text is not None:
        w = to_si(quantity(what, text, dimension))
        if not w > 0:
            raise ParameterError.at(what, f"must be > 0, got {text!r}")
        return w
    top = float(np.max(np.abs(data))) if data.size else 0.0
    return top / 8.0 if top > 0 else 1.0


def bin_series(t, speed, torque, oil=None, speed_bin: str | None = None, torque_bin: str | None = None,
               source: str = "series") -> Cycle:
    """Bin a time series of the carrier's speed ``speed`` [rad/s, signed: < 0 reverse] and torque ``torque`` [N m]
    at instants ``t`` [s] (and the oil temperature ``oil`` [K], optional).

    Sample and hold: sample k holds over [t_k, t_{k+1}) (the last sample closes the series and holds no time).
    Bins are classes of the speed's magnitude, [j Δn, (j+1) Δn), and of the torque, [m ΔT, (m+1) ΔT), per
    direction (``speed_bin`` Δn and ``torque_bin`` ΔT with their units; default: an eighth of the largest
    magnitude, 8 classes each way). A bin's time is the sum of its samples' holds, t_b = Σ Δt_k; its revolutions
    N_b = Σ |n_k| Δt_k, and its speed is N_b / t_b (so that revolutions = speed × time holds exactly); its
    torque is the revolution-weighted mean Σ |n_k| Δt_k T_k / N_b (its bearing loads follow the torque about
    linearly within a narrow class), its oil temperature the time-weighted mean. Samples at standstill (n = 0)
    turn no revolution and do no damage: their time is left out and said."""
    t, n, T = (np.asarray(x, float) for x in (t, speed, torque))
    if t.ndim != 1 or t.size < 2 or n.shape != t.shape or T.shape != t.shape:
        raise ParameterError.at(f"--cycle {source}", "a time series needs at least two samples of time, speed and "
                                                     "torque")
    dt = np.diff(t)
    if np.any(dt <= 0):
        raise ParameterError.at(f"--cycle {source}", "time must increase from sample to sample")
    n, T = n[:-1], T[:-1]
    oil_k = None if oil is None else np.asarray(oil, float)[:-1]
    wn = _width(speed_bin, n, "angular_velocity", "--speed-bin")
    wt = _width(torque_bin, T, "torque", "--torque-bin")
    moving = n != 0.0
    jn = np.floor(np.abs(n) / wn).astype(int)
    jt = np.floor(T / wt).astype(int)
    sense = np.where(n >= 0, 0, 1)                    # 0 forward, 1 reverse
    keys = sorted({(int(s), int(a), int(b)) for s, a, b, m in zip(sense, jn, jt, moving) if m})
    index = np.full(n.size, -1)
    rows, hours = [], []
    rpm = 60.0 / (2.0 * math.pi)
    for b, (s, a, c) in enumerate(keys):
        sel = moving & (sense == s) & (jn == a) & (jt == c)
        index[sel] = b
        time_b = math.fsum(dt[sel])
        revs = math.fsum(np.abs(n[sel]) * dt[sel])                    # rad
        speed_b = revs / time_b
        torque_b = math.fsum(np.abs(n[sel]) * dt[sel] * T[sel]) / revs
        name = (f"{'fwd' if s == 0 else 'rev'}_{a * wn * rpm:.0f}-{(a + 1) * wn * rpm:.0f}rpm_"
                f"{c * wt:.0f}-{(c + 1) * wt:.0f}Nm").replace("--", "-m")
        f = {"name": name, "carrier_speed": f"{speed_b * rpm!r} rpm", "torque": f"{torque_b!r} N*m",
             "direction": "forward" if s == 0 else "reverse"}
        if oil_k is not None:
            # the bin's time-mean oil temperature, to 6 digits (0.001 K: far below what a log measures)
            f["oil_temperature"] = f"{math.fsum(oil_k[sel] * dt[sel]) / time_b - 273.15:.6g} degC"
        hours.append(time_b / 3600.0)
        rows.append((f, f"binned from {Path(source).name}: bin {name}"))
    if not rows:
        raise ParameterError.at(f"--cycle {source}", "the series never turns: no bin has revolutions")
    points = [_bin_point(f, row) for f, row in rows]
    total = math.fsum(hours)
    still = math.fsum(dt[~moving])
    notes = [f"standstill: {still / 3600:.4g} h of the series at zero speed turn no revolution and are left out"] \
        if still > 0 else []
    binning = {"rule": "sample and hold: sample k holds over [t_k, t_k+1); classes of |speed| and torque per "
                       "direction; a bin's speed = its revolutions / its time, its torque the revolution-weighted "
                       "mean, its oil temperature the time-weighted mean; standstill left out",
               "speed_bin_rpm": wn * rpm, "torque_bin_N_m": wt, "samples": int(t.size), "standstill_h": still / 3600,
               "series_h": float((t[-1] - t[0]) / 3600)}
    return Cycle(source, [Bin(p, h, h / total, row) for p, h, (_, row) in zip(points, hours, rows)], notes,
                 binning, {"t": t.tolist(), "speed_rpm": (np.asarray(speed) * rpm).tolist(),
                           "torque_N_m": np.asarray(torque, float).tolist(), "bin": index.tolist()})


# ---------------------------------------------------------------------------------------------------------------
# the lives over the spectrum
# ---------------------------------------------------------------------------------------------------------------
LIVES = (("iso281", "ISO 281"), ("iso16281", "ISO/TS 16281-style"))
KINDS = ("inner", "outer")


def relative_speed(bearing: dict) -> float | None:
    """The planet's speed relative to its pin [rad/s] a summary's lives were counted at: the ratio of its ISO 281
    life in revolutions to that in hours (:func:`components.life.hours`)."""
    m, h = bearing.get("life_iso281_Mrev"), bearing.get("life_iso281_h")
    if not m or not h:
        return None
    return m * 1e6 * 2.0 * math.pi / (h * 3600.0)


def spectrum_lives(summaries: list[dict], shares: list[float], hours: list[float | None]) -> dict:
    """Per bearing type and planet the lives over the spectrum from each bin's summary (in cycle order) and its time
    share τ_i (``hours``: the bins' hours, or None): revolutions per bin N_i ∝ τ_i ω_rel,i (the planet relative to
    its pin, the lives' own revolutions), u_i = N_i/ΣN; each life L = 1/Σ(u_i/L_i) in 10^6 revolutions
    (:func:`components.life.miner_life`), in hours at the cycle's mean relative speed ΣN/Σt — equal to
    1/Σ(τ_i/L_h,i) with each bin's life in hours at its own speed; the damage shares; ISO 281's equivalent load of
    the spectrum (pair 1's, :func:`components.life.spectrum_equivalent_load`)."""
    out = {}
    for kind in KINDS:
        w = [relative_speed(s[kind]) for s in summaries]
        if any(x is None for x in w):
            raise ValueError(f"{kind} planet bearings: a bin has no life (no load): {w!r}")
        u = life.revolution_shares([ti * wi for ti, wi in zip(shares, w)])
        rev_per_h = math.fsum(ti * wi for ti, wi in zip(shares, w)) * 3600.0 / (2.0 * math.pi)  # per hour of cycle
        n_planets = len(summaries[0][kind]["life_iso281_per_planet_h"])
        d: dict = {"revolution_shares": u.tolist(), "relative_speed_rad_s": w,
                   "mean_relative_speed_rad_s": rev_per_h * 2.0 * math.pi / 3600.0, "planets": {}}
        for j in range(n_planets):
            planet = {}
            for key, _ in LIVES:
                lh = [s[kind].get(f"life_{key}_per_planet_h", [None] * n_planets)[j] for s in summaries]
                if any(x is None for x in lh):
                    continue
                lrev = [h * 3600.0 * wi / (2.0 * math.pi) / 1e6 for h, wi in zip(lh, w)]    # 10^6 rev
                L = life.miner_life(lrev, u)
                planet[key] = {"per_bin_h": lh, "per_bin_Mrev": lrev, "life_Mrev": L,
                               "life_h": L * 1e6 / rev_per_h, "damage_shares": life.damage_shares(lrev, u)}
            d["planets"][f"{'a' if kind == 'inner' else 'b'}{j + 1}"] = planet
        P = [s[kind]["equivalent_load_N"] for s in summaries]
        d["equivalent_load_per_bin_N"] = P
        d["equivalent_load_N"] = life.spectrum_equivalent_load(P, u)
        d["dynamic_load_rating_N"] = summaries[0][kind]["dynamic_load_rating_N"]
        out[kind] = d
    return out


def mesh_spectrum(summaries: list[dict], names: list[str], hours: list[float | None], shares: list[float]) -> list:
    """The meshes' drive-flank force per bin (time mean and max, pair 1's mesh and the mean over the pairs) with the
    bin's mesh cycles f_m t (per hour of the cycle when it gives shares only)."""
    rows = []
    for s, name, h, tau in zip(summaries, names, hours, shares):
        t = (h if h is not None else tau) * 3600.0
        for mesh, m in (s.get("meshes") or {}).items():
            per = m.get("drive_force_mean_per_pair_N") or []
            rows.append({"bin": name, "direction": s["direction"], "mesh": mesh, "drive_flank": m.get("drive_flank"),
                         "drive_force_mean_N": m.get("drive_force_mean_N"),
                         "drive_force_mean_all_N": float(np.mean(per)) if per else None,
                         "drive_force_max_N": m.get("drive_force_max_N"),
                         "mesh_cycles": s["f_m_hz"] * t, "cycles_per": "duty cycle" if h is not None else "hour of the duty cycle"})
    return rows


# ---------------------------------------------------------------------------------------------------------------
# the bins that carry the damage
# ---------------------------------------------------------------------------------------------------------------
DEFAULT_DYNAMIC_SHARE = 0.9
SHARE_SLACK = 1e-12       # round-off allowed in a bearing's carried share (shares that sum to one sum to 1 ± 1e-16 n)


def damage_table(lives: dict) -> dict[str, list[float]]:
    """{bearing: damage shares per bin} from :func:`spectrum_lives`: every planet bearing of each type, by each of
    its lives (ISO 281 and ISO/TS 16281-style) — e.g. ``"inner a1 ISO 281"``; a bin without a life does none."""
    table = {}
    for kind in KINDS:
        for planet, p in lives[kind]["planets"].items():
            for key, words in LIVES:
                if key in p:
                    table[f"{kind} {planet} {words}"] = [x or 0.0 for x in p[key]["damage_shares"]]
    return table


def dominant_bins(table: dict[str, list[float]], share: float) -> list[int]:
    """The fewest bins that together carry at least ``share`` of every bearing's damage (``table``: {bearing: damage
    shares per bin, each row summing to one}); among equally few, those carrying the most damage summed over the
    bearings. Indices in cycle order.

    A covering problem solved exactly as a 0–1 integer programme (scipy.optimize.milp, HiGHS): minimise
    Σ x_i − ε Σ_b Σ_i d_bi x_i subject to Σ_i d_bi x_i ≥ share for every bearing b, x_i ∈ {0, 1}, with
    ε = 1/(2B) for B bearings so that the tie-break (≤ B ε = 1/2) never trades a bin. For one bearing this is the
    bins in falling order of damage until the share is reached; for several, the union of those per-bearing sets
    can hold more bins than needed (a bin that matters to two bearings serves both)."""
    from scipy.optimize import Bounds, LinearConstraint, milp    # deferred: only when bins are chosen

    if not 0.0 < share <= 1.0:
        raise ValueError(f"share must be in (0, 1], got {share!r}")
    d = np.array([table[k] for k in sorted(table)], float)
    if d.ndim != 2 or d.size == 0 or not np.all(np.isfinite(d)) or np.any(d < 0):
        raise ValueError("damage shares must be finite and >= 0, a row per bearing")
    n_b, n = d.shape
    cost = np.ones(n) - 0.5 / n_b * d.sum(axis=0)
    res = milp(cost, integrality=np.ones(n), bounds=Bounds(0, 1),
               constraints=LinearConstraint(d, lb=share - SHARE_SLACK, ub=np.inf), options={"mip_rel_gap": 0.0})
    if res.x is None:
        raise ValueError(f"no set of bins carries {share:g} of every bearing's damage ({res.message})")
    chosen = [i for i in range(n) if res.x[i] > 0.5]
    assert np.all(d[:, chosen].sum(axis=1) >= share - SHARE_SLACK), "milp returned an infeasible set"
    return chosen


def _share(text: str) -> float:
    try:
        x = float(text.strip().rstrip("%")) / (100.0 if text.strip().endswith("%") else 1.0)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a share in (0, 1] or a percentage, got {text!r}") from None
    if not 0.0 < x <= 1.0:
        raise argparse.ArgumentTypeError(f"must be in (0, 1] (or 0-100 %), got {text!r}")
    return x


# ---------------------------------------------------------------------------------------------------------------
# the study
# ---------------------------------------------------------------------------------------------------------------
def build_parser():
    p = args.parser(NAME, __doc__, examples=EXAMPLES, writes=WRITES, out=OUT)
    p.add_argument("--cycle", required=True, type=args.existing_file, metavar="FILE",
                   help="the duty cycle: a bin table (TOML [[bin]] tables or CSV) or a CSV time series (a 'time' "
                        "column), README: Duty cycles")
    p.add_argument("--dynamic", default="", metavar="BIN[,BIN...]|all|auto",
                   help="bins also run dynamically (time integration): their lives include the dynamic load; "
                        "'all' for every bin; 'auto': every bin statically first, then dynamically the fewest bins "
                        "that carry --dynamic-share of every bearing's damage (named before they run) (default: none, "
                        "every bin quasi-static)")
    p.add_argument("--dynamic-share", type=_share, default=None, metavar="SHARE",
                   help=f"with --dynamic auto: the share of each bearing's damage (by its static lives) the dynamic "
                        f"bins carry, e.g. 0.9 or 90%% (default {DEFAULT_DYNAMIC_SHARE:g})")
    p.add_argument("--snapshots", type=args.count(1), default=DEFAULT_SNAPSHOTS,
                   help=f"static solutions per bin over a carrier revolution and the mesh cycle (default "
                        f"{DEFAULT_SNAPSHOTS})")
    p.add_argument("--speed-bin", type=args.quantity_of("angular_velocity", positive_only=True), default=None,
                   metavar="SPEED", help="a time series' speed class width, e.g. \"250 rpm\" (default: 1/8 of the "
                                         "largest speed)")
    p.add_argument("--torque-bin", type=args.quantity_of("torque", positive_only=True), default=None,
                   metavar="TORQUE", help="a time series' torque class width, e.g. \"100 N*m\" (default: 1/8 of the "
                                          "largest torque)")
    p.add_argument("--rated-speed", type=args.quantity_of("angular_velocity", positive_only=True),
                   default=f"{RATED_DEFAULT:~P}", metavar="SPEED",
                   help=f"the machine's rated carrier speed; a faster bin is refused (default {RATED_DEFAULT:~P}, the "
                        f"source's fastest condition)")
    p.add_argument("--settle", type=args.nonnegative("s"), default=0.03,
                   help="dynamic bins: seconds discarded after the start (default 0.03)")
    p.add_argument("--window", type=args.positive("s"), default=None,
                   help="dynamic bins: seconds analysed (default: the paper study's, whole cage revolutions)")
    args.add_shared(p, "params", "set", "out", "overwrite", "force", "no-progress", "workers", "scheduler", out=OUT)
    return p


def parse_args(argv):
    return build_parser().parse_args(argv)


class DutyCycle(Study):
    """Every bin of the cycle solved (static; ``--dynamic`` bins also dynamically), then the lives over the
    spectrum."""

    record = True

    def __init__(self, a):
        super().__init__(a)
        sets = args.parse_sets(a.set)
        self.overrides = user_overrides(sets, a.params, {"operating": "the cycle's bins (--cycle)"})
        if a.params and points_from_toml(a.params):
            raise ParameterError.at(f"--params {a.params}", "its [[operating_point]] tables are not used here: the "
                                                            "cycle's bins (--cycle) are the operating points")
        self.machine = machine_identity(a.params, self.overrides)
        self.cycle = read_cycle(a.cycle, a.speed_bin, a.torque_bin)
        for n in self.cycle.notes:             # said before anything runs (and kept in duty_cycle.json)
            print(n, flush=True)
        names = [b.point.name for b in self.cycle.bins]
        asked = [x.strip() for x in a.dynamic.split(",") if x.strip()]
        self.auto = asked == ["auto"]
        if a.dynamic_share is not None and not self.auto:
            raise ParameterError.at("--dynamic-share", "is the share the bins of --dynamic auto carry; give it with "
                                                       "--dynamic auto")
        self.share = a.dynamic_share if a.dynamic_share is not None else DEFAULT_DYNAMIC_SHARE
        self.selection: dict | None = None
        if self.auto:
            asked = []
        if asked == ["all"]:
            asked = names
        unknown = [x for x in asked if x not in names]
        if unknown:
            raise ParameterError.at("--dynamic", f"no bin {unknown[0]!r} in {Path(a.cycle).name}"
                                                 f"{did_you_mean(unknown[0], names)}; its bins: {', '.join(names)}")
        self.dynamic = set(asked)

    def config(self) -> RunConfig:
        return RunConfig(settle=self.a.settle, window=self.a.window, progress=not self.a.no_progress, mode="static",
                         snapshots=self.a.snapshots)

    def _case(self, b: Bin, dynamic: bool = False) -> Case:
        label = b.point.name + ("_dynamic" if dynamic else "")
        return Case.at(b.point, b.point.direction, str(self.out / label), self.overrides, self.a.params,
                       tag="dynamic" if dynamic else "", mode="dynamic" if dynamic else None)

    def cases(self) -> list[Case]:
        rated = to_si(quantity("--rated-speed", self.a.rated_speed, "angular_velocity"))
        out = []
        for b in self.cycle.bins:
            c = self._case(b)
            try:
                params = build_params(c)
            except ParameterError as exc:
                raise ParameterError.at(b.row, exc.problem or str(exc)) from None
            w = abs(params.si().operating.carrier_speed)
            if w > rated * (1 + 1e-12):
                raise ParameterError.at(b.row, f"carrier speed {w * 30 / math.pi:.6g} rpm is above the machine's rated "
                                               f"{rated * 30 / math.pi:.6g} rpm (--rated-speed)")
            out.append(c)
            if b.point.name in self.dynamic:
                out.append(self._case(b, dynamic=True))
        return out

    def machine_identity(self) -> dict:
        return self.machine

    def second_phase(self, run: StudyRun) -> list[Case]:
        """``--dynamic auto``: the bins that carry ``--dynamic-share`` of every bearing's damage by the static lives
        (:func:`dominant_bins`), named with the shares they carry before their dynamic runs start."""
        if not self.auto:
            return []
        res = run.results
        bins = self.cycle.bins
        static = [res.get(b.point.name) for b in bins]
        missing = [b.point.name for b, st in zip(bins, static) if st is None or not st.has_bearings]
        if missing:
            print(f"--dynamic auto: no bins chosen, the static runs of {', '.join(missing)} have no results")
            return []
        table = damage_table(spectrum_lives(static, [b.share for b in bins], [b.hours for b in bins]))
        chosen = dominant_bins(table, self.share)
        carried = {k: math.fsum(v[i] for i in chosen) for k, v in table.items()}
        least = min(carried, key=carried.get)
        per_kind = {kind: min(v for k, v in carried.items() if k.startswith(kind + " ")) for kind in KINDS}
        names = [bins[i].point.name for i in chosen]
        self.dynamic = set(names)
        self.selection = {"share": self.share, "bins": names, "carried": carried, "least_covered": least,
                          "rule": "the fewest bins that carry at least the share of every planet bearing's damage "
                                  "(each type and planet, ISO 281 and ISO/TS 16281-style, by the static lives); "
                                  "among equally few, those carrying the most damage"}
        print(f"dynamic bins (--dynamic auto, share {self.share:g} of every bearing's damage by the static lives): "
              f"{', '.join(names)} ({len(names)} of {len(bins)}); they carry at least "
              + ", ".join(f"{100 * per_kind[k]:.1f} % ({k})" for k in KINDS)
              + f" of each bearing's damage, least {100 * carried[least]:.1f} % ({least})", flush=True)
        return [self._case(bins[i], dynamic=True) for i in chosen]

    def study_record(self) -> dict:
        return {"cycle": self.cycle.source, "dynamic_selection": self.selection}

    def report(self, run: StudyRun) -> dict:
        res = run.results
        bins = self.cycle.bins
        chosen, increments, sources = [], {}, []
        for b in bins:
            st = res.get(b.point.name)
            dy = res.get(f"{b.point.name}_dynamic") if b.point.name in self.dynamic else None
            if dy is not None and dy.has_bearings and not dy.failed:
                chosen.append(dy)
                sources.append("dynamic")
                if st is not None and st.has_bearings:
                    increments[b.point.name] = {k: dy[k]["equivalent_load_N"] / st[k]["equivalent_load_N"] - 1.0
                                                for k in KINDS}
            else:
                chosen.append(st)
                sources.append("static")
        missing = [b.point.name for b, s in zip(bins, chosen) if s is None or not s.has_bearings]
        if missing:
            print(f"no lives over the cycle: the bins {', '.join(missing)} have no results")
            return {"lives": None}
        shares = [b.share for b in bins]
        hours = [b.hours for b in bins]
        lives = spectrum_lives(chosen, shares, hours)
        names = [b.point.name for b in bins]
        record = self._record(chosen, lives, names, sources, increments)
        print("\n" + headline(record))
        run.step("tables", write_tables, record, self.out)
        run.step("figures", figures, record, self.cycle, self.out)
        return {"lives": lives, "record": record}

    def _record(self, chosen, lives, names, sources, increments) -> dict:
        bins = []
        for i, (b, s) in enumerate(zip(self.cycle.bins, chosen)):
            bins.append({"name": b.point.name, "row": b.row, "direction": s["direction"], "carrier_rpm": abs(s["carrier_rpm"]),
                         "power_W": s["power_W"], "output_torque_N_m": s["power_W"] / abs(s["carrier_rpm"] * math.pi / 30),
                         "oil_temperature": b.point.oil_temperature, "hours": b.hours, "time_share": b.share,
                         "revolution_share": {k: lives[k]["revolution_shares"][i] for k in KINDS},
                         "life_source": sources[i], "dynamic_load_included": sources[i] == "dynamic",
                         "dynamic_increment_equivalent_load": increments.get(b.point.name)})
        static_idx = [i for i, src in enumerate(sources) if src == "static"]
        ignoring = {k: math.fsum(v[i] for i in static_idx) for k, v in damage_table(lives).items()}
        total_h = math.fsum(b.hours for b in self.cycle.bins) if self.cycle.bins[0].hours is not None else None
        return {"machine": self.machine, "cycle": {"file": Path(self.cycle.source).name, "hours": total_h,
                                                   "binning": self.cycle.binning, "notes": self.cycle.notes},
                "static_lives_note": STATIC_NOTE if "static" in sources else None,
                "lives_ignore_dynamic_load": [n for n, src in zip(names, sources) if src == "static"],
                "damage_share_ignoring_dynamic_load": ignoring,
                "dynamic_selection": self.selection,
                "method": ("Palmgren-Miner over the revolutions of the planet relative to its pin: L = 1/sum(u_i/L_i), "
                           "u_i = N_i/sum N (components.life.miner_life); in hours at the cycle's mean relative speed, "
                           "equal to 1/sum(tau_i/L_h,i) with time shares tau_i; equivalent load (sum u_i P_i^(10/3))^(3/10)"),
                "bins": bins, "lives": lives,
                "mesh_spectrum": mesh_spectrum(chosen, names, [b.hours for b in self.cycle.bins],
                                               [b.share for b in self.cycle.bins])}


def _g(x, nd=4):
    return "–" if x is None else f"{x:.{nd}g}"


def headline(rec: dict) -> str:
    """The answer first: per bearing type the combined lives of its weakest planet, the equivalent load, and the bin
    that does the most damage."""
    m = rec["machine"]
    lines = [f"duty cycle {rec['cycle']['file']} on {m['label']}:",
             "| bearing | combined L10 ISO 281 [h] | combined L10 ISO/TS 16281-style [h] | equivalent load [kN] | "
             "most damaging bin (ISO 281 share) |", "|---|---|---|---|---|"]
    for kind in KINDS:
        d = rec["lives"][kind]
        weakest = {key: min((p[key]["life_h"], name) for name, p in d["planets"].items() if key in p)
                   for key, _ in LIVES if any(key in p for p in d["planets"].values())}
        p1 = next(iter(d["planets"].values()))
        shares = p1["iso281"]["damage_shares"]
        top = int(np.argmax(shares))
        cells = [f"{_g(weakest[k][0])} ({weakest[k][1]})" if k in weakest else "–" for k, _ in LIVES]
        lines.append(f"| {kind} | {cells[0]} | {cells[1]} | {d['equivalent_load_N'] / 1e3:.4g} | "
                     f"{rec['bins'][top]['name']} ({100 * shares[top]:.1f} %) |")
    for b in rec["bins"]:
        inc = b["dynamic_increment_equivalent_load"]
        if inc:
            lines.append(f"dynamic bin {b['name']}: its dynamic run's equivalent load is "
                         f"{100 * inc['inner']:+.2f} % (inner) and {100 * inc['outer']:+.2f} % (outer) of the static "
                         f"solution's; its lives are the dynamic run's")
    sel = rec.get("dynamic_selection")
    if sel:
        lines.append(f"dynamic bins chosen by --dynamic auto: {', '.join(sel['bins'])}, at least "
                     f"{100 * sel['carried'][sel['least_covered']]:.1f} % of every bearing's damage by the static "
                     f"lives (asked {100 * sel['share']:.4g} %)")
    if rec["static_lives_note"]:
        ign = rec.get("damage_share_ignoring_dynamic_load") or {}
        worst = max(ign, key=ign.get) if ign else None
        share = f"; they do up to {100 * ign[worst]:.1f} % of a bearing's damage ({worst})" if worst else ""
        lines.append(f"note: {rec['static_lives_note']} ({len(rec['lives_ignore_dynamic_load'])} of "
                     f"{len(rec['bins'])} bins: {', '.join(rec['lives_ignore_dynamic_load'])}{share})")
    return "\n".join(lines)


def table_rows(rec: dict) -> list[dict]:
    """duty_cycle.csv: a row per bin, bearing type and planet."""
    rows = []
    for kind in KINDS:
        d = rec["lives"][kind]
        for planet, p in d["planets"].items():
            for i, b in enumerate(rec["bins"]):
                row = {"machine": rec["machine"]["label"], "bin": b["name"], "direction": b["direction"],
                       "carrier_rpm": b["carrier_rpm"], "output_torque_N_m": b["output_torque_N_m"],
                       "power_W": b["power_W"], "oil_temperature": b["oil_temperature"] or "", "hours": b["hours"],
                       "time_share": b["time_share"], "revolution_share": d["revolution_shares"][i],
                       "bearing": kind, "planet": planet, "equivalent_load_N": d["equivalent_load_per_bin_N"][i]
                       if planet.endswith("1") else None}
                for key, _ in LIVES:
                    if key in p:
                        row[f"life_{key}_h"] = p[key]["per_bin_h"][i]
                        row[f"damage_share_{key}"] = p[key]["damage_shares"][i]
                row.update(life_source=b["life_source"], dynamic_load_included=b["dynamic_load_included"])
                rows.append(row)
    return rows


def _csv(rows: list[dict]) -> str:
    """The rows as CSV, numbers to 12 significant digits (1000 r/min reads 1000, not the 1000.0000000000001 its
    round trip through rad/s gives)."""
    buf = io.StringIO()
    keys = list(dict.fromkeys(k for r in rows for k in r))
    w = csv.DictWriter(buf, fieldnames=keys)
    w.writeheader()
    w.writerows({k: (f"{v:.12g}" if isinstance(v, float) else v) for k, v in r.items()} for r in rows)
    return buf.getvalue()


def write_tables(rec: dict, out: Path) -> list[Path]:
    rows = table_rows(rec)
    lives = []
    for kind in KINDS:
        d = rec["lives"][kind]
        for planet, p in d["planets"].items():
            r = {"machine": rec["machine"]["label"], "bearing": kind, "planet": planet}
            for key, _ in LIVES:
                if key in p:
                    r[f"life_{key}_h"], r[f"life_{key}_Mrev"] = p[key]["life_h"], p[key]["life_Mrev"]
            r["equivalent_load_N"] = d["equivalent_load_N"] if planet.endswith("1") else None
            r["static_bins_ignore_dynamic_load"] = " ".join(rec["lives_ignore_dynamic_load"])
            lives.append(r)
    mesh = [{"machine": rec["machine"]["label"], **r} for r in rec["mesh_spectrum"]]
    atomic_write_text(out / "duty_cycle.csv", _csv(rows))
    atomic_write_text(out / "lives.csv", _csv(lives))
    atomic_write_text(out / "mesh_spectrum.csv", _csv(mesh))
    atomic_write_text(out / "duty_cycle.json", json.dumps(rec, indent=1, default=str))
    md = [f"# Duty cycle {rec['cycle']['file']}", "", f"Machine: {rec['machine']['label']}", "",
          headline(rec), "", "## Bins (pair 1)", "",
          "| bin | direction | carrier [rpm] | torque [N m] | time share | lives from | inner: L10 ISO 281 [h] / "
          "damage | outer: L10 ISO 281 [h] / damage | inner: L10 16281 [h] / damage | outer: L10 16281 [h] / damage |",
          "|---|---|---|---|---|---|---|---|---|---|"]
    for i, b in enumerate(rec["bins"]):
        cells = []
        for key, _ in LIVES:
            for kind in KINDS:
                p = next(iter(rec["lives"][kind]["planets"].values())).get(key)
                cells.append("–" if p is None else f"{_g(p['per_bin_h'][i])} / {100 * p['damage_shares'][i]:.1f} %")
        src = b["life_source"] + ("" if b["dynamic_load_included"] else " (no dynamic load)")
        md.append(f"| {b['name']} | {b['direction']} | {b['carrier_rpm']:.5g} | {b['output_torque_N_m']:.5g} | "
                  f"{b['time_share']:.4g} | {src} | " + " | ".join([cells[0], cells[1], cells[2], cells[3]]) + " |")
    md += ["", "## Meshes: drive-flank force spectrum (pair 1)", "",
           "| bin | mesh | drive-flank force mean [N] | max [N] | mesh cycles |", "|---|---|---|---|---|"]
    md += [f"| {r['bin']} | {r['mesh']} | {_g(r['drive_force_mean_N'])} | {_g(r['drive_force_max_N'])} | "
           f"{r['mesh_cycles']:.4g} per {r['cycles_per']} |" for r in rec["mesh_spectrum"]]
    md += ["", f"Method: {rec['method']}."]
    if rec["static_lives_note"]:
        md += ["", f"Note: {rec['static_lives_note']}."]
    atomic_write_text(out / "duty_cycle.md", "\n".join(md) + "\n")
    return [out / n for n in ("duty_cycle.csv", "lives.csv", "mesh_spectrum.csv", "duty_cycle.md", "duty_cycle.json")]


def figures(rec: dict, cycle: Cycle, out: Path) -> list[Path]:
    from viz import plots as vp  # deferred: matplotlib (≈ 0.5 s) only when the figures are drawn
    title = f"{rec['cycle']['file']} on {rec['machine']['name']} [{rec['machine']['fingerprint']}]"
    shares = {f"{kind} planet bearings, {words}": next(iter(rec["lives"][kind]["planets"].values()))[key]["damage_shares"]
              for key, words in LIVES for kind in KINDS
              if key in next(iter(rec["lives"][kind]["planets"].values()))}
    paths = [vp.damage_shares(
        [b["name"] + (" (static)" if not b["dynamic_load_included"] else " (dynamic)") for b in rec["bins"]],
        [b["time_share"] for b in rec["bins"]], shares, out / "damage_share.png",
        title=f"Damage share per bin (pair 1), Palmgren–Miner: {title}")]
    if cycle.series is not None:
        paths.append(vp.binned_series(cycle.series, [b["name"] for b in rec["bins"]], out / "binning.png",
                                      title=f"Time series binned ({cycle.binning['speed_bin_rpm']:.4g} rpm × "
                                            f"{cycle.binning['torque_bin_N_m']:.4g} N m classes): {title}"))
    return paths


@holds_out_folder
def run(a) -> dict:
    return DutyCycle(a).run()


@command
def main(argv=None) -> int:
    return Study.exit_code(run(parse_args(sys.argv[1:] if argv is None else argv)))


if __name__ == "__main__":
    raise SystemExit(main())
