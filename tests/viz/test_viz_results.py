"""viz.results and `dpgt animate`: saved DPGT results → cage orbits, train bodies, animations.

One short forward and one short reverse DPGT run (1 ms simulated, 13 samples each) are made once per
session with scenarios.core.runner.run_case; everything else reads their results files.  The derived
quantities are checked against independent outputs the engine recorded in the same file (guide
eccentricity and force, pocket offset, inner-race deflection, fixed-frame poses).  Animations are tiny
and skip, with the probe's reason, where this machine cannot render offscreen.
"""
from __future__ import annotations

import json
import shutil
import subprocess
import sys
import warnings
from pathlib import Path

import h5py
import imageio.v3 as iio
import numpy as np
import pytest
import xarray as xr

from viz import render_check
from viz import results as vr
from viz.cli import main as animate_main

N_FRAMES = 5


# ----------------------------------------------------------------------------------- fixtures
def _short_run(out_dir: Path, direction: str) -> Path:
    from components.presets import reference_dpgt
    from components.scene import SceneOptions
    from scenarios.core.runner import RunConfig, run_case

    run_case(reference_dpgt(3, direction),
             RunConfig(settle=0.0005, window=0.0005, progress=False, options=SceneOptions()), out_dir)
    return out_dir / "results.nc"


@pytest.fixture(scope="session")
def runs(tmp_path_factory) -> dict[str, Path]:
    root = tmp_path_factory.mktemp("dpgt_runs")
    return {d: _short_run(root / d, d) for d in ("forward", "reverse")}


@pytest.fixture(scope="session")
def fwd(runs) -> vr.Run:
    return vr.load_run(runs["forward"])


def _frames(path: Path) -> np.ndarray:
    return np.asarray(iio.imread(path, index=None))[..., :3]


def _assert_animation(path: Path, n_frames: int, size: tuple[int, int]) -> None:
    assert path.is_file() and path.stat().st_size > 0
    frames = _frames(path)
    assert frames.shape[:3] == (n_frames, size[1], size[0])
    for f in frames.astype(float):
        assert f.std() > 8.0, "blank frame"
        assert np.mean(f.min(axis=-1) < 200) > 0.005, "frame has almost no ink"
    diffs = [np.abs(frames[k + 1].astype(float) - frames[k]).mean() for k in range(n_frames - 1)]
    assert min(diffs) > 0.05, f"consecutive frames (nearly) identical: {diffs}"


def _pocket_axes(off: np.ndarray):
    """(radial, tangential) components of roller offsets given in cage axes (pocket j at 2πj/Z)."""
    Z = off.shape[1]
    psi = 2 * np.pi * np.arange(Z) / Z
    c, s = np.cos(psi), np.sin(psi)
    return off[..., 0] * c + off[..., 1] * s, -off[..., 0] * s + off[..., 1] * c


# ----------------------------------------------------------------------------------- loader
def test_load_run_layout(runs, fwd):
    with xr.open_dataset(runs["forward"], engine="h5netcdf") as ds:
        t_file = ds["time"].values
        q_file = np.concatenate([ds["motion.position"].values, ds["motion.angle"].values[..., None]], axis=-1)
    np.testing.assert_array_equal(fwd.t, t_file)
    np.testing.assert_array_equal(fwd.q, q_file)
    assert fwd.n_t == 13 and np.all(np.diff(fwd.t) > 0)
    N, Z = fwd.meta["planets"], fwd.meta["rollers"]
    assert (N, Z) == (3, 12)
    assert fwd.q.shape == fwd.v.shape == fwd.a.shape == (fwd.n_t, len(fwd.bodies), 3)
    expected = {"sun", "ring", "carrier", *(f"{p}{n}" for p in "ab" for n in range(1, N + 1))}
    assert expected <= set(fwd.bodies)
    assert len(fwd.bodies) == 3 + 2 * N * (1 + Z + 1)
    assert [b["kind"] for b in fwd.bearings] == ["inner", "outer"] * N
    assert fwd.bearing("outer", 2)["planet"] == "b3" and fwd.bearing("a2.pb")["pair"] == 1
    assert fwd.direction == "forward" and fwd.frame == "rotating"
    assert fwd.output("race_inner.load").shape == (fwd.n_t, 2 * N * Z)
    # R turns at Ω: the angle read from the carrier's pose in both frames is Ω t
    np.testing.assert_allclose(fwd.frame_angle, fwd.carrier_speed * fwd.t, rtol=0, atol=1e-9)
    # a run directory works as well as the file
    assert vr.load_run(runs["forward"].parent).bodies == fwd.bodies


def test_geometry_comes_from_the_file_or_is_given(runs, fwd, tmp_path):
    from components.presets import reference_dpgt
    from components.results.schema import drawing_geometry
    assert fwd.geometry["source"] == "file"          # the runner stores the drawing geometry
    bare = tmp_path / "bare.nc"                       # a file without it needs the caller's geometry
    shutil.copy(runs["forward"], bare)
    with h5py.File(bare, "r+") as f:
        del f.attrs["geometry"]
    with pytest.raises(vr.ResultsError, match="no drawing geometry.*fallback_geometry"):
        vr.load_run(bare)
    ref = drawing_geometry(reference_dpgt())
    g = vr.load_run(bare, fallback_geometry=ref).geometry
    assert g["source"] == "given"
    assert g == {**fwd.geometry, "source": "given"}
    si = reference_dpgt().si()
    assert g["bearing"]["d_m"] == pytest.approx(si.bearing.pitch_diameter)
    assert g["bearing"]["guide_clearance"] == pytest.approx(0.15e-3)
    assert g["teeth"] == {"sun": 31, "inner_planet": 24, "outer_planet": 24, "ring": 82}
    # geometry stored in the file wins; what it lacks comes from the given geometry
    path = tmp_path / "results.nc"
    shutil.copy(runs["forward"], path)
    with h5py.File(path, "r+") as f:
        f.attrs["geometry"] = json.dumps({"bearing": {"guide_clearance": 0.2e-3}})
    g2 = vr.load_run(path, fallback_geometry=ref).geometry
    assert g2["source"] == "file+given"
    assert g2["bearing"]["guide_clearance"] == 0.2e-3 and g2["bearing"]["d_m"] == g["bearing"]["d_m"]


def test_geometry_mismatch_warns(runs, tmp_path):
    from components.presets import reference_dpgt
    from components.results.schema import drawing_geometry
    path = tmp_path / "results.nc"
    shutil.copy(runs["forward"], path)
    with h5py.File(path, "r+") as f:
        f.attrs["geometry"] = json.dumps({"bearing": {"d_m": 0.05}})
    with pytest.warns(vr.GeometryWarning, match="d_m/2"):
        run = vr.load_run(path, fallback_geometry=drawing_geometry(reference_dpgt()))
    assert run.geometry["source"] == "file+given"  # partly given: checked against the motion


# ----------------------------------------------------------------------------------- orbits
def test_cage_orbits_match_the_guide_contact(fwd):
    orb = vr.cage_orbits(fwd)
    assert set(orb) == {"inner", "outer"}
    eps = fwd.output("guide.eccentricity")
    F = fwd.output("guide.force")
    C_g = fwd.geometry["bearing"]["guide_clearance"]
    for kind, e in orb.items():
        assert e.shape == (fwd.n_t, 2)
        g = fwd.bearing(kind)["guide"]
        np.testing.assert_allclose(np.hypot(e[:, 0], e[:, 1]), eps[:, g], rtol=1e-12, atol=1e-15)
        # the land pushes only outside the clearance circle: the geometry's C_g is the run's
        ecc = eps[:, g]
        assert np.all((F[:, g] > 0) == (ecc > C_g))
    every = vr.cage_orbits(fwd, pair=None)
    assert list(every) == [b["name"] for b in fwd.bearings]
    np.testing.assert_array_equal(every["b1.pb"], orb["outer"])
    # the fixed-frame view is the same vector turned by φ_R
    fixed = vr.cage_orbits(fwd, frame="fixed")["inner"]
    np.testing.assert_allclose(np.hypot(*fixed.T), np.hypot(*orb["inner"].T), rtol=1e-12)


def test_roller_offsets_match_pocket_and_race_outputs(fwd):
    for kind in ("inner", "outer"):
        b = fwd.bearing(kind)
        off = vr.roller_offsets(fwd, kind)
        assert off.shape == (fwd.n_t, 12, 2)
        radial, tangential = _pocket_axes(off)
        # tangential: the pocket contact's offset s_j; radial: −(inner-race deflection)
        np.testing.assert_allclose(tangential, fwd.output("pocket.offset")[:, slice(*b["pocket"])],
                                   rtol=0, atol=1e-12)
        np.testing.assert_allclose(radial, -fwd.output("race_inner.deflection")[:, slice(*b["race_inner"])],
                                   rtol=0, atol=1e-12)


def test_no_cage_is_a_clear_error(fwd):
    b = dict(fwd.bearing("inner"), cage=None, type="linear")
    with pytest.raises(vr.ResultsError, match="no cage"):
        vr.roller_offsets(fwd, b)


# ----------------------------------------------------------------------------------- train
def test_train_bodies(fwd):
    bodies = vr.train_bodies(fwd, frame="carrier")
    kinds = [b["kind"] for b in bodies]
    assert kinds.count("roller") == 72 and kinds.count("cage") == 6 and kinds.count("ring") == 1
    assert kinds.count("gear") == 1 + 6 and kinds.count("carrier") == 1 + 6  # plate + pins
    by = {b["name"]: b for b in bodies}
    # seen from the carrier, a rotating-frame run is drawn in R as recorded
    np.testing.assert_allclose(by["a1"]["xy"], fwd.pose("a1")[:, :2], rtol=0, atol=1e-15)
    assert by["sun"]["teeth"] == 31 and by["b2"]["teeth"] == 24
    assert by["ring"]["radius"] == pytest.approx(0.123)
    b = fwd.bearing("outer", 1)
    np.testing.assert_array_equal(by[b["rollers"][3]]["force"],
                                  fwd.output("race_inner.load")[:, b["race_inner"][0] + 3])
    # seen from the housing: sun, carrier, ring coincide with the fixed-frame poses the engine wrote
    fixed = {b["name"]: b for b in vr.train_bodies(fwd, frame="fixed")}
    for name in ("sun", "carrier", "ring"):
        fq = fwd.fixed_q[:, fwd.fixed_bodies.index(name)]
        np.testing.assert_allclose(fixed[name]["xy"], fq[:, :2], rtol=0, atol=1e-12)
        np.testing.assert_allclose(fixed[name]["theta"], fq[:, 2], rtol=0, atol=1e-12)
    # magnify scales the displacement from the nominal centre and nothing else
    mag = {b["name"]: b for b in vr.train_bodies(fwd, frame="carrier", magnify=50.0)}
    for name in ("sun", "a1", "b1.pb.cage", b["rollers"][3]):
        np.testing.assert_allclose(mag[name]["xy"] - mag[name]["ref"],
                                   50.0 * (by[name]["xy"] - by[name]["ref"]), rtol=1e-9, atol=1e-15)
        np.testing.assert_array_equal(mag[name]["theta"], by[name]["theta"])
    with pytest.raises(ValueError, match="frame"):
        vr.train_bodies(fwd, frame="planet")


def test_fixed_frame_run_seen_from_the_carrier(runs, fwd, tmp_path):
    """The same motion stored as a fixed-frame run (R = I) gives the same carrier view and orbits."""
    with xr.open_dataset(runs["forward"], engine="h5netcdf") as ds:
        ds = ds.load()
    phi = fwd.frame_angle[:, None]
    q = ds["motion.position"].values.copy()
    x, y = q[..., 0].copy(), q[..., 1].copy()
    q[..., 0] = np.cos(phi) * x - np.sin(phi) * y
    q[..., 1] = np.sin(phi) * x + np.cos(phi) * y
    ds["motion.position"].values = q
    ds["motion.angle"].values = ds["motion.angle"].values + phi
    ds = ds.drop_vars([k for k in ds.data_vars if k.startswith("fixed.")] + ["fixed.body"])  # R from the metadata alone
    meta = dict(fwd.meta, frame="fixed")
    ds.attrs["meta"] = json.dumps(meta)
    ds.to_netcdf(tmp_path / "results.nc", engine="h5netcdf")
    other = vr.load_run(tmp_path / "results.nc")
    assert other.frame == "fixed" and np.all(other.frame_angle == 0.0)
    a = {b["name"]: b for b in vr.train_bodies(fwd, "carrier")}
    b = {b["name"]: b for b in vr.train_bodies(other, "carrier")}
    for name in ("sun", "a2", "b3.pb.cage", "b3.pb.roller7"):
        np.testing.assert_allclose(b[name]["xy"], a[name]["xy"], rtol=0, atol=1e-12)
        np.testing.assert_allclose(b[name]["theta"], a[name]["theta"], rtol=0, atol=1e-9)
    np.testing.assert_allclose(vr.cage_orbits(other)["outer"], vr.cage_orbits(fwd)["outer"],
                               rtol=0, atol=1e-12)


# ----------------------------------------------------------------------------------- bad inputs
def test_bad_inputs_give_clear_errors(tmp_path, capsys, runs):
    missing = tmp_path / "nope.nc"
    with pytest.raises(vr.ResultsError, match="no such results file"):
        vr.load_run(missing)
    text = tmp_path / "notes.nc"
    text.write_text("not a results file\n")
    with pytest.raises(vr.ResultsError, match="not a netCDF4/HDF5"):
        vr.load_run(text)
    foreign = tmp_path / "other.nc"
    xr.Dataset({"x": ("time", np.arange(3.0))}, coords={"time": np.arange(3.0)}).to_netcdf(
        foreign, engine="h5netcdf")
    with pytest.raises(vr.ResultsError, match="not a DPGT results file.*motion.position"):
        vr.load_run(foreign)
    with pytest.raises(vr.ResultsError, match="without a results.nc"):
        vr.load_run(tmp_path)

    out = tmp_path / "a.gif"
    cases = [([str(missing), "--out", str(out)], 2, "argument results: no such file"),
             ([str(text), "--out", str(out)], 1, "not a netCDF4/HDF5"),
             ([str(foreign), "--out", str(out)], 1, "not a DPGT results file"),
             ([str(runs["forward"]), "--out", str(tmp_path / "a.png")], 2, ".gif or .mp4"),
             ([str(runs["forward"]), "--out", str(out), "--size", "big"], 2, "WxH"),
             ([str(runs["forward"]), "--out", str(out), "--fps", "0"], 2, "positive"),
             ([str(runs["forward"]), "--out", str(out), "--kind", "train", "--compare",
               str(runs["reverse"])], 2, "--compare applies to --kind cage"),
             ([str(runs["forward"]), "--out", str(out), "--compare", str(missing)], 2,
              "argument --compare: no such file")]
    for argv, code, message in cases:
        assert animate_main(argv) == code, argv
        err = capsys.readouterr().err
        assert message in err, (argv, err)
        assert "Traceback" not in err
    assert not out.exists()
    with pytest.raises(vr.ResultsError, match="expected 'forward'"):
        vr.study_cage_animation(runs["reverse"], runs["forward"], tmp_path / "s.gif")


def test_no_offscreen_rendering_is_a_message(runs, tmp_path, capsys, monkeypatch):
    monkeypatch.setattr(render_check, "check_offscreen",
                        lambda timeout=60.0: (False, "no offscreen OpenGL library found"))
    out = tmp_path / "a.gif"
    assert animate_main([str(runs["forward"]), "--out", str(out)]) == 1
    err = capsys.readouterr().err
    assert "cannot render offscreen: no offscreen OpenGL library found" in err
    assert not out.exists()


def test_dpgt_routes_animate(tmp_path, capsys):
    from scenarios.cli import main as dpgt_main
    assert dpgt_main(["animate", str(tmp_path / "x.nc"), "--out", str(tmp_path / "x.gif")]) == 2   # usage error
    assert "no such file" in capsys.readouterr().err


def test_viz_reads_results_without_the_engine(runs):
    """viz must not import mbd (integrators): load, derive and build panels in a fresh process."""
    code = (
        "import sys; import viz.results as vr, viz.cli\n"
        f"r = vr.load_run({str(runs['forward'])!r}); vr.train_bodies(r, 'fixed'); "
        f"vr.cage_panels([r, {str(runs['reverse'])!r}])\n"
        "bad = sorted(m for m in sys.modules if m == 'mbd' or m.startswith('mbd.'))\n"
        "assert not bad, bad\n")
    res = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert res.returncode == 0, res.stderr


# ----------------------------------------------------------------------------------- animations
def test_cli_cage_animation(offscreen, runs, tmp_path, capsys):
    out = tmp_path / "cage.gif"
    size = (320, 180)
    rc = animate_main([str(runs["forward"]), "--out", str(out), "--max-frames", str(N_FRAMES),
                       "--size", f"{size[0]}x{size[1]}", "--fps", "10"])
    assert rc == 0, capsys.readouterr().err
    assert f"({N_FRAMES} frames" in capsys.readouterr().out
    _assert_animation(out, N_FRAMES, size)


def test_cli_compare_and_train(offscreen, runs, tmp_path, capsys):
    out = tmp_path / "compare.gif"
    size = (480, 160)
    assert animate_main([str(runs["forward"]), "--out", str(out), "--max-frames", str(N_FRAMES),
                         "--size", "480x160", "--compare", str(runs["reverse"])]) == 0
    _assert_animation(out, N_FRAMES, size)
    out = tmp_path / "train.gif"
    assert animate_main([str(runs["forward"]), "--out", str(out), "--kind", "train", "--frame", "fixed",
                         "--max-frames", "4", "--size", "200x200"]) == 0, capsys.readouterr().err
    _assert_animation(out, 4, (200, 200))


def test_study_cage_animation(offscreen, runs, tmp_path):
    out = vr.study_cage_animation(runs["forward"], runs["reverse"], tmp_path / "study.gif",
                                  size=(480, 170), max_frames=3)
    _assert_animation(out, 3, (480, 170))
    # four panels side by side: each quarter of the last frame carries its own drawing
    last = _frames(out)[-1].astype(float)
    for k in range(4):
        quarter = last[:, k * 120:(k + 1) * 120]
        assert np.mean(quarter.min(axis=-1) < 200) > 0.01, f"panel {k} is empty"


def test_study_cage_pictures(runs, tmp_path, monkeypatch):
    """One PNG per bearing type, a panel per run: the trail drawn is cage_orbits' offset in µm, the circle the
    file's guide clearance, the colours the run's times in ms."""
    from viz import plots

    figs = []
    save = plots._save
    monkeypatch.setattr(plots, "_save", lambda fig, path: (figs.append(fig), save(fig, path))[1])
    paths = vr.study_cage_pictures({"forward": runs["forward"], "reverse": runs["reverse"]}, tmp_path, prefix="c3_")
    assert [p.name for p in paths] == ["c3_cage_orbit_inner.png", "c3_cage_orbit_outer.png"]
    assert all(p.stat().st_size > 10_000 for p in paths)
    for fig, kind in zip(figs, ("inner", "outer")):
        assert f"{kind} planet bearing" in fig._suptitle.get_text()
        top = [ax for ax in fig.axes if ax.get_label() != "<colorbar>"][:2]
        assert [ax.get_title() for ax in top] == ["forward", "reverse"]
        for ax, d in zip(top, ("forward", "reverse")):
            run = vr.load_run(runs[d])
            e = vr.cage_orbits(run, 0)[kind] * 1e6
            segs = ax.collections[0].get_segments()
            np.testing.assert_allclose(np.array([s[1] for s in segs]), e[1:])
            np.testing.assert_allclose(ax.collections[0].get_array(), 0.5e3 * (run.t[:-1] + run.t[1:]))
            circle = next(ln for ln in ax.get_lines() if ln.get_linestyle() == "--")
            np.testing.assert_allclose(np.hypot(circle.get_xdata(), circle.get_ydata()),
                                       run.geometry["bearing"]["guide_clearance"] * 1e6)


# ----------------------------------------------------------------------------------- schema
_LENGTHS = {"m", "m/s", "m/s^2"}
_ANGLES = {"rad", "rad/s", "rad/s^2"}


def test_results_file_describes_itself(runs, fwd):
    """Every variable and coordinate of a run_case results.nc has units and a long name; lengths and
    angles live in separate variables; instance coordinates say which bearing/roller/mesh each is."""
    with xr.open_dataset(runs["forward"], engine="h5netcdf") as ds:
        for name in ds.variables:
            attrs = ds[name].attrs
            assert isinstance(attrs.get("units"), str) and attrs["units"].strip(), name
            assert isinstance(attrs.get("long_name"), str) and attrs["long_name"].strip(), name
        units = {k: ds[k].attrs["units"] for k in ds.data_vars}
        for name, da in ds.data_vars.items():
            assert not ({units[name]} & _LENGTHS and {units[name]} & _ANGLES)
            if "axis" in da.dims:                          # vector components: x, y only, a length unit
                assert list(da["axis"].values) == ["x", "y"] and units[name] in _LENGTHS, name
            for d in da.dims:                              # no component dimension holds an angle
                if d in ds.coords and ds[d].dtype == object:
                    assert "theta" not in {str(v) for v in ds[d].values}, (name, d)
        assert units["motion.position"] == "m" and units["motion.angle"] == "rad"
        assert units["fixed.angular_acceleration"] == "rad/s^2" and units["race_inner.load"] == "N"
        assert ds["motion.angle"].dims == ("time", "motion.body")
        assert units["race_inner.angle"] == "rad" and units["carrier_drive.torque"] == "N m"

        N, Z = 3, 12
        order = [(n, p) for n in range(N) for p in "ab"]             # bearing order of the bearing map
        rollers = [f"{p}{n + 1}.pb.roller{j}" for n, p in order for j in range(Z)]
        load = ds["race_inner.load"]
        assert load.dims == ("time", "race_inner.instance")
        for fam in ("race_inner", "race_outer", "pocket"):
            assert list(ds[f"{fam}.instance"].values) == rollers, fam
            assert list(ds[f"{fam}.roller"].values) == list(range(Z)) * 2 * N
        assert list(load["race_inner.bearing"].values) == [f"{p}{n + 1}.pb" for n, p in order for _ in range(Z)]
        assert list(load["race_inner.planet"].values) == [f"{p}{n + 1}" for n, p in order for _ in range(Z)]
        assert list(load["race_inner.pair"].values) == [n for n, _ in order for _ in range(Z)]
        assert list(load["race_inner.bearing_kind"].values) == [
            {"a": "inner", "b": "outer"}[p] for _, p in order for _ in range(Z)]
        assert list(ds["guide.instance"].values) == [f"{p}{n + 1}.pb.cage" for n, p in order]
        assert list(ds["mesh_sa.instance"].values) == [f"sun-a{n}" for n in range(1, N + 1)]
        assert list(ds["mesh_ab.instance"].values) == [f"a{n}-b{n}" for n in range(1, N + 1)]
        assert list(ds["mesh_br.instance"].values) == [f"b{n}-ring" for n in range(1, N + 1)]
        assert list(ds["mesh_br.gear1"].values) == [f"b{n}" for n in range(1, N + 1)]
        assert list(ds["carrier_drive.instance"].values) == ["carrier"]
        # selecting by coordinate (the README example) = slicing with the JSON bearing map
        b = fwd.bearing("a2.pb")
        sel = load.where(load["race_inner.bearing"] == "a2.pb", drop=True)
        np.testing.assert_array_equal(sel.values, fwd.output("race_inner.load")[:, slice(*b["race_inner"])])
        assert list(sel["race_inner.instance"].values) == b["rollers"]
        assert sel.mean("time").shape == (Z,)


def test_linear_bearing_instances_are_named():
    from components.dpgt import build_dpgt
    from components.presets import reference_dpgt
    from components.results.schema import OUTPUTS, instance_coords
    from components.scene import SceneOptions

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")                # design warnings of the reference machine
        scene = build_dpgt(reference_dpgt(3, "forward"), SceneOptions(bearings="linear"))
    coords = instance_coords(scene)
    lin = coords["bearing_linear"]
    assert lin["instance"][1] == [f"{p}{n}.pb" for n in (1, 2, 3) for p in "ab"]
    assert lin["bearing_kind"][1] == ["inner", "outer"] * 3 and lin["pair"][1] == [0, 0, 1, 1, 2, 2]
    assert "race_inner" not in coords and "bearing_linear" in OUTPUTS
