"""Work beside the runs (scenarios.core.sweep.Beside): each group's task starts once, when its last case is in."""
import pytest

from scenarios.core.sweep import ALL, Beside, Case, Outcome, Status


def _case(cond, d):
    return Case(cond, d, f"/nowhere/c{cond}_{d}")


def _done(case, ok=True):
    return Outcome(case, Status.FINISHED if ok else Status.FAILED, summary={"condition": case.condition} if ok else None)


def test_a_group_starts_once_and_only_when_all_its_cases_are_in():
    cases = [_case(c, d) for c in (1, 2) for d in ("forward", "reverse")]
    seen = []
    b = Beside(key=lambda c: c.condition, task=lambda k, outs: (seen.append((k, sorted(outs))) or len, (outs,)))
    groups, started, results = b.groups(cases), set(), {}
    assert list(b.ready(groups, results, started)) == []
    results[cases[0].label] = _done(cases[0])                 # condition 1 forward only: nothing starts
    results[cases[2].label] = _done(cases[2])                 # condition 2 forward
    assert list(b.ready(groups, results, started)) == []
    results[cases[1].label] = _done(cases[1])                 # condition 1 complete
    ready = list(b.ready(groups, results, started))
    assert [k for k, _ in ready] == [1] and seen == [(1, ["c1_forward", "c1_reverse"])]
    assert list(b.ready(groups, results, started)) == []      # never twice
    results[cases[3].label] = _done(cases[3])
    assert [k for k, _ in b.ready(groups, results, started)] == [2]
    for k, work in ready:
        b.here(k, work)
    assert b.done == {1: 2}                                   # len of the group's two outcomes


def test_cases_outside_every_group_wait_for_nothing_and_a_failing_task_is_kept_as_its_error():
    cases = [_case(3, "forward"), _case(4, "forward")]
    b = Beside(key=lambda c: c.condition if c.condition == 3 else None, task=lambda k, outs: (int, ("x",)))
    groups, started = b.groups(cases), set()
    assert groups == {3: ["c3_forward"]}
    (k, work), = b.ready(groups, {"c3_forward": _done(cases[0])}, started)
    b.here(k, work)
    assert isinstance(b.done[3], ValueError)


def test_the_paper_study_draws_a_point_beside_only_when_both_its_runs_finished(tmp_path):
    from scenarios import paper_study
    a = paper_study.parse_args(["--conditions", "2,3", "--out", str(tmp_path)])
    study = paper_study.PaperStudy(a)
    b = study.beside(study.config())
    f, r = _case(3, "forward"), _case(3, "reverse")
    assert b.task(3, {f.label: _done(f), r.label: _done(r, ok=False)}) is None
    pieces = b.task(3, {f.label: _done(f), r.label: _done(r)})
    assert all(fn is paper_study.point_work and fargs[2] == 3 for fn, fargs in pieces)
    assert [fargs[3] for _, fargs in pieces] == list(paper_study.POINT_PIECES)      # each on a worker of its own
    assert sorted(f for piece in paper_study.POINT_PIECES for f in piece) == sorted([*paper_study.HISTORY_GROUPS, "cage_orbits"])
    animated = paper_study.PaperStudy(paper_study.parse_args(["--conditions", "2,3", "--animate", "--out", str(tmp_path)]))
    pieces = animated.beside(animated.config()).task(3, {f.label: _done(f), r.label: _done(r)})
    # the animation, the longest piece, goes out first: it does not start after the figures on the same worker
    assert [fargs[3] for _, fargs in pieces] == ["animation", *paper_study.POINT_PIECES]
    static = paper_study.PaperStudy(paper_study.parse_args(["--conditions", "3", "--mode", "static",
                                                            "--out", str(tmp_path)]))
    assert static.beside(static.config()) is None
    one = paper_study.PaperStudy(paper_study.parse_args(["--conditions", "3", "--out", str(tmp_path)]))
    assert one.beside(one.config()) is not None   # one point (the demo): its pieces side by side on the workers
    for argv in (["--workers", "1"], ["--directions", "forward"]):     # ... but not one after another here
        alone = paper_study.PaperStudy(paper_study.parse_args(["--conditions", "3", *argv, "--out", str(tmp_path)]))
        assert alone.beside(alone.config()) is None


def test_a_group_in_pieces_starts_each_piece_once_and_joins_their_lists_in_order():
    """A group's work in pieces (a list of (function, args)): every piece starts when the group is in, once; their
    lists are joined in the order of the pieces, whatever order they finish in; a piece that raises is the group's
    result (the report redraws that point)."""
    cases = [_case(1, "forward"), _case(1, "reverse")]
    b = Beside(key=lambda c: c.condition, task=lambda k, outs: [(list, ("ab",)), (list, ("cd",))])
    groups, started = b.groups(cases), set()
    results = {c.label: _done(c) for c in cases}
    ready = list(b.ready(groups, results, started))
    assert [k for k, _ in ready] == [1, 1] and list(b.ready(groups, results, started)) == []
    for k, work in ready:
        b.here(k, work)
    assert b.done == {1: ["a", "b", "c", "d"]} and len(b.spans) == 2
    bad = Beside(key=lambda c: c.condition, task=lambda k, outs: [(list, ("ab",)), (int, ("x",)), (list, ("cd",))])
    for k, work in bad.ready(bad.groups(cases), results, set()):
        bad.here(k, work)
    assert isinstance(bad.done[1], ValueError)


def test_the_work_across_all_cases_starts_once_with_the_last_case_after_that_groups_pieces():
    """``last``: given every case's outcome, once, when the last case is in; its pieces come after the last group's
    (so they are submitted behind them), and its value is kept under ALL, apart from every group's."""
    cases = [_case(c, d) for c in (1, 2) for d in ("forward", "reverse")]
    seen = []
    b = Beside(key=lambda c: c.condition, task=lambda k, outs: (len, (outs,)),
               last=lambda outs: (seen.append(sorted(outs)) or [(len, ("abc",)), (len, ("de",))]))
    groups, started, results = b.groups(cases), set(), {}
    for c in cases[:3]:
        results[c.label] = _done(c)
    assert [k for k, _ in b.ready(groups, results, started)] == [1] and seen == []
    results[cases[3].label] = _done(cases[3])
    ready = list(b.ready(groups, results, started))
    assert [k for k, _ in ready] == [2, ALL, ALL]
    assert seen == [sorted(c.label for c in cases)]
    assert list(b.ready(groups, results, started)) == []          # never twice
    for k, work in ready:
        b.here(k, work)
    assert b.done == {2: 2, ALL: 2}     # the pieces' values are not lists: the last one's stays


def test_the_paper_study_draws_the_figures_across_its_points_beside_only_when_every_run_finished(tmp_path):
    from scenarios import paper_study
    study = paper_study.PaperStudy(paper_study.parse_args(["--conditions", "2,3", "--out", str(tmp_path)]))
    b = study.beside(study.config())
    cases = [_case(c, d) for c in (2, 3) for d in ("forward", "reverse")]
    assert b.last({c.label: _done(c, ok=c.label != "c3_reverse") for c in cases}) is None  # the report draws them
    pieces = b.last({c.label: _done(c) for c in cases})
    assert all(fn is paper_study.across_figures for fn, _ in pieces)
    assert [fargs[3] for _, fargs in pieces] == [(p,) for p in paper_study.ACROSS_PIECES]
    assert sorted(paper_study.ACROSS_PIECES) == ["bars", "headline"]


TINY = ["--conditions", "3,4", "--directions", "forward", "--settle", "0.0005", "--window", "0.0005",
        "--set", "bearing.rollers=8", "--no-progress", "--workers", "1"]


def test_a_study_of_two_points_draws_every_figure_once_beside_its_runs_and_redraws_what_failed_there(
        tmp_path, capsys, monkeypatch):
    """In-process (one worker): each point's figures after its run, those across the points after the last run;
    the report draws nothing again. A piece across the points that fails beside the runs is drawn by the report,
    and said so."""
    from scenarios import paper_study

    r = paper_study.run(paper_study.parse_args([*TINY, "--out", str(tmp_path / "ok")]))
    names = [p.name for p in r["figures"]]
    want = {f"c{c}_{g}.png" for c in (3, 4) for g in paper_study.HISTORY_GROUPS} | {
        f"c{c}_cage_orbit_{k}.png" for c in (3, 4) for k in ("inner", "outer")} | {"bearing_load_life.png", "bars.png"}
    assert sorted(names) == sorted(want)                       # each once
    assert names.index("c3_cage.png") < names.index("c4_cage.png") < names.index("bearing_load_life.png")
    lines = capsys.readouterr().out.splitlines()
    assert sum(x.startswith("figures beside the runs: ") for x in lines) == 1
    assert not any(x.startswith("figures: ") for x in lines)          # nothing left for the report to draw

    paper_study.run(paper_study.parse_args([*TINY, "--out", str(tmp_path / "ok")]))      # every run reused
    lines = capsys.readouterr().out.splitlines()
    assert not any(x.startswith("figures beside the runs") for x in lines)       # nothing ran: nothing beside
    head = next(i for i, x in enumerate(lines) if x.startswith("headline ("))
    figures = next(i for i, x in enumerate(lines) if x.startswith("figures: "))
    assert head < figures and all(n in lines[figures] for n in ("c3_cage.png", "c4_mesh.png", "bars.png"))

    # a point's piece fails beside the runs: the report draws that point's figures, and only that point's
    r, text, figures_line = _with_a_failing_piece(monkeypatch, capsys, tmp_path / "point", "point_work",
                                                  lambda *a: a[2] == 3 and a[3] == paper_study.POINT_PIECES[1])
    assert "figures of condition 3 beside the runs failed (failed here); drawn now" in text
    assert "c3_cage.png" in figures_line and "c3_bearing_loads.png" in figures_line and "c4_cage.png" not in figures_line
    assert sorted(p.name for p in r["figures"]).count("c3_cage.png") == 1
    # a piece across the points fails beside the runs (the report asks for both: figures=None): it draws both
    r, text, figures_line = _with_a_failing_piece(monkeypatch, capsys, tmp_path / "redo", "across_figures",
                                                  lambda *a: len(a) == 4 and a[3] == ("bars",))
    assert "figures across the points beside the runs failed (failed here); drawn now" in text
    assert "bars.png" in figures_line and "bearing_load_life.png" in figures_line
    assert sorted(p.name for p in r["figures"]).count("bearing_load_life.png") == 1


def _with_a_failing_piece(monkeypatch, capsys, out, name, fails):
    """The tiny two-point study with paper_study's ``name`` raising where ``fails(*its arguments)``: its result, what
    it printed, and its "figures: " line (what the report drew)."""
    from scenarios import paper_study

    real = getattr(paper_study, name)

    def failing(*a):
        if fails(*a):
            raise RuntimeError("failed here")
        return real(*a)
    monkeypatch.setattr(paper_study, name, failing)
    try:
        r = paper_study.run(paper_study.parse_args([*TINY, "--out", str(out)]))
    finally:
        monkeypatch.setattr(paper_study, name, real)
    text = capsys.readouterr().out
    return r, text, next(x for x in text.splitlines() if x.startswith("figures: "))


def test_an_animation_without_offscreen_rendering_is_skipped_in_words(tmp_path, capsys, monkeypatch):
    """The animation's offscreen probe runs beside its reading of the runs; where no offscreen rendering works, the
    point's animation is skipped with the probe's reason, nothing raised and no file written."""
    from scenarios import paper_study
    from viz import render_check

    args = [*TINY, "--conditions", "3", "--directions", "forward,reverse", "--out", str(tmp_path)]
    r = paper_study.run(paper_study.parse_args(args))
    capsys.readouterr()
    monkeypatch.delenv("VTK_DEFAULT_OPENGL_WINDOW", raising=False)
    monkeypatch.delenv("DISPLAY", raising=False)
    monkeypatch.setattr(render_check, "_find_libs", lambda: {"EGL": None, "OSMesa": None})
    render_check._check.cache_clear()
    try:
        assert paper_study.animate(r["results"], tmp_path) == []
    finally:
        render_check._check.cache_clear()
    said = capsys.readouterr().out
    assert "animation skipped: no offscreen OpenGL library found" in said
    assert not list(tmp_path.glob("*.gif"))

    # where offscreen rendering works, an error of the animation itself is raised, not taken for the machine's
    import viz.results

    def broken(*a, **k):
        raise RuntimeError("the animation's own")

    monkeypatch.setattr(render_check, "_find_libs", lambda: {"EGL": "libEGL.so.1", "OSMesa": None})
    monkeypatch.setattr(render_check, "_probe", lambda cls, timeout: (True, f"offscreen rendering works via {cls}"))
    monkeypatch.setattr(viz.results, "study_cage_animation", broken)
    render_check._check.cache_clear()
    try:
        with pytest.raises(RuntimeError, match="the animation's own"):
            paper_study.animate(r["results"], tmp_path)
    finally:
        render_check._check.cache_clear()
    assert "animation skipped" not in capsys.readouterr().out
