"""What sets the adaptive step at an operating point: which DOFs make the controller's local error estimate.

    python -m scenarios.bench_steps [--conditions 1] [--settle 0.03] [--window 0.01] [--set KEY=VALUE ...]

One dynamic run of each condition (forward, production settings, compiled engine, into a temporary folder). Every
accepted step's scaled local error estimate e_i = (β − 1/6) h² (a₁,ᵢ − a₀,ᵢ) / atol_i (the one the controller
accepts when its RMS ≤ 1, docs/numerics.md §1) is taken from the compiled runner's log, its squares summed per DOF
over the run. Printed per condition: accepted steps per simulated second, the median step (p10, p90), rejections,
Newton iterations per step, and the shares of Σe² of the bodies' coordinates — the rollers' x, y turned into radial
and tangential about their planet's centre, inner (a…) and outer (b…) bearings apart — with the largest single DOFs.
``--onsets`` adds the split by contact state (:func:`roller_categories`): the shares of Σe² in steps where the DOF's
roller had a raceway contact close or open, a pocket contact do so, a raceway contact loaded throughout (and by the
time since that roller's last raceway onset or release), none; the same for the dominant DOF of every rejected step's
first attempt (re-taken from its start state at its size on a copy of the runner, a fresh LU: how many fail Newton);
the raceway onsets and releases per contact. docs/numerics.md §5 ("What sets the step") quotes it.
"""
from __future__ import annotations

import copy
import json
import sys
import tempfile
import warnings
from collections import defaultdict

import numpy as np

import mbd.compiled.runner as runner_module
from mbd import rules

from components.params import with_overrides
from components.presets import reference_dpgt

from ..core import args
from ..core.runner import RunConfig, run_case
from ..core.command import command

EXAMPLES = ["{prog} --conditions 1,3", "{prog} --conditions 1 --set operating.output_power=\"2 kW\""]
WRITES = "one JSON object on the screen per condition"


def parse_args(argv):
    p = args.parser("bench_steps", __doc__, examples=EXAMPLES, writes=WRITES, out=None)
    p.add_argument("--settle", type=args.nonnegative("s"), default=0.03, help="seconds before the window (default 0.03)")
    p.add_argument("--window", type=args.positive("s"), default=0.01, help="seconds recorded (default 0.01)")
    p.add_argument("--onsets", action="store_true",
                   help="also split the error estimate (accepted steps, and each rejected step's first attempt "
                        "re-taken) by the state of the dominant roller's contacts across the step")
    args.add_shared(p, "conditions", "set", conditions="1",
                    conditions_why="condition 1 (the heaviest torque) takes the smallest steps")
    return p.parse_args(argv)


def error_squares(h: np.ndarray, a0: np.ndarray, a1: np.ndarray, errc: float, atol: np.ndarray) -> np.ndarray:
    """(steps, n) squared scaled local error estimates of accepted steps of sizes ``h`` (steps,), whose
    accelerations go from ``a0`` to ``a1`` (steps, n) each: the terms whose mean is the controller's RMS²."""
    e = errc * (h * h)[:, None] * (a1 - a0) / atol[None, :]
    return e * e


def roller_split(e2x, e2y, exy, ux, uy):
    """Radial and tangential parts of a roller's (x, y) error vector: its squared components along
    u = (ux, uy) and across it, from the squares e2x, e2y and the product exy of its x and y errors."""
    radial = e2x * ux * ux + 2.0 * exy * ux * uy + e2y * uy * uy
    return radial, e2x + e2y - radial


class _Tally:
    """Hooks :meth:`CompiledRunner.advance` and sums the error squares of every accepted step it logs."""

    def __init__(self):
        self.sums = defaultdict(float)
        self.per_dof = None
        self.h, self.accepted, self.rejected, self.newton = [], 0, 0, 0

    def take(self, runner, state, blk):
        n, log = runner.n, blk.log
        if not len(log):
            return
        names = runner.cs.model.body_names
        h = log[:, 1]
        a1 = log[:, 3 + 2 * n:3 + 3 * n]
        a0 = np.vstack([np.asarray(state.a, float)[None, :], a1[:-1]])
        e = runner.prm[3] * (h * h)[:, None] * (a1 - a0) / runner.atol[None, :]
        e2 = e * e
        self.per_dof = e2.sum(axis=0) + (0.0 if self.per_dof is None else self.per_dof)
        idx = {nm: i for i, nm in enumerate(names)}
        q = log[:, 3:3 + n]
        for i, nm in enumerate(names):
            if ".roller" not in nm:
                for c, xyz in enumerate("xyt"):
                    self.sums[f"{nm}.{xyz}"] += e2[:, 3 * i + c].sum()
                continue
            p = idx[nm.split(".")[0]]
            dx, dy = q[:, 3 * i] - q[:, 3 * p], q[:, 3 * i + 1] - q[:, 3 * p + 1]
            L = np.hypot(dx, dy)
            radial, tangential = roller_split(e2[:, 3 * i], e2[:, 3 * i + 1], e[:, 3 * i] * e[:, 3 * i + 1],
                                              dx / L, dy / L)
            side = "inner" if nm.startswith("a") else "outer"
            self.sums[f"{side} rollers radial"] += radial.sum()
            self.sums[f"{side} rollers tangential"] += tangential.sum()
            self.sums[f"{side} rollers spin"] += e2[:, 3 * i + 2].sum()
        self.h.extend(h)
        self.accepted += len(log)
        self.rejected += blk.counters["rejected"]
        self.newton += blk.counters["newton"]
        self.names = names

    def report(self, simulated: float) -> dict:
        total = sum(self.sums.values())
        h = np.array(self.h)
        shares = sorted(((k, v / total) for k, v in self.sums.items()), key=lambda kv: -kv[1])
        return {"accepted_per_simulated_s": self.accepted / simulated,
                "h_median_us": float(np.median(h) * 1e6), "h_p10_us": float(np.percentile(h, 10) * 1e6),
                "h_p90_us": float(np.percentile(h, 90) * 1e6),
                "rejected_share": self.rejected / max(self.accepted + self.rejected, 1),
                "newton_per_step": self.newton / max(self.accepted, 1),
                "error_share": {k: round(v, 4) for k, v in shares if v >= 0.005}}


SINCE_BINS = ("< 10 us", "10-30 us", "30-100 us", "100-300 us", ">= 300 us or none")
SINCE_EDGES = np.array([10e-6, 30e-6, 100e-6, 300e-6])
CATEGORIES = ("race onset/release", "pocket onset/release", "in race contact", "out of contact", "other bodies")


def roller_categories(d0, d1, p0, p1, race_roller, pocket_roller, n_rollers) -> np.ndarray:
    """(K, n_rollers) index into :data:`CATEGORIES` of each roller's contacts across K steps: a race contact whose
    deflection changes sign between the step's ends (δ > 0 at one end, ≤ 0 at the other) makes "race onset/release";
    else a pocket contact whose penetration does ("pocket onset/release"); else a race contact loaded at both ends
    "in race contact"; else "out of contact". ``d0``, ``d1`` (K, n_race) the race deflections at the step's start
    and end, ``p0``, ``p1`` (K, n_pocket) the pocket penetrations; ``race_roller``, ``pocket_roller`` each
    contact's roller (0 … n_rollers − 1)."""
    K = d0.shape[0]

    def per_roller(flags, owner):
        out = np.zeros((K, n_rollers), bool)
        for j in range(flags.shape[1]):         # a few contacts a roller: a loop over contacts, not states
            out[:, owner[j]] |= flags[:, j]
        return out

    onset = per_roller((d0 > 0.0) != (d1 > 0.0), race_roller)
    pocket = per_roller((p0 > 0.0) != (p1 > 0.0), pocket_roller)
    loaded = per_roller((d0 > 0.0) & (d1 > 0.0), race_roller)
    return np.where(onset, 0, np.where(pocket, 1, np.where(loaded, 2, 3)))


class _Onsets:
    """The error estimate split by what the dominant roller's contacts did across the step (:func:`roller_categories`),
    for the accepted steps and for each rejected step's first attempt, re-taken from its start state at its size with
    a fixed step on a copy of the runner (a fresh LU; the production run's state is untouched)."""

    def __init__(self, runner):
        m = runner.cs.model
        self.model = m
        f2f = m.full_to_free
        names = m.body_names
        rollers = [i for i, nm in enumerate(names) if ".roller" in nm]
        index = {b: r for r, b in enumerate(rollers)}
        self.n_rollers = len(rollers)
        self.dof_roller = -np.ones(runner.n, np.int64)
        for b, r in index.items():
            for c in range(3):
                if f2f[3 * b + c] >= 0:
                    self.dof_roller[f2f[3 * b + c]] = r
        self.race = [e for e, _ in runner.cs.system._evals if type(e).__name__ == "RaceContact"]
        self.pocket = [e for e, _ in runner.cs.system._evals if type(e).__name__ == "PocketContact"]
        self.race_roller = np.concatenate([[index[d // 3] for d in e.dofs[:, 0]] for e in self.race]).astype(np.int64)
        self.pocket_roller = np.concatenate([[index[d // 3] for d in e.dofs[:, 0]] for e in self.pocket]).astype(np.int64)
        self.sums = {c: 0.0 for c in CATEGORIES}
        self.reversing = {c: 0.0 for c in CATEGORIES}     # Σe² of the steps whose Δa turned against the step before's
        self.last_da = None
        self.race_kappa = np.concatenate([np.broadcast_to(e.kappa, (e.n,)) for e in self.race])
        self.counting, self.race_events = False, np.zeros(self.race_roller.size)
        self.last_event = None                            # per roller: the end time of its last race onset/release
        self.since = {b: 0.0 for b in SINCE_BINS}         # Σe² of "in race contact" DOFs by the time since that
        self.dominant = {"accepted": {c: 0 for c in CATEGORIES}, "accepted, largest 5 % of errors": {c: 0 for c in CATEGORIES},
                         "rejected (re-taken)": {c: 0 for c in CATEGORIES}}
        self.errors, self.cats = [], []
        self.rejected_seen, self.newton_failed, self.retaken_error = 0, 0, []

    def _outputs(self, fams, key, t, q, v):
        qf, vf = self.model.full_batch(t, q, v)
        fs = self.model.frame_batch(t)
        cols = []
        for e in fams:
            ql, vl = qf[:, e.dofs], vf[:, e.dofs]
            _, out = e.kernel(t[:, None], fs, list(np.moveaxis(ql, 2, 0)), list(np.moveaxis(vl, 2, 0)), None)
            cols.append(np.broadcast_to(np.asarray(out[key], float), (t.size, e.n)))
        return np.concatenate(cols, axis=1)

    def categories(self, t0, q0, v0, t1, q1, v1):
        """(K, n) category of every DOF over K steps (rollers' DOFs by their roller, others "other bodies")."""
        d0, d1 = self._outputs(self.race, "deflection", t0, q0, v0), self._outputs(self.race, "deflection", t1, q1, v1)
        p0, p1 = (self._outputs(self.pocket, "penetration", t0, q0, v0),
                  self._outputs(self.pocket, "penetration", t1, q1, v1))
        rc = roller_categories(d0, d1, p0, p1, self.race_roller, self.pocket_roller, self.n_rollers)
        if self.counting:
            self.race_events += ((d0 > 0.0) != (d1 > 0.0)).sum(axis=0)
        return np.where(self.dof_roller[None, :] >= 0, rc[:, np.maximum(self.dof_roller, 0)], len(CATEGORIES) - 1)

    def _count(self, which, e2, cats):
        dom = cats[np.arange(e2.shape[0]), np.argmax(e2, axis=1)]
        for k in dom:
            self.dominant[which][CATEGORIES[k]] += 1
        return dom

    def take(self, runner, original, state, h_in, t_end, blk):
        n, log = runner.n, blk.log
        if not len(log):
            return
        t1, h, err = log[:, 0], log[:, 1], log[:, 2]
        q1, v1, a1 = log[:, 3:3 + n], log[:, 3 + n:3 + 2 * n], log[:, 3 + 2 * n:3 + 3 * n]
        q0 = np.vstack([np.asarray(state.q, float)[None, :], q1[:-1]])
        v0 = np.vstack([np.asarray(state.v, float)[None, :], v1[:-1]])
        a0 = np.vstack([np.asarray(state.a, float)[None, :], a1[:-1]])
        t0 = np.concatenate([[state.t], t1[:-1]])
        e2 = error_squares(h, a0, a1, runner.prm[3], runner.atol)
        self.counting = True
        cats = self.categories(t0, q0, v0, t1, q1, v1)
        self.counting = False
        rc = np.full((len(log), self.n_rollers), -1, np.int64)
        m = self.dof_roller >= 0
        rc[:, self.dof_roller[m]] = cats[:, m]
        ev = np.where(rc == 0, t1[:, None], -np.inf)
        if self.last_event is not None:
            ev[0] = np.maximum(ev[0], self.last_event)
        ev = np.maximum.accumulate(ev, axis=0)
        self.last_event = ev[-1].copy()
        since = t1[:, None] - ev[:, np.maximum(self.dof_roller, 0)]
        b = np.searchsorted(SINCE_EDGES, since)
        for k, name in enumerate(SINCE_BINS):
            self.since[name] += float(e2[(cats == 2) & (b == k)].sum())
        da = a1 - a0
        prev = np.vstack([da[:1] if self.last_da is None else self.last_da[None, :], da[:-1]])
        self.last_da = da[-1].copy()
        rev = (da * prev) < 0.0
        for k, c in enumerate(CATEGORIES):
            self.sums[c] += float(e2[cats == k].sum())
            self.reversing[c] += float(e2[(cats == k) & rev].sum())
        dom = self._count("accepted", e2, cats)
        self.errors.extend(err)
        self.cats.extend(dom)
        # each accepted step whose size is not the controller's choice after the step before: its first attempt failed
        ctrl = runner.ctrl
        h_pred = float(h_in)
        for j in range(len(log)):
            h_try = min(h_pred, t_end - t0[j])
            if abs(h[j] - h_try) > 1e-9 * h_try:
                self.rejected_seen += 1
                self._retake(runner, original, state if j == 0 else blk.state_at(j - 1), h_try)
            h_pred = float(rules.adaptive_decide(h[j], True, err[j], ctrl[1], ctrl[2], ctrl[3], ctrl[4], ctrl[5],
                                                 ctrl[6])[1])
        runner.cs.set_internal(blk.state.z)

    def _retake(self, runner, original, s0, h_try):
        sh = copy.copy(runner)
        sh.lu, sh.work, sh.out = copy.deepcopy(runner.lu), copy.deepcopy(runner.work), copy.deepcopy(runner.out)
        sh.cache = np.array([0.0, np.nan, 0.0])
        sh.ctrl = np.array([0.0, h_try, np.inf, 0, 0, 0, 0, runner.ctrl[7]])
        b = original(sh, s0, h_try, s0.t + h_try, 1)
        if b.counters["rejected"] or not len(b.log):
            self.newton_failed += 1
            if not len(b.log):
                return
        n, row = runner.n, b.log[0]
        h = row[1]
        self.retaken_error.append(row[2])
        e2 = error_squares(np.array([h]), np.asarray(s0.a, float)[None, :], row[None, 3 + 2 * n:3 + 3 * n],
                           runner.prm[3], runner.atol)
        cats = self.categories(np.array([s0.t]), np.asarray(s0.q, float)[None, :], np.asarray(s0.v, float)[None, :],
                               row[:1], row[None, 3:3 + n], row[None, 3 + n:3 + 2 * n])
        self._count("rejected (re-taken)", e2, cats)

    def report(self) -> dict:
        total = sum(self.sums.values())
        err, cats = np.array(self.errors), np.array(self.cats)
        top = cats[err >= np.percentile(err, 95)]
        self.dominant["accepted, largest 5 % of errors"] = {c: int(np.sum(top == k)) for k, c in enumerate(CATEGORIES)}
        return {"error_share_by_contact_state": {c: round(v / total, 4) for c, v in self.sums.items()},
                "in_race_contact_share_by_time_since_the_rollers_last_onset": {
                    k: round(v / total, 4) for k, v in self.since.items()},
                "of_which_acceleration_change_reversed": {c: round(self.reversing[c] / v, 4) if v else None
                                                          for c, v in self.sums.items()},
                "dominant_dof_by_contact_state": self.dominant,
                "race_onsets_and_releases_per_contact": {
                    side: {"median": float(np.median(ev)), "p90": float(np.percentile(ev, 90)), "max": float(ev.max()),
                           "contacts": int(ev.size)}
                    for side, ev in (("inner", self.race_events[self.race_kappa > 0]),
                                     ("outer", self.race_events[self.race_kappa < 0])) if ev.size},
                "rejections_found": self.rejected_seen, "retaken_newton_failed": self.newton_failed,
                "retaken_error_median": float(np.median(self.retaken_error)) if self.retaken_error else None}


def measure(condition: int, settle: float, window: float, sets: dict, onsets: bool = False) -> dict:
    tally, original = _Tally(), runner_module.CompiledRunner.advance
    split = []

    def advance(self, state, h, t_end, max_steps):
        blk = original(self, state, h, t_end, max_steps)
        tally.take(self, state, blk)
        if onsets:
            if not split:
                split.append(_Onsets(self))
            split[0].take(self, original, state, h, t_end, blk)
        return blk

    runner_module.CompiledRunner.advance = advance
    try:
        with warnings.catch_warnings(), tempfile.TemporaryDirectory() as d:
            warnings.simplefilter("ignore")
            p = with_overrides(reference_dpgt(condition, "forward"), sets)
            run_case(p, RunConfig(settle=settle, window=window, progress=False), d)
    finally:
        runner_module.CompiledRunner.advance = original
    return {"condition": condition, "set": sets, **tally.report(settle + window), **(split[0].report() if split else {})}


@command
def main(argv=None) -> int:
    a = parse_args(sys.argv[1:] if argv is None else argv)
    for c in [int(x) for x in a.conditions.split(",")]:
        print(json.dumps(measure(c, a.settle, a.window, args.parse_sets(a.set), a.onsets)), flush=True)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
