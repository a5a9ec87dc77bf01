import numpy as np, warnings, time, mbd
warnings.simplefilter("ignore")
from components.presets import reference_dpgt
from components.dpgt import build_dpgt
from components import static
from components.params.errors import PinSlopeParams
from components.units import Q_
p = reference_dpgt(3, "forward")
ps = p.replace(bearing=p.bearing.replace(model="sliced"))
for label, params in (("aligned", ps), ("a1 4' tangential", ps.replace(errors=ps.errors.replace(pin_slope=(PinSlopeParams(planet="a1", slope=Q_("4 arcmin"), direction=Q_("90 deg")),))))):
    sc = build_dpgt(params)
    times = static.snapshot_times(sc, 8)
    t0 = time.time()
    sols = static.solve_snapshots(sc, times[:1], system=mbd.System(sc.model))
    s = sols[0]
    m = sc.model
    qf, vf = m.full(s.t, s.q, s.v)
    sl = {m.body_names[m.extra_owner[i - m.n_body_coords]]: qf[[i, i + 1]] for i, _ in m.slope_pairs}
    print(label, "steps", s.steps, "wall %.1f" % (time.time() - t0), {k: np.round(np.degrees(v) * 60, 4).tolist() for k, v in sl.items() if k in ("a1", "b1", "a2")})
    ri = [e for e in m.elements if e.name == "race_inner"][0]
    qk = ri.slice_loads(qf, vf)
    j = int(np.argmax(qk.sum(1)))
    print("  most loaded inner contact slices [N]:", np.round(qk[j, [0, 5, 10, 15, 20, 25, 30]], 1).tolist())
