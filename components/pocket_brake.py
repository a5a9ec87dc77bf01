"""The brake the cage pockets put on the rollers (docs/skidding.md, "The oiled pocket and the cage's drag"): the
moment of the pocket families' forces against each roller's spin in its cage, re-evaluated with a run's own elements
from its recorded motion, and the share of the samples whose solid pocket contact carries.

    from pathlib import Path
    from components.dpgt import build_dpgt
    from components.pocket_brake import run_pocket_brake
    from scenarios.core.sweep import build_params
    from scenarios.skidding_study import make_cases, parse_args
    case = make_cases(parse_args(["--powers", "2", "--oil-temperatures", "40", "--directions", "forward",
                                  "--set", "bearing.cage.pocket_law=hydrodynamic"]), Path("results/skid_pocket/hydro"))[0]
    run_pocket_brake(build_dpgt(build_params(case), strict=False).model, case.out_dir)

The families are frame-objective (they see relative positions and velocities only), so the recorded motion, in the
scene's frame, serves as it is."""
from __future__ import annotations

import numpy as np

from mbd.element import evaluate

from .families import FAMILY
from .results.reader import read_results

__all__ = ["pocket_brake", "run_pocket_brake"]


def pocket_brake(model, t: float, q_full, v_full) -> tuple[np.ndarray, np.ndarray]:
    """(brake [N·m], solid contact) per pocket instance at one state: the moment on one physical roller of the pocket
    families (the solid contact with its wall friction, and the oil film where the scene has it) taken against the
    roller's spin relative to its cage (> 0: it slows that spin), and whether the solid contact carries."""
    fs = model.frame.at(t)
    names = {e.name for e in model.elements}
    brake, touch = 0.0, None
    for fam in (FAMILY["pocket"], FAMILY["pocket_film"]):
        if fam not in names:
            continue
        elem = model.element(fam)
        F, out, _, _ = evaluate(elem, t, fs, q_full, v_full, None, False)
        spin = v_full[elem.dofs[:, 2]] - v_full[elem.dofs[:, 5]]
        brake = brake - F[:, 2] / elem.multiplicity * np.sign(spin)
        if fam == FAMILY["pocket"]:
            touch = out["force"] != 0.0
    return np.asarray(brake, float), touch


def run_pocket_brake(model, run_dir) -> dict:
    """Per bearing kind of a run's recording (``run_dir``/results.nc, made with ``model``): the mean pocket brake
    [N·m] on the rollers out of the load zone (not loaded on the pin) and in it, and the share of the pocket samples in
    solid contact."""
    ds = read_results(run_dir, ("race_inner.load", *(f"{g}.{k}" for g in ("motion", "fixed")
                                                      for k in ("position", "angle", "velocity", "angular_velocity"))))
    if not np.array_equal(ds["pocket.roller"], ds["race_inner.roller"]):
        raise ValueError(f"{run_dir}: the pockets' instances do not follow the pin contacts' rollers")
    X = np.zeros((len(ds["time"]), model.n_bodies, 3))
    V = np.zeros_like(X)
    for grp in ("motion", "fixed"):
        idx = [model.body_names.index(str(nm)) for nm in ds[f"{grp}.body"]]
        X[:, idx, :2], X[:, idx, 2] = ds[f"{grp}.position"], ds[f"{grp}.angle"]
        V[:, idx, :2], V[:, idx, 2] = ds[f"{grp}.velocity"], ds[f"{grp}.angular_velocity"]
    rows = [pocket_brake(model, float(t), model.full_of_poses(X[k]), model.full_of_poses(V[k]))
            for k, t in enumerate(ds["time"])]
    brake, touch = np.array([r[0] for r in rows]), np.array([r[1] for r in rows])
    loaded = ds["race_inner.load"] > 0.0          # the pocket's instances follow the rollers', as the races'
    kind = ds["pocket.bearing_kind"]
    out = {}
    for k in np.unique(kind):
        sel = kind == k
        out[str(k)] = {"brake_unloaded_Nm": float(brake[:, sel][~loaded[:, sel]].mean()),
                       "brake_loaded_Nm": float(brake[:, sel][loaded[:, sel]].mean()),
                       "solid_contact_share": float(touch[:, sel].mean())}
    return out
