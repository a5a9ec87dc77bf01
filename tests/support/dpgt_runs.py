"""Shared DPGT runs for the load-path and statistics tests: one simulation per operating point with the
statistics observer (components.outputs.WindowStatistics) and, where asked, extra time means."""
from __future__ import annotations

import dataclasses
import math
import warnings

import numpy as np

import mbd
from components.dpgt import build_dpgt
from components.geometry import DesignWarning
from components.outputs import WindowStatistics, cage_period
from components.params import with_overrides
from components.presets import reference_dpgt, typical_errors
from components.scene import SceneOptions
from scenarios.fault_study import FAULTS

# the carrier drive the short runs use: 200 Hz brings the carrier on speed within 0.15 % by 7 ms (the
# study's softer 80 Hz drive needs ≈ 25 ms, too long for a test)
FAST_DRIVE = {"rig.carrier_drive_bandwidth": "200 Hz"}
SETTLE = 8e-3
CONTROLLER = mbd.Adaptive(h0=1e-6, h_max=1e-5, h_min=1e-9)


def cage_revolution(params) -> float:
    """One cage revolution relative to the carrier [s] (inner and outer cages turn alike here)."""
    si = params.si()
    op = si.operating
    return max(cage_period(si.bearing, op.carrier_speed, w) for w in (op.inner_planet_speed, op.outer_planet_speed))


def carrier_revolution(params) -> float:
    """One carrier revolution [s]: gravity and the ring turn once relative to the carrier in it."""
    return 2.0 * math.pi / abs(params.si().operating.carrier_speed)


def build(params, **options):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DesignWarning)
        return build_dpgt(params, SceneOptions(**options))


# numpy's SIMD math functions may round the last bit differently for arrays of other shapes; a contact's
# compression is a small difference of lengths ~1e3 times larger, so one ulp there is ~1e-13..1e-12 of the
# family's largest load (measured: 2.5e-9 N at 2.3 kN, the largest ~1e4 N)
OUTPUT_ROUND_OFF = 1e-12


def faulty_machine(direction="forward"):
    """The reference machine at condition 3 with class-6 teeth, runouts and pinhole errors (the rig's typical
    errors: the tooth-pair mesh law), a spall on b1's pin and a cracked tooth on b1."""
    p = reference_dpgt(3, direction)
    p = dataclasses.replace(p, errors=typical_errors(p, 6))
    return with_overrides(p, {**FAULTS["spall_pin"][0], **FAULTS["cracked_tooth"][0]})


def summary_numbers(d, prefix=""):
    """A summary flattened to {"kind.key": value} (list entries as "key.i")."""
    out = {}
    for k, v in d.items():
        if isinstance(v, dict):
            out.update(summary_numbers(v, f"{prefix}{k}."))
        elif isinstance(v, list):
            out.update(summary_numbers(dict(enumerate(v)), f"{prefix}{k}."))
        else:
            out[prefix + str(k)] = v
    return out


def run(condition, direction, overrides=None, *, window=None, settle=SETTLE, extra=None, **options):
    """Build and run; returns (scene, WindowStatistics, [extra observers], SimResult). ``window``
    defaults to one cage revolution relative to the carrier; ``extra``: fn(scene) -> list of observers
    (given t0, t1 through closure)."""
    p = with_overrides(reference_dpgt(condition, direction), {**FAST_DRIVE, **(overrides or {})})
    bs = build(p, **options)
    window = cage_revolution(p) if window is None else window
    t1 = settle + window
    stats = WindowStatistics(bs, settle, t1)
    more = extra(bs, settle, t1) if extra is not None else []
    res = mbd.simulate(bs.model, bs.q0, bs.v0, stats.t_end, stepper=mbd.HHT(alpha=-0.3), controller=CONTROLLER,
                       progress=False, observers=[stats, *more])
    return bs, stats, more, res


def line_of_action(e, flank, alpha, internal):
    """Unit direction of a flank's force on gear 2 (external) or on the planet (internal), docs/model.md §6.2."""
    t = np.array([-e[1], e[0]])
    s = -1.0 if internal else 1.0
    return s * math.sin(alpha) * e + flank * math.cos(alpha) * t


def ramp_state(t: float = 0.003, engine: str = "compiled"):
    """(scene, state) of the reference DPGT (condition 3, forward) ``t`` into its load ramp: every contact
    family active, for tests that need one loaded state rather than statistics."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        sc = build_dpgt(reference_dpgt(3, "forward"))
    res = mbd.simulate(sc.model, sc.q0, sc.v0, t, stepper=mbd.PRODUCTION.stepper(),
                       controller=mbd.PRODUCTION.controller(), progress=False, engine=engine)
    return sc, res.state


def assert_static_is_dynamic_mean(st, dyn, roller_rtol: float) -> None:
    """A static solution's statistics ``st`` against a dynamic run's ``dyn`` (tests/components/test_load_path.py):
    every pin's mean reaction as a vector within 1 % of its magnitude, the bearings' mean roller loads on pin and bore
    within ``roller_rtol``, the planets' speeds relative to the carrier within 3e-4 and the cages' within 1.2 %."""
    vec = lambda s: np.stack([s.stats("load_radial")["mean"], s.stats("load_tangential")["mean"]], axis=1)  # noqa: E731
    Fd, Fs = vec(dyn), vec(st)
    np.testing.assert_array_less(np.hypot(*(Fs - Fd).T), 0.01 * np.hypot(*Fd.T))
    rb = st.plan.roller_bearing
    for key in ("roller_inner_load", "roller_outer_load"):
        md, ms = (np.bincount(rb, s.stats(key)["mean"]) / np.bincount(rb) for s in (dyn, st))
        np.testing.assert_allclose(ms, md, rtol=roller_rtol, err_msg=key)
    for key, rtol in (("planet_speed_rel", 3e-4), ("cage_speed_rel", 0.012)):
        np.testing.assert_allclose(st.stats(key)["mean"], dyn.stats(key)["mean"], rtol=rtol, err_msg=key)
